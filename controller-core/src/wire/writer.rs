//! Building frames (layout in [`super`]).

use super::auth::{self, Counter, StoredCounter, COUNTER_EXT_LEN, TAG_LEN};
use super::{mode_with_items, offset, Integrity, ANGLE_ITEM_LEN, FIXED_LEN, MAX_FRAME_LEN};
use crate::{crc16, AgentId};

// The byte arrays below are built in the documented field order.
const _: () = assert!(
    offset::MODE == 0
        && offset::SENDER == 1
        && offset::SEQ == 2
        && offset::VELOCITY == 4
        && FIXED_LEN == 12
        && offset::ITEM_GAMMA == 2
        && offset::ITEM_SIGMA == 4
        && offset::ITEM_RHO0 == 6
        && offset::ITEM_RHO1 == 8
        && ANGLE_ITEM_LEN == 10
);

/// Builds one frame at a time: [`FrameWriter::start`] (header and velocity), then
/// [`FrameWriter::push_angle`] while it fits, then [`FrameWriter::finish`] (the item
/// count in the mode byte, the trailer). The buffer is reused from frame to frame (no
/// zeroing). The fast path's encoder: its bytes are `postcard::to_slice` of the
/// [`super::Frame`] it holds and the trailer, as [`super::Frame::encode`] writes them
/// (`tests/wire_postcard.rs`).
#[derive(Clone, Debug)]
pub struct FrameWriter {
    buf: [u8; MAX_FRAME_LEN],
    len: usize,
    integrity: Integrity,
    /// `auth`: the full counter of the current frame (its low 16 bits are the header's
    /// sequence number).
    counter: StoredCounter,
}

impl FrameWriter {
    /// A writer for frames with `integrity`.
    pub const fn new(integrity: Integrity) -> Self {
        Self {
            buf: [0; MAX_FRAME_LEN],
            len: 0,
            integrity,
            counter: [0; 2],
        }
    }

    /// Starts a frame: the mode byte (its modes, bits 3–0: [`super::mode_byte`]; bits 7–4
    /// are the item count's, written by [`FrameWriter::finish`]), sender, sequence number
    /// and velocity. In `auth`
    /// mode the frame's full counter is `seq` (epoch 0): use
    /// [`FrameWriter::start_counted`].
    #[inline]
    pub fn start(&mut self, mode: u8, sender: AgentId, seq: u16, velocity: [f32; 2]) {
        self.start_counted(mode, sender, Counter::from(seq), velocity);
    }

    /// Starts a frame whose full counter (see [`super::auth`]) is `counter`; the header
    /// carries its low 16 bits as the sequence number.
    #[inline]
    pub fn start_counted(
        &mut self,
        mode: u8,
        sender: AgentId,
        counter: Counter,
        velocity: [f32; 2],
    ) {
        self.counter = auth::store(counter);
        let [q0, q1] = (counter as u16).to_le_bytes();
        let [v0, v1, v2, v3] = velocity[0].to_le_bytes();
        let [w0, w1, w2, w3] = velocity[1].to_le_bytes();
        if let Some(head) = self.buf.first_chunk_mut::<FIXED_LEN>() {
            *head = [mode, sender, q0, q1, v0, v1, v2, v3, w0, w1, w2, w3];
        }
        self.len = FIXED_LEN;
    }

    /// Appends one angle item: far vertices and the binary16 codes (see [`super::quant`])
    /// of `[γ, σ, r_v, r_w]`; `false`, and nothing written, if the frame is full.
    #[inline]
    pub fn push_angle(&mut self, far: [AgentId; 2], codes: [u16; 4]) -> bool {
        let end = self.len + ANGLE_ITEM_LEN;
        if end + self.integrity.trailer_len() > MAX_FRAME_LEN {
            return false;
        }
        // The item as five little-endian 16-bit words (far vertices, then the codes):
        // five half-word stores on target rather than ten byte stores.
        let [g, s, a, b] = codes;
        let words = [u16::from_le_bytes(far), g, s, a, b];
        let slot = self
            .buf
            .get_mut(self.len..)
            .and_then(|b| b.first_chunk_mut::<ANGLE_ITEM_LEN>());
        match slot {
            Some(d) => {
                let (pairs, _) = d.as_chunks_mut::<2>();
                for (pair, w) in pairs.iter_mut().zip(words) {
                    *pair = w.to_le_bytes();
                }
                self.len = end;
                true
            }
            None => false,
        }
    }

    /// Angle items in the current frame.
    pub fn angles(&self) -> usize {
        (self.len.saturating_sub(FIXED_LEN)) / ANGLE_ITEM_LEN
    }

    /// Writes the item count into the mode byte, appends the integrity trailer and returns
    /// the finished frame. In `auth` mode: the counter extension if it fits (at most 3
    /// items), then the tag.
    #[inline]
    pub fn finish(&mut self) -> &[u8] {
        let items = self.angles();
        if let Some(mode) = self.buf.first_mut() {
            *mode = mode_with_items(*mode, items);
        }
        let mut body = self.len;
        match &self.integrity {
            Integrity::Crc16 => {
                let crc = crc16::checksum(self.buf.get(..body).unwrap_or(&[]));
                if let Some(t) = self.buf.get_mut(body..body + 2) {
                    t.copy_from_slice(&crc.to_le_bytes());
                }
            }
            Integrity::Link => {}
            Integrity::Auth(key) => {
                if body + COUNTER_EXT_LEN + TAG_LEN <= MAX_FRAME_LEN {
                    let [epoch, n] = self.counter;
                    let [e0, e1, e2, e3] = epoch.to_le_bytes();
                    let [h0, h1] = ((n >> 16) as u16).to_le_bytes();
                    let ext = self
                        .buf
                        .get_mut(body..)
                        .and_then(|b| b.first_chunk_mut::<COUNTER_EXT_LEN>());
                    if let Some(ext) = ext {
                        *ext = [e0, e1, e2, e3, h0, h1];
                        body += COUNTER_EXT_LEN;
                    }
                }
                let (signed, rest) = self.buf.split_at_mut(body.min(MAX_FRAME_LEN));
                let tag = auth::tag(key, auth::load(self.counter), signed);
                if let Some(t) = rest.first_chunk_mut::<TAG_LEN>() {
                    *t = tag;
                }
            }
        }
        let end = body + self.integrity.trailer_len();
        self.buf.get(..end).unwrap_or(&[])
    }
}

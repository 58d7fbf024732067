//! `auth` integrity: 100 % rejection of forged, corrupted, replayed, re-attributed,
//! truncated and extended frames, at least 10⁶ attempts per kind (issue 10 §2).
//!
//! Every campaign starts from a receiver that has accepted one authentic frame from each
//! neighbour, makes its attempts, and ends by checking that the receiver accepted
//! nothing, counted every attempt as rejected, and still accepts the sender's next
//! authentic frame (a rejected frame changes no state but the counters). The counts per
//! rejection reason are printed (`cargo test -p ph-formation-core --test auth_reject --
//! --nocapture`) and recorded in docs/core.md ("auth").

use ph_formation_core::wire::auth::{counter, Counter};
use ph_formation_core::wire::{
    mode_byte, mode_with_items, FrameWriter, Integrity, SwarmKey, MAX_FRAME_LEN,
};
use ph_formation_core::{Agent, AgentConfig, AgentId, EstimatorMode, FrameError, FrameStats};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::BTreeMap;

mod testkit;

/// Attempts per campaign.
const N: usize = 1_000_000;

const KEY: SwarmKey = SwarmKey::new(*b"swarm key 128bit");
/// The receiver (far vertex of both angles of triangle (1, 2, 3)).
const ME: AgentId = 3;
/// The sender whose frames are attacked; `OTHER` is the receiver's other neighbour.
const SENDER: AgentId = 1;
const OTHER: AgentId = 2;

type Receiver = Agent<f32, 1, 2>;

fn config(id: AgentId, key: SwarmKey) -> AgentConfig<f32, 1> {
    testkit::one_triangle(id, Integrity::Auth(key))
}

fn mode() -> u8 {
    mode_byte(Integrity::Auth(KEY), EstimatorMode::Shared)
}

/// An authentic frame of `sender` with full counter `c` and `items` angle items
/// (`items ≤ 3`: with the counter extension; 4: without).
fn signed(key: SwarmKey, sender: AgentId, c: Counter, items: usize) -> Vec<u8> {
    let mut w = FrameWriter::new(Integrity::Auth(key));
    w.start_counted(mode(), sender, c, [0.25, -0.5]);
    for i in 0..items {
        // γ 0.5, σ 0.5, r 1.0, 1.5 (binary16 codes); far vertices (2, 3) or (3, 2).
        let far = if i % 2 == 0 { [2, 3] } else { [3, 2] };
        assert!(w.push_angle(far, [0x3800, 0x3800, 0x3C00, 0x3E00]));
    }
    w.finish().to_vec()
}

/// A receiver that accepted one authentic frame of each neighbour at `start`.
fn synced(start: Counter) -> Receiver {
    let mut r = Receiver::new(config(ME, KEY)).expect("valid configuration");
    r.receive(&signed(KEY, SENDER, start, 1))
        .expect("authentic");
    r.receive(&signed(KEY, OTHER, start, 1)).expect("authentic");
    r
}

/// Tally of rejection reasons.
#[derive(Default)]
struct Tally(BTreeMap<&'static str, usize>);

impl Tally {
    fn add(&mut self, e: FrameError) {
        let name = match e {
            FrameError::TooShort | FrameError::TooLong => "bad_length",
            FrameError::BadCrc => "bad_crc",
            FrameError::UnknownVersion(_) => "unknown_version",
            FrameError::ModeMismatch(_) => "mode_mismatch",
            FrameError::Malformed | FrameError::Cobs => "malformed",
            FrameError::UnknownSender(_) | FrameError::OwnFrame => "unknown_sender",
            FrameError::StaleSequence { .. } => "stale",
            FrameError::InvalidValue => "invalid_value",
            FrameError::BadTag => "bad_tag",
            FrameError::Replayed { .. } => "replayed",
            FrameError::Unsynced(_) => "unsynced",
        };
        *self.0.entry(name).or_default() += 1;
    }
}

/// Runs one campaign: `attempt` makes the `i`-th frame; every one must be rejected.
/// Afterwards the sender's frame `next` must still be accepted.
fn campaign(
    name: &str,
    start: Counter,
    next: Counter,
    mut attempt: impl FnMut(usize, &mut ChaCha8Rng) -> Vec<u8>,
) {
    let mut r = synced(start);
    let mut rng = ChaCha8Rng::seed_from_u64(0xA17 ^ name.len() as u64);
    let mut tally = Tally::default();
    for i in 0..N {
        let bytes = attempt(i, &mut rng);
        match r.receive(&bytes) {
            Ok(()) => panic!("{name}: attempt {i} accepted: {bytes:02x?}"),
            Err(e) => tally.add(e),
        }
    }
    let s: FrameStats = *r.stats();
    assert_eq!(
        s.accepted, 2,
        "{name}: nothing accepted but the two sync frames"
    );
    assert_eq!(s.rejected() as usize, N, "{name}: every attempt counted");
    println!("{name}: {N} attempts, {N} rejected (100 %): {:?}", tally.0);
    // No state changed: the sender's next authentic frame (no extension: its counter is
    // reconstructed from the last accepted one) is accepted.
    r.receive(&signed(KEY, SENDER, next, 4))
        .unwrap_or_else(|e| panic!("{name}: next authentic frame refused: {e}"));
}

const START: Counter = counter(7, 1000);

#[test]
fn random_frames_are_rejected() {
    campaign("random frames", START, START + 1, |_, rng| {
        let len = rng.random_range(0..=MAX_FRAME_LEN + 4);
        let mut b: Vec<u8> = (0..len).map(|_| rng.random()).collect();
        // Most attempts get a plausible header (the receiver's mode byte with the item
        // count that fits the length, a neighbour's id) so that they reach the tag check.
        if len >= 2 && rng.random_bool(0.9) {
            let items = if len == MAX_FRAME_LEN {
                4
            } else {
                (len.saturating_sub(26) / 10).min(3)
            };
            b[0] = mode_with_items(mode(), items);
            b[1] = if rng.random_bool(0.5) { SENDER } else { OTHER };
        }
        b
    });
}

#[test]
fn bit_flipped_authentic_frames_are_rejected() {
    campaign(
        "bit-flipped authentic frames",
        START,
        START + 1,
        |i, rng| {
            // Fresh counters (not yet accepted), with and without the extension.
            let c = START + 1 + (i as u64 % 20_000);
            let mut b = signed(KEY, SENDER, c, i % 5);
            // 1 to 3 distinct bits (two flips of one bit would restore the frame).
            let mut bits: Vec<usize> = Vec::new();
            let flips = rng.random_range(1..=3);
            while bits.len() < flips {
                let bit = rng.random_range(0..8 * b.len());
                if !bits.contains(&bit) {
                    bits.push(bit);
                }
            }
            for bit in bits {
                b[bit / 8] ^= 1 << (bit % 8);
            }
            b
        },
    );
}

#[test]
fn frames_signed_with_another_key_are_rejected() {
    campaign("other-key frames", START, START + 1, |i, rng| {
        let key = SwarmKey::new(rng.random());
        let c = START + 1 + (i as u64 % 20_000);
        signed(key, SENDER, c, i % 5)
    });
}

#[test]
fn replays_inside_and_outside_the_window_are_rejected() {
    // The receiver last accepted counter `last`; frames with earlier counters are
    // authentic recordings. Inside the window (`last − 2¹⁵ < c ≤ last`) the counter is
    // reconstructed exactly and refused as not newer; outside, a frame without extension
    // is reconstructed to a newer counter than it was signed with and its tag fails.
    let last = counter(7, 3_000_000);
    campaign("replays inside the window", last, last + 1, |i, rng| {
        let back = rng.random_range(0..0x8000u64);
        signed(KEY, SENDER, last - back, i % 5)
    });
    campaign("replays outside the window", last, last + 1, |i, rng| {
        let back = rng.random_range(0x8000..=3_000_000u64);
        signed(KEY, SENDER, last - back, i % 5)
    });
}

#[test]
fn replays_across_a_counter_wrap_are_rejected() {
    // The header's 16-bit sequence number wrapped (…, 0xFFFF, 0x10000, …); frames from
    // before the wrap have large header values and must not pass for newer ones.
    let last = counter(7, 0x3_0005);
    campaign(
        "replays across a sequence wrap",
        last,
        last + 1,
        |i, rng| {
            let c = counter(7, rng.random_range(0x2_8006..=0x3_0005));
            signed(KEY, SENDER, c, i % 5)
        },
    );
}

#[test]
fn replays_across_a_neighbour_reboot_are_rejected() {
    // The sender ran in epoch 7, rebooted into epoch 8 and the receiver accepted its new
    // frames: every recording of epoch 7 (any frame number) is refused, and so are the
    // replays of epoch 8's frames already accepted.
    let rebooted = counter(8, 40);
    campaign(
        "replays across a reboot",
        rebooted,
        rebooted + 1,
        |i, rng| {
            let c = if i % 4 == 0 {
                counter(8, rng.random_range(0..=40))
            } else {
                counter(7, rng.random())
            };
            signed(KEY, SENDER, c, i % 5)
        },
    );
}

#[test]
fn rewritten_sender_ids_are_rejected() {
    campaign("rewritten sender id", START, START + 1, |i, rng| {
        let c = START + 1 + (i as u64 % 20_000);
        let mut b = signed(KEY, SENDER, c, i % 5);
        // The other neighbour (the tag fails) or any other id (not a neighbour, own).
        b[1] = if i % 2 == 0 {
            OTHER
        } else {
            loop {
                let id: u8 = rng.random();
                if id != SENDER {
                    break id;
                }
            }
        };
        b
    });
}

#[test]
fn truncated_and_extended_frames_are_rejected() {
    campaign(
        "truncated and extended frames",
        START,
        START + 1,
        |i, rng| {
            let c = START + 1 + (i as u64 % 20_000);
            let mut b = signed(KEY, SENDER, c, i % 5);
            if i % 2 == 0 {
                let keep = rng.random_range(0..b.len());
                b.truncate(keep);
            } else {
                for _ in 0..rng.random_range(1..=16) {
                    b.push(rng.random());
                }
            }
            b
        },
    );
}

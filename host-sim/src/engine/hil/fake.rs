//! A host-side stand-in for the `qemu-uart` firmware, for tests without QEMU: a thread
//! running the firmware's own UART session (`firmware_example::boards::uart::Session`,
//! the same code the `qemu-uart` binary runs, built for the host) over a TCP connection,
//! with optional misbehaviour injected on the line (stop answering, corrupt an answer,
//! answer out of protocol).
//!
//! The misbehaviour lives in the serial port (`FakePort`), not in a second copy of the
//! protocol: the port sees every message the session writes (one COBS frame per write)
//! and counts the `Output`s to know which tick an answer belongs to.

use firmware_example::boards::uart::{self, Event, SerialPort, Session};
use ph_formation_core::link::{TargetMsg, LINK_VERSION, MAX_LINK_MSG};
use ph_formation_core::wire::{cobs_decode, cobs_encode};
use std::io::{BufReader, Read, Write};
use std::net::TcpStream;
use std::thread::JoinHandle;

/// Neighbour capacity of the fake target: the firmware's `NB`.
pub const FAKE_NB: usize = uart::NB;

/// How the fake target misbehaves (the default: it does not).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FakeBehaviour {
    /// After this many `Step`s, stop answering (keeps the connection open).
    pub stop_after: Option<u64>,
    /// At this `Step` (counted from 0), answer with bytes that are not a COBS frame.
    pub corrupt_at: Option<u64>,
    /// At this `Step`, answer with a well-formed but unexpected message (`Ready`).
    pub unexpected_at: Option<u64>,
    /// Let `TargetMsg::Estimates` through (the firmware sends them whenever the agent
    /// owns estimates; without this the host reads the estimates from the agent's
    /// frames instead).
    pub send_estimates: bool,
}

/// Starts a fake target that connects to `127.0.0.1:port` (as QEMU does); the thread
/// ends when the host closes the connection or sends `Finish`.
pub fn spawn(port: u16, behaviour: FakeBehaviour) -> JoinHandle<std::io::Result<()>> {
    std::thread::spawn(move || {
        let stream = TcpStream::connect(("127.0.0.1", port))?;
        serve(stream, behaviour)
    })
}

/// Serves one connection (see [`spawn`]) with the firmware's session.
pub fn serve(stream: TcpStream, behaviour: FakeBehaviour) -> std::io::Result<()> {
    stream.set_nodelay(true)?;
    let writer = stream.try_clone()?;
    let mut session = Session::new(FakePort {
        reader: BufReader::new(stream),
        writer,
        behaviour,
        outputs: 0,
        closed: false,
        eof: closed_line_message(),
        eof_pos: 0,
        error: None,
    });
    // As the firmware: announce once the receiver is on.
    session.announce();
    loop {
        if let Event::Finished { .. } = session.poll() {
            return Ok(());
        }
    }
}

/// A closed line is read as a `Finish` message: the session answers it (into the void)
/// and [`serve`] ends, as the firmware ends after `Finish`.
fn closed_line_message() -> Vec<u8> {
    let mut raw = [0u8; MAX_LINK_MSG];
    let mut out = vec![0u8; MAX_LINK_MSG + 4];
    let msg = ph_formation_core::link::HostMsg::<{ uart::MT }>::Finish;
    let n = postcard::to_slice(&msg, &mut raw).map_or(0, |b| b.len());
    let n = raw
        .get(..n)
        .and_then(|b| cobs_encode(b, &mut out))
        .unwrap_or(0);
    out.truncate(n);
    // A leading delimiter ends any partial frame first.
    let mut v = vec![0u8];
    v.extend(out);
    v
}

/// The fake target's serial line: the TCP stream, with the misbehaviour applied to what
/// the session writes.
struct FakePort {
    reader: BufReader<TcpStream>,
    writer: TcpStream,
    behaviour: FakeBehaviour,
    /// `Output` messages written so far = the index of the tick being answered.
    outputs: u64,
    /// The host closed the line: [`Self::eof`] is fed to the session.
    closed: bool,
    eof: Vec<u8>,
    eof_pos: usize,
    /// The first write error (the host went away); later writes are dropped.
    error: Option<String>,
}

impl FakePort {
    fn send(&mut self, bytes: &[u8]) {
        if self.error.is_none() {
            if let Err(e) = self.writer.write_all(bytes) {
                self.error = Some(e.to_string());
            }
        }
    }
}

impl SerialPort for FakePort {
    fn read_byte(&mut self) -> u8 {
        if !self.closed {
            let mut b = [0u8];
            match self.reader.read_exact(&mut b) {
                Ok(()) => return b[0],
                Err(_) => self.closed = true,
            }
        }
        let b = self.eof.get(self.eof_pos).copied().unwrap_or(0);
        self.eof_pos += 1;
        b
    }

    fn write_all(&mut self, bytes: &[u8]) {
        // One call is one message (a COBS frame and its `0`), or the lone `0` of the
        // announcement.
        let mut raw = [0u8; MAX_LINK_MSG];
        let body = bytes.strip_suffix(&[0]).unwrap_or(bytes);
        let msg = if body.is_empty() {
            None
        } else {
            cobs_decode(body, &mut raw)
                .ok()
                .and_then(|n| raw.get(..n))
                .and_then(|b| postcard::from_bytes::<TargetMsg>(b).ok())
        };
        let is_output = matches!(msg, Some(TargetMsg::Output(_)));
        let tick = self.outputs;
        if is_output {
            self.outputs += 1;
        }
        let b = self.behaviour;
        if b.stop_after.is_some_and(|n| tick >= n) {
            return; // silent from this tick on
        }
        if b.corrupt_at == Some(tick) {
            if is_output {
                self.send(&[0x05, 0xff, 0x00]);
            }
            return;
        }
        if b.unexpected_at == Some(tick) {
            if is_output {
                let ready = TargetMsg::Ready {
                    id: 0,
                    version: LINK_VERSION,
                    max_triangles: uart::MT as u16,
                    max_neighbours: uart::NB as u16,
                };
                let mut enc = [0u8; MAX_LINK_MSG];
                let mut frame = [0u8; MAX_LINK_MSG + 4];
                if let Some(n) = postcard::to_slice(&ready, &mut enc)
                    .ok()
                    .and_then(|m| cobs_encode(m, &mut frame))
                {
                    let f = frame.get(..n).unwrap_or_default().to_vec();
                    self.send(&f);
                }
            }
            return;
        }
        if matches!(msg, Some(TargetMsg::Estimates(_))) && !b.send_estimates {
            return;
        }
        self.send(bytes);
    }
}

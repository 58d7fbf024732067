//! The host end of one emulated UART: `ph_formation_core::link` messages, postcard-encoded
//! and COBS-framed (one message per `0`-delimited frame), over a TCP stream, with byte
//! and frame counters and a deadline on every read.
//!
//! The session: wait for the target's start-up announcement (a lone `0` byte, sent once
//! its receiver is on), then `Configure` → `Ready`, per tick `Radio`* + `Step` →
//! `Radio`* [+ `Estimates`] + `Output`, and `Finish` → `Finished` (`docs/firmware.md`).

use ph_formation_core::link::{HostMsg, TargetMsg, MAX_LINK_MSG};
use ph_formation_core::wire::{cobs_decode, cobs_encode};
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::io::{self, Read, Write};
use std::net::TcpStream;
use std::time::{Duration, Instant};

/// Largest COBS frame of one link message (before its `0` delimiter).
pub const MAX_COBS_FRAME: usize = MAX_LINK_MSG + MAX_LINK_MSG / 254 + 2;

/// Capacity of `HostMsg`'s configuration (triangles): the firmware's `MT`.
pub const TARGET_MT: usize = 4;

/// Counters of one link, in both directions.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LinkCounters {
    /// Messages (COBS frames) sent to the target.
    pub frames_to_target: u64,
    /// Messages (COBS frames) received from the target.
    pub frames_from_target: u64,
    /// Bytes written to the serial line (COBS overhead and delimiters included).
    pub bytes_to_target: u64,
    /// Bytes read from the serial line (COBS overhead and delimiters included).
    pub bytes_from_target: u64,
}

/// Why [`Link::recv`] returned without a message.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum RecvError {
    /// Nothing complete arrived before the deadline.
    Timeout {
        /// Bytes of an incomplete frame received so far.
        partial: usize,
    },
    /// The other end closed the connection (QEMU exited).
    Closed,
    /// A frame that does not decode (COBS or postcard), described with its bytes.
    Corrupt(String),
    /// A socket error.
    Io(String),
}

/// Up to 48 bytes as hex, for error messages.
pub fn hex(bytes: &[u8]) -> String {
    let mut s = String::new();
    for (k, b) in bytes.iter().take(48).enumerate() {
        if k > 0 {
            s.push(' ');
        }
        s.push_str(&format!("{b:02x}"));
    }
    if bytes.len() > 48 {
        s.push_str(&format!(" … ({} bytes)", bytes.len()));
    }
    s
}

/// One host–target byte link.
#[derive(Debug)]
pub struct Link {
    stream: TcpStream,
    out: Vec<u8>,
    raw: [u8; MAX_LINK_MSG],
    rbuf: Vec<u8>,
    rpos: usize,
    chunk: Vec<u8>,
    msg: [u8; MAX_LINK_MSG],
    /// Counters so far.
    pub counters: LinkCounters,
}

impl Link {
    /// Wraps a connected stream (sets `TCP_NODELAY`: every message goes out at once).
    pub fn new(stream: TcpStream) -> io::Result<Self> {
        stream.set_nodelay(true)?;
        stream.set_nonblocking(false)?;
        Ok(Self {
            stream,
            out: Vec::with_capacity(4096),
            raw: [0; MAX_LINK_MSG],
            rbuf: Vec::with_capacity(4096),
            rpos: 0,
            chunk: Vec::with_capacity(MAX_COBS_FRAME + 1),
            msg: [0; MAX_LINK_MSG],
            counters: LinkCounters::default(),
        })
    }

    /// Limits how long [`Self::flush`] may block (a target that stopped reading).
    pub fn set_write_timeout(&self, limit: Duration) -> io::Result<()> {
        self.stream.set_write_timeout(Some(limit))
    }

    /// Appends one message to the outgoing buffer (sent by [`Self::flush`]).
    pub fn queue(&mut self, msg: &HostMsg<TARGET_MT>) -> Result<(), String> {
        self.queue_value(msg)
    }

    /// Appends any serializable value as one COBS frame (tests use it to send other
    /// message types).
    pub fn queue_value<T: Serialize>(&mut self, msg: &T) -> Result<(), String> {
        let bytes = postcard::to_slice(msg, &mut self.raw)
            .map_err(|e| format!("message does not encode in {MAX_LINK_MSG} bytes: {e}"))?;
        let mut cobs = [0u8; MAX_COBS_FRAME + 1];
        let n = cobs_encode(bytes, &mut cobs).ok_or("COBS encoding overflow")?;
        let framed = cobs.get(..n).ok_or("COBS encoding overflow")?;
        self.out.extend_from_slice(framed);
        self.counters.frames_to_target += 1;
        self.counters.bytes_to_target += n as u64;
        Ok(())
    }

    /// Appends raw bytes to the outgoing buffer (not counted as a frame).
    pub fn queue_raw(&mut self, bytes: &[u8]) {
        self.out.extend_from_slice(bytes);
        self.counters.bytes_to_target += bytes.len() as u64;
    }

    /// Queues one message and writes everything queued ([`Self::queue`] + [`Self::flush`]).
    pub fn send(&mut self, msg: &HostMsg<TARGET_MT>) -> Result<(), String> {
        self.queue(msg)?;
        self.flush()
            .map_err(|e| format!("cannot write to the target: {e}"))
    }

    /// Writes the outgoing buffer in one go.
    pub fn flush(&mut self) -> io::Result<()> {
        let r = self.stream.write_all(&self.out);
        self.out.clear();
        r
    }

    /// Waits until `deadline` for the target's start-up announcement: a lone `0` byte,
    /// sent once its receiver is on (bytes sent before it would be lost). Returns the
    /// bytes that came before it, if any (an error for the caller to report).
    pub fn wait_announcement(&mut self, deadline: Instant) -> Result<(), RecvError> {
        loop {
            while self.rpos < self.rbuf.len() {
                let b = self.rbuf[self.rpos];
                self.rpos += 1;
                self.counters.bytes_from_target += 1;
                if b == 0 && self.chunk.is_empty() {
                    return Ok(());
                }
                if b == 0 || self.chunk.len() > MAX_COBS_FRAME {
                    let what = format!(
                        "bytes before the start-up announcement (a lone 0x00): {}",
                        hex(&self.chunk)
                    );
                    self.chunk.clear();
                    return Err(RecvError::Corrupt(what));
                }
                self.chunk.push(b);
            }
            self.fill(deadline)?;
        }
    }

    /// Reads more bytes into the buffer (at least one), waiting at most until `deadline`.
    fn fill(&mut self, deadline: Instant) -> Result<(), RecvError> {
        self.rbuf.clear();
        self.rpos = 0;
        loop {
            let now = Instant::now();
            if now >= deadline {
                return Err(RecvError::Timeout {
                    partial: self.chunk.len(),
                });
            }
            let wait = (deadline - now).max(Duration::from_millis(1));
            self.stream
                .set_read_timeout(Some(wait))
                .map_err(|e| RecvError::Io(e.to_string()))?;
            let mut buf = [0u8; 4096];
            match self.stream.read(&mut buf) {
                Ok(0) => return Err(RecvError::Closed),
                Ok(n) => {
                    self.rbuf.extend_from_slice(buf.get(..n).unwrap_or(&[]));
                    return Ok(());
                }
                Err(e)
                    if matches!(
                        e.kind(),
                        io::ErrorKind::WouldBlock
                            | io::ErrorKind::TimedOut
                            | io::ErrorKind::Interrupted
                    ) => {}
                Err(e)
                    if matches!(
                        e.kind(),
                        io::ErrorKind::ConnectionReset | io::ErrorKind::BrokenPipe
                    ) =>
                {
                    return Err(RecvError::Closed)
                }
                Err(e) => return Err(RecvError::Io(e.to_string())),
            }
        }
    }

    /// Bytes received but not yet consumed (after the last message read).
    pub fn pending(&self) -> usize {
        self.rbuf.len() - self.rpos + self.chunk.len()
    }

    /// Reads the next target message, waiting at most until `deadline`.
    pub fn recv(&mut self, deadline: Instant) -> Result<TargetMsg, RecvError> {
        self.recv_as(deadline)
    }

    /// Reads the next message of type `T` (one COBS frame), waiting at most until
    /// `deadline`.
    pub fn recv_as<T: DeserializeOwned>(&mut self, deadline: Instant) -> Result<T, RecvError> {
        loop {
            // Consume buffered bytes up to the next delimiter.
            while self.rpos < self.rbuf.len() {
                let b = self.rbuf[self.rpos];
                self.rpos += 1;
                if b != 0 {
                    if self.chunk.len() > MAX_COBS_FRAME {
                        let what = format!(
                            "no frame delimiter within {MAX_COBS_FRAME} bytes (not a COBS stream): {}",
                            hex(&self.chunk)
                        );
                        self.chunk.clear();
                        return Err(RecvError::Corrupt(what));
                    }
                    self.chunk.push(b);
                    continue;
                }
                if self.chunk.is_empty() {
                    // A lone delimiter (e.g. a line reset before the first frame): skip.
                    self.counters.bytes_from_target += 1;
                    continue;
                }
                self.counters.bytes_from_target += self.chunk.len() as u64 + 1;
                self.counters.frames_from_target += 1;
                let decoded = match cobs_decode(&self.chunk, &mut self.msg) {
                    Ok(n) => n,
                    Err(_) => {
                        let what = format!("a frame that is not valid COBS: {}", hex(&self.chunk));
                        self.chunk.clear();
                        return Err(RecvError::Corrupt(what));
                    }
                };
                let body = self.msg.get(..decoded).unwrap_or(&[]);
                let result = postcard::from_bytes::<T>(body).map_err(|e| {
                    RecvError::Corrupt(format!(
                        "a frame that does not decode as a message ({e}): {}",
                        hex(body)
                    ))
                });
                self.chunk.clear();
                return result;
            }
            self.fill(deadline)?;
        }
    }

    /// Closes both directions (the target sees end of file).
    pub fn shutdown(&self) {
        let _ = self.stream.shutdown(std::net::Shutdown::Both);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ph_formation_core::link::LINK_VERSION;
    use std::net::TcpListener;

    /// A connected (host link, target stream) pair on loopback.
    fn pair() -> (Link, TcpStream) {
        let listener = TcpListener::bind("127.0.0.1:0").expect("bind");
        let target = TcpStream::connect(listener.local_addr().expect("addr")).expect("connect");
        let (host, _) = listener.accept().expect("accept");
        (Link::new(host).expect("link"), target)
    }

    fn framed<T: Serialize>(msg: &T) -> Vec<u8> {
        let mut raw = [0u8; MAX_LINK_MSG];
        let bytes = postcard::to_slice(msg, &mut raw).expect("encode");
        let mut out = [0u8; MAX_COBS_FRAME + 1];
        let n = cobs_encode(bytes, &mut out).expect("cobs");
        out[..n].to_vec()
    }

    fn later() -> Instant {
        Instant::now() + Duration::from_secs(20)
    }

    #[test]
    fn announcement_then_messages_in_both_directions() {
        let (mut link, mut target) = pair();
        let ready = TargetMsg::Ready {
            id: 3,
            version: LINK_VERSION,
            max_triangles: 4,
            max_neighbours: 8,
        };
        let mut bytes = vec![0u8];
        bytes.extend(framed(&ready));
        bytes.push(0); // a lone delimiter between frames is skipped
        bytes.extend(framed(&TargetMsg::Finished {
            accepted: 7,
            rejected: 1,
        }));
        target.write_all(&bytes).expect("write");
        link.wait_announcement(later()).expect("announcement");
        assert_eq!(link.recv(later()).expect("ready"), ready);
        assert_eq!(
            link.recv(later()).expect("finished"),
            TargetMsg::Finished {
                accepted: 7,
                rejected: 1
            }
        );
        assert_eq!(link.counters.frames_from_target, 2);
        assert_eq!(link.counters.bytes_from_target, bytes.len() as u64);

        link.send(&HostMsg::Finish).expect("send");
        let expected = framed(&HostMsg::<TARGET_MT>::Finish);
        let mut got = vec![0u8; expected.len()];
        target.read_exact(&mut got).expect("read");
        assert_eq!(got, expected);
        assert_eq!(link.counters.frames_to_target, 1);
        assert_eq!(link.counters.bytes_to_target, expected.len() as u64);
    }

    #[test]
    fn corrupt_frames_and_bytes_before_the_announcement_are_errors() {
        let (mut link, mut target) = pair();
        target.write_all(&[5, 6, 0]).expect("write");
        match link.wait_announcement(later()) {
            Err(RecvError::Corrupt(what)) => assert!(what.contains("05 06"), "{what}"),
            other => panic!("expected Corrupt, got {other:?}"),
        }
        // A valid COBS frame whose body is not a TargetMsg (variant 200).
        target.write_all(&framed(&[200u8, 1, 2])).expect("write");
        assert!(matches!(link.recv(later()), Err(RecvError::Corrupt(_))));
    }

    #[test]
    fn deadline_and_closed_connection() {
        let (mut link, target) = pair();
        assert_eq!(
            link.recv(Instant::now()),
            Err(RecvError::Timeout { partial: 0 })
        );
        drop(target);
        assert_eq!(link.recv(later()), Err(RecvError::Closed));
    }

    #[test]
    fn hex_is_short() {
        assert_eq!(hex(&[0, 0xab]), "00 ab");
        assert!(hex(&[1; 100]).ends_with("… (100 bytes)"));
    }
}

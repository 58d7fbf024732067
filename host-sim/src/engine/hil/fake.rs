//! A host-side stand-in for the `qemu-uart` firmware, for tests without QEMU: a thread
//! running a `controller-core` `Agent<f32, 4, 8>` behind a TCP connection, speaking the
//! same `controller_core::link` protocol, with optional misbehaviour (stop answering,
//! corrupt a frame, answer out of protocol).

use super::link::{Link, RecvError, TARGET_MT};
use controller_core::link::{
    link_estimates, HostMsg, LinkBearing, LinkError, LinkOutput, TargetMsg, LINK_VERSION,
};
use controller_core::{Agent, BearingMeasurement, Measurements, Vec2};
use std::net::TcpStream;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Neighbour capacity of the fake target (the firmware's `NB`).
pub const FAKE_NB: usize = 8;

/// How the fake target misbehaves (the default: it does not).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FakeBehaviour {
    /// After this many `Step`s, stop reading and answering (keeps the connection open).
    pub stop_after: Option<u64>,
    /// At this `Step` (counted from 0), answer with bytes that are not a COBS frame.
    pub corrupt_at: Option<u64>,
    /// At this `Step`, answer with a well-formed but unexpected message (`Ready`).
    pub unexpected_at: Option<u64>,
    /// Send `TargetMsg::Estimates` before every `Output` (if the agent owns any).
    pub send_estimates: bool,
}

/// Starts a fake target that connects to `127.0.0.1:port` (as QEMU does); the thread
/// ends when the host closes the connection or sends `Finish`.
pub fn spawn(port: u16, behaviour: FakeBehaviour) -> JoinHandle<Result<(), String>> {
    std::thread::spawn(move || {
        let stream = TcpStream::connect(("127.0.0.1", port)).map_err(|e| e.to_string())?;
        serve(stream, behaviour)
    })
}

type FakeAgent = Agent<f32, TARGET_MT, FAKE_NB>;

fn reply(link: &mut Link, msg: &TargetMsg) -> Result<(), String> {
    link.queue_value(msg)?;
    link.flush().map_err(|e| e.to_string())
}

/// Serves one connection (see [`spawn`]).
pub fn serve(stream: TcpStream, behaviour: FakeBehaviour) -> Result<(), String> {
    let mut link = Link::new(stream).map_err(|e| e.to_string())?;
    // The start-up announcement, as the firmware sends it once its receiver is on.
    link.queue_raw(&[0]);
    link.flush().map_err(|e| e.to_string())?;
    let mut agent: Option<FakeAgent> = None;
    let mut queue: Vec<Vec<u8>> = Vec::new();
    let mut steps = 0u64;
    loop {
        let far = Instant::now() + Duration::from_secs(3600);
        let msg = match link.recv_host(far) {
            Ok(m) => m,
            Err(RecvError::Closed) => return Ok(()),
            Err(RecvError::Corrupt(_)) => {
                reply(&mut link, &TargetMsg::Error(LinkError::Malformed))?;
                continue;
            }
            Err(e) => return Err(format!("{e:?}")),
        };
        match msg {
            HostMsg::Configure(c) => match FakeAgent::new(c) {
                Ok(a) => {
                    let id = a.id();
                    agent = Some(a);
                    queue.clear();
                    reply(
                        &mut link,
                        &TargetMsg::Ready {
                            id,
                            version: LINK_VERSION,
                            max_triangles: TARGET_MT as u16,
                            max_neighbours: FAKE_NB as u16,
                        },
                    )?;
                }
                Err(e) => reply(&mut link, &TargetMsg::Error(LinkError::Config(e)))?,
            },
            HostMsg::Radio(f) => queue.push(f.to_vec()),
            HostMsg::Step(s) => {
                if behaviour.stop_after.is_some_and(|n| steps >= n) {
                    // Silent, but keep the line open until the host gives up.
                    while !matches!(link.recv_host(far), Err(RecvError::Closed)) {}
                    return Ok(());
                }
                if behaviour.corrupt_at == Some(steps) {
                    link.queue_raw(&[0x05, 0xff, 0x00]);
                    link.flush().map_err(|e| e.to_string())?;
                    steps += 1;
                    continue;
                }
                if behaviour.unexpected_at == Some(steps) {
                    reply(
                        &mut link,
                        &TargetMsg::Ready {
                            id: 0,
                            version: LINK_VERSION,
                            max_triangles: TARGET_MT as u16,
                            max_neighbours: FAKE_NB as u16,
                        },
                    )?;
                    steps += 1;
                    continue;
                }
                steps += 1;
                let Some(a) = agent.as_mut() else {
                    reply(&mut link, &TargetMsg::Error(LinkError::NotConfigured))?;
                    continue;
                };
                for f in queue.drain(..) {
                    let _ = a.receive(&f);
                }
                let bearings: Vec<BearingMeasurement<f32>> =
                    s.bearings.iter().map(LinkBearing::measurement).collect();
                let out = a.step(&Measurements {
                    time: s.time,
                    dt: s.dt,
                    velocity: Vec2::new(s.velocity[0], s.velocity[1]),
                    bearings: &bearings,
                    partner_offset: s.partner_offset.map(|p| Vec2::new(p[0], p[1])),
                });
                let mut frames = Vec::new();
                a.frames(|bytes| frames.push(bytes.to_vec()));
                for f in &frames {
                    let mut v = heapless::Vec::new();
                    let _ = v.extend_from_slice(f);
                    link.queue_value(&TargetMsg::Radio(v))?;
                }
                // As the firmware: only an agent that owns estimates reports them.
                if behaviour.send_estimates && a.owned_estimates().next().is_some() {
                    match link_estimates(a) {
                        Ok(est) => link.queue_value(&TargetMsg::Estimates(est))?,
                        Err(e) => link.queue_value(&TargetMsg::Error(e))?,
                    }
                }
                let o = LinkOutput::new(&out, frames.len(), a.stats().rejected());
                reply(&mut link, &TargetMsg::Output(o))?;
            }
            HostMsg::Finish => {
                let (accepted, rejected) = agent
                    .as_ref()
                    .map_or((0, 0), |a| (a.stats().accepted, a.stats().rejected()));
                return reply(&mut link, &TargetMsg::Finished { accepted, rejected });
            }
        }
    }
}

impl Link {
    /// Reads the next host message (the target's side of the link; tests only).
    pub fn recv_host(&mut self, deadline: Instant) -> Result<HostMsg<TARGET_MT>, RecvError> {
        self.recv_as(deadline)
    }
}

//! Host-in-the-loop over the emulated UART: the `qemu-uart` firmware under QEMU
//! (netduinoplus2, USART1 connected to a loopback TCP socket this test listens
//! on, `nodelay=on`) runs agent 3 of the paper
//! scenario in lock step with agents 1, 2 and 4 simulated here in `f64`.
//!
//! Checks: the handshake (`Configure` → `Ready`), that every `Step` gets the
//! agent's `Radio` frames, its `Estimates` (agent 3 owns four) and then an
//! `Output` with a finite force, that the
//! output is nominal once the neighbours have been heard, that the force
//! and the estimates agree with an `Agent<f32, 4, 8>` run here on exactly the
//! same inputs (relative difference ≤ 1e-3; in practice they are
//! bit-identical, frames included), and `Finish` → `Finished` with exit code 0.
//! Reports the lock-step round-trip throughput (ticks per second of wall
//! clock). No pacing delays: socket timeouts are failure guards only.
//!
//! Ignored by default (needs `qemu-system-arm` and the release firmware):
//!
//! ```text
//! cargo build -p firmware-example --target thumbv7em-none-eabihf --release --bin qemu-uart
//! cargo test -p ph-formation-tests --test qemu_uart -- --include-ignored
//! ```
//!
//! `cargo xtask firmware-check` runs it (the one `qemu-uart` run of a test run).
//! QEMU, the link and the log decoding are `qemu_harness`'s.
//!
//! Environment: `QEMU_SYSTEM_ARM` (QEMU binary), `PH_QEMU_UART_ELF` (firmware
//! ELF), `PH_QEMU_UART_LOG` (write the firmware's decoded defmt log there;
//! `cargo xtask firmware-check` reads its stack line), `DEFMT_PRINT`.

use std::net::TcpListener;
use std::time::{Duration, Instant};

use ph_formation_core::link::{
    HostMsg, LinkBearing, LinkOutput, LinkStep, TargetMsg, LINK_VERSION,
};
use ph_formation_core::{
    Agent, AgentConfig, AngleConfig, BearingMeasurement, LeaderConfig, LeaderRole, Measurements,
    Real, Schedule, TriangleConfig, Vec2,
};
use qemu_harness::link::Link;
use qemu_harness::{defmt, firmware, Qemu, Serial};

/// Control ticks of the session.
const TICKS: usize = 300;
/// Control period (s).
const DT: f64 = 0.01;
/// Relative tolerance of the force comparison with the host's f32 agent.
const FORCE_RTOL: f32 = 1e-3;
/// Failure guard on every socket read (not a pacing delay).
const READ_GUARD: Duration = Duration::from_secs(20);

const Q0: [[f64; 2]; 4] = [[0.9, 2.2], [2.2, 2.8], [1.8, 1.1], [3.1, 1.9]];
const FRICTION: f64 = 0.5;

/// The paper scenario's configuration of agent index `i` (id `i + 1`), SPEC §9.
fn paper_config<T: Real>(i: usize) -> AgentConfig<T, 4> {
    let t = |x: f64| T::lit(x);
    let cos45 = std::f64::consts::FRAC_1_SQRT_2;
    // (triangle vertices, [(apex, cos α*); 2]) with agent indices.
    let triangles = [
        ([0usize, 1, 2], [(0usize, 0.0f64), (2, cos45)]),
        ([1, 2, 3], [(1, cos45), (2, cos45)]),
    ];
    let mut c = AgentConfig::new(i as u8 + 1);
    c.friction = [t(FRICTION); 2];
    c.velocity_damping = [t(1.8); 2];
    c.velocity_reference = Schedule::constant([t(3.0), t(3.0)]);
    c.limits.max_force = t(1e5);
    for (vertices, angles) in triangles {
        if !vertices.contains(&i) {
            continue;
        }
        let angle = |(apex, cos): (usize, f64)| AngleConfig {
            apex: apex as u8 + 1,
            cos_desired: t(cos),
            stiffness: t(1000.0),
            damping: t(10.0),
            estimator_gain: t(1000.0),
        };
        c.triangles
            .push(TriangleConfig {
                vertices: vertices.map(|v| v as u8 + 1),
                angles: angles.map(angle),
            })
            .expect("capacity");
    }
    let leader = |role, partner| LeaderConfig {
        role,
        partner,
        stiffness: t(1.0),
        damping: [t(0.8); 2],
        displacement: Schedule::constant([t(10.0), t(-10.0)]),
    };
    c.leader = match i {
        0 => Some(leader(LeaderRole::A, 2)),
        1 => Some(leader(LeaderRole::B, 1)),
        _ => None,
    };
    c
}

fn neighbours(i: usize) -> &'static [usize] {
    match i {
        0 => &[1, 2],
        1 => &[0, 2, 3],
        2 => &[0, 1, 3],
        _ => &[1, 2],
    }
}

/// Unit bearing from `q[i]` to `q[j]`.
fn bearing(q: &[[f64; 2]; 4], i: usize, j: usize) -> [f64; 2] {
    let d = [q[j][0] - q[i][0], q[j][1] - q[i][1]];
    let r = d[0].hypot(d[1]);
    [d[0] / r, d[1] / r]
}

/// The firmware's clock: microsecond ticks, seconds as `whole + frac / hz`
/// in f32 (`firmware_example::hal::ticks_to_seconds`).
fn us_to_seconds(us: u64) -> f32 {
    (us / 1_000_000) as f32 + (us % 1_000_000) as u32 as f32 / 1_000_000.0
}

fn seconds_to_us(s: f32) -> u64 {
    (s * 1_000_000.0 + 0.5) as u64
}

/// Sends one message (failure guard: the write has [`READ_GUARD`] too).
fn send(link: &mut Link, msg: &HostMsg<4>) {
    link.send(msg)
        .unwrap_or_else(|e| panic!("sending {msg:?}: {e}"));
}

/// The next message from the target; the deadline is a failure guard only.
fn recv(link: &mut Link) -> TargetMsg {
    link.recv(Instant::now() + READ_GUARD)
        .unwrap_or_else(|e| panic!("no message from the target: {e:?}"))
}

/// What the firmware's control loop does with the same inputs, on the host.
struct Reference {
    agent: Agent<f32, 4, 8>,
    last_us: Option<u64>,
}

impl Reference {
    fn tick(
        &mut self,
        frames: &[Vec<u8>],
        step: &LinkStep,
        now_us: u64,
    ) -> (LinkOutput, Vec<Vec<u8>>) {
        for f in frames {
            let _ = self.agent.receive(f);
        }
        let dt = match self.last_us {
            Some(l) => us_to_seconds(now_us - l),
            None => 0.0,
        };
        self.last_us = Some(now_us);
        let bearings: Vec<BearingMeasurement<f32>> =
            step.bearings.iter().map(LinkBearing::measurement).collect();
        let out = self.agent.step(&Measurements {
            time: us_to_seconds(now_us),
            dt,
            velocity: Vec2::new(step.velocity[0], step.velocity[1]),
            bearings: &bearings,
            partner_offset: step.partner_offset.map(|p| Vec2::new(p[0], p[1])),
        });
        let mut sent = Vec::new();
        self.agent.frames(|b| sent.push(b.to_vec()));
        let lo = LinkOutput::new(&out, sent.len(), self.agent.stats().rejected());
        (lo, sent)
    }
}

#[test]
#[ignore = "needs qemu-system-arm and the firmware ELF; run by cargo xtask firmware-check"]
fn uart_agent_in_the_loop() {
    let elf = firmware::elf_or_env("qemu-uart", "PH_QEMU_UART_ELF");
    let elf = firmware::require_elf(&elf, "qemu-uart").unwrap_or_else(|e| panic!("{e}"));
    let out_dir = firmware::target_dir().join("qemu-tests");

    // The test listens on a free loopback port; QEMU's USART1 connects to it (QEMU is
    // killed when `qemu` is dropped, e.g. when an assertion fails).
    let listener = TcpListener::bind("127.0.0.1:0").expect("listen on a loopback port");
    let port = listener.local_addr().expect("local address").port();
    let command = Qemu::new(&elf, out_dir.join("qemu-uart")).serial(Serial::TcpClient { port });
    let mut qemu = command
        .spawn()
        .unwrap_or_else(|e| panic!("{e}: {}", command.display()));
    let stream = qemu
        .accept(&listener, Instant::now() + Duration::from_secs(20))
        .unwrap_or_else(|e| panic!("QEMU did not connect its USART1: {e}"));
    let mut link = Link::new(stream).expect("configure the connection");
    link.set_write_timeout(READ_GUARD).expect("write timeout");
    link.wait_announcement(Instant::now() + READ_GUARD)
        .unwrap_or_else(|e| panic!("no start-up announcement from the firmware: {e:?}"));

    // Handshake.
    const ME: usize = 2; // agent 3
    send(&mut link, &HostMsg::Configure(paper_config::<f32>(ME)));
    match recv(&mut link) {
        TargetMsg::Ready { id, version, .. } => {
            assert_eq!(id, 3);
            assert_eq!(version, LINK_VERSION);
        }
        other => panic!("expected Ready, got {other:?}"),
    }

    // Host side: agents 1, 2, 4 in f64, and the reference f32 agent 3.
    let mut host: Vec<(usize, Agent<f64, 4, 8>)> = [0usize, 1, 3]
        .into_iter()
        .map(|i| (i, Agent::new(paper_config::<f64>(i)).expect("config")))
        .collect();
    let mut reference = Reference {
        agent: Agent::new(paper_config::<f32>(ME)).expect("config"),
        last_us: None,
    };

    let mut q = Q0;
    let mut v = [[0.0f64; 2]; 4];
    let mut in_flight: Vec<(usize, Vec<u8>)> = Vec::new(); // frames sent last tick
    let mut clock_us: Option<u64> = None;
    let (mut first_nominal, mut max_rel, mut identical) = (None, 0.0f32, 0usize);
    let started = Instant::now();
    for k in 0..TICKS {
        let time = k as f64 * DT;
        // 1. What each agent's radio heard: last tick's frames of the others.
        let heard = |i: usize| -> Vec<Vec<u8>> {
            in_flight
                .iter()
                .filter(|(s, _)| *s != i)
                .map(|(_, f)| f.clone())
                .collect()
        };
        let for_target = heard(ME);
        let mut forces = [[0.0f64; 2]; 4];
        let mut sent_now: Vec<(usize, Vec<u8>)> = Vec::new();
        for (i, agent) in host.iter_mut() {
            for f in heard(*i) {
                let _ = agent.receive(&f);
            }
            let bearings: Vec<BearingMeasurement<f64>> = neighbours(*i)
                .iter()
                .map(|&j| {
                    let s = bearing(&q, *i, j);
                    BearingMeasurement {
                        neighbour: j as u8 + 1,
                        bearing: Vec2::new(s[0], s[1]),
                        rate: None,
                        range: None,
                    }
                })
                .collect();
            let partner = match *i {
                0 => Some(1),
                1 => Some(0),
                _ => None,
            };
            let out = agent.step(&Measurements {
                time,
                dt: if k == 0 { 0.0 } else { DT },
                velocity: Vec2::new(v[*i][0], v[*i][1]),
                bearings: &bearings,
                partner_offset: partner
                    .map(|p: usize| Vec2::new(q[p][0] - q[*i][0], q[p][1] - q[*i][1])),
            });
            forces[*i] = [out.force.x, out.force.y];
            agent.frames(|b| sent_now.push((*i, b.to_vec())));
        }

        // 2. Agent 3 on the target: Radio*, Step → Radio*, Output.
        let step = LinkStep {
            time: time as f32,
            dt: if k == 0 { 0.0 } else { DT as f32 },
            velocity: [v[ME][0] as f32, v[ME][1] as f32],
            bearings: neighbours(ME)
                .iter()
                .map(|&j| {
                    let s = bearing(&q, ME, j);
                    LinkBearing {
                        neighbour: j as u8 + 1,
                        s: [s[0] as f32, s[1] as f32],
                        rate: None,
                        range: None,
                    }
                })
                .collect(),
            partner_offset: None,
        };
        for f in &for_target {
            let frame = heapless::Vec::from_slice(f).expect("frame fits");
            link.queue(&HostMsg::Radio(frame))
                .expect("queue a radio frame");
        }
        send(&mut link, &HostMsg::Step(step.clone()));
        let mut target_frames = Vec::new();
        let mut target_estimates = Vec::new();
        let output = loop {
            match recv(&mut link) {
                TargetMsg::Radio(f) => {
                    assert!(
                        target_estimates.is_empty(),
                        "tick {k}: Radio after Estimates"
                    );
                    target_frames.push(f.to_vec());
                }
                TargetMsg::Estimates(e) => target_estimates.extend(e.iter().map(|e| e.value)),
                TargetMsg::Output(o) => break o,
                other => panic!("tick {k}: expected Radio, Estimates or Output, got {other:?}"),
            }
        };

        // 3. The same tick on the host's f32 agent (the firmware's clock rule).
        let now = match clock_us {
            None => seconds_to_us(step.time),
            Some(t) => t + seconds_to_us(step.dt),
        };
        clock_us = Some(now);
        let (expected, expected_frames) = reference.tick(&for_target, &step, now);

        assert!(
            output.force.iter().all(|x| x.is_finite()),
            "tick {k}: non-finite force {:?}",
            output.force
        );
        assert_eq!(
            output.status, expected.status,
            "tick {k}: status differs: {output:?} vs {expected:?}"
        );
        assert_eq!(
            usize::try_from(output.frames).ok(),
            Some(target_frames.len()),
            "tick {k}: frame count"
        );
        let diff = ((output.force[0] - expected.force[0]).powi(2)
            + (output.force[1] - expected.force[1]).powi(2))
        .sqrt();
        let scale = expected.force[0].hypot(expected.force[1]).max(1e-6);
        let rel = diff / scale;
        max_rel = max_rel.max(rel);
        assert!(
            rel <= FORCE_RTOL,
            "tick {k}: force {:?} differs from the host f32 agent's {:?} (relative {rel:e})",
            output.force,
            expected.force
        );
        let expected_estimates: Vec<f32> =
            reference.agent.owned_estimates().map(|e| e.value).collect();
        assert_eq!(
            target_estimates.len(),
            expected_estimates.len(),
            "tick {k}: estimates"
        );
        for (a, b) in target_estimates.iter().zip(&expected_estimates) {
            assert!(
                (a - b).abs() <= FORCE_RTOL * b.abs(),
                "tick {k}: estimate {a} vs {b}"
            );
        }
        if output.force == expected.force
            && target_frames == expected_frames
            && target_estimates == expected_estimates
        {
            identical += 1;
        }
        let nominal = output.status == ph_formation_core::Status::Nominal;
        if nominal && first_nominal.is_none() {
            first_nominal = Some(k);
        }
        if k >= 1 {
            // Every neighbour has been heard since tick 1 (one tick of latency).
            assert!(
                nominal,
                "tick {k}: not nominal after the neighbours were heard: {output:?}"
            );
        } else {
            assert!(!nominal, "tick 0 cannot be nominal (nothing heard yet)");
        }

        // 4. Plant (semi-implicit Euler at the control period), radio.
        forces[ME] = [f64::from(output.force[0]), f64::from(output.force[1])];
        for i in 0..4 {
            for a in 0..2 {
                v[i][a] += DT * (forces[i][a] - FRICTION * v[i][a]);
                q[i][a] += DT * v[i][a];
            }
        }
        in_flight = sent_now;
        in_flight.extend(target_frames.into_iter().map(|f| (ME, f)));
    }
    let elapsed = started.elapsed();

    send(&mut link, &HostMsg::Finish);
    match recv(&mut link) {
        TargetMsg::Finished { accepted, rejected } => {
            assert_eq!(
                accepted,
                reference.agent.stats().accepted,
                "accepted frames"
            );
            assert_eq!(
                rejected,
                reference.agent.stats().rejected(),
                "rejected frames"
            );
        }
        other => panic!("expected Finished, got {other:?}"),
    }
    // The firmware exits right after `Finished`; the limit is a failure guard only.
    let status = qemu.wait_or_kill(READ_GUARD);
    let log = defmt::decode_or_note(&elf, &qemu.log);
    if let Some(path) = std::env::var_os("PH_QEMU_UART_LOG") {
        std::fs::write(&path, &log).expect("write PH_QEMU_UART_LOG");
    }
    assert_eq!(
        status.and_then(|s| s.code()),
        Some(0),
        "qemu-uart exit status {status:?} ({}); firmware log:\n{log}",
        qemu.stderr_tail()
    );

    let tps = TICKS as f64 / elapsed.as_secs_f64();
    println!(
        "qemu-uart: {TICKS} lock-step ticks in {:.3} s = {tps:.0} ticks/s of wall clock; \
         {} bytes to the target, {} bytes back; first nominal tick {first_nominal:?}; \
         max relative force difference {max_rel:e}; {identical}/{TICKS} ticks bit-identical (force, frames, estimates)",
        elapsed.as_secs_f64(),
        link.counters.bytes_to_target,
        link.counters.bytes_from_target,
    );
    println!("firmware log:\n{log}");
    assert_eq!(first_nominal, Some(1));
}

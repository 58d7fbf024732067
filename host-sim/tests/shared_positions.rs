//! Bearings from shared positions (`sensors.bearing_source = "shared_positions"`,
//! docs/sensors.md): on the sensor itself (`engine::sensors::SharedPositions`: the table
//! of heard positions, staleness, the noise) and in runs (convergence with σ = 0, the
//! packets' share of the shared channel, the same bits on 1 and 4 threads), and bad
//! settings refused with file, field and reason.

#[path = "support/docs.rs"]
mod docs;
mod support;
use ph_formation_core::wire::auth::SwarmKey;
use ph_formation_core::wire::position::{position_len, PositionPacket, MAX_POSITION_LEN};
use ph_formation_core::{Integrity, Vec2};
use ph_formation_sim::engine::radio::RadioFrame;
use ph_formation_sim::engine::sensors::{
    BearingKind, BearingSensor, Sensors, SharedPositions, World, POSITION_VERSION,
};
use ph_formation_sim::engine::{run, Engine, NullRecorder, SampledSim, PARALLEL_MIN_AGENTS};
use ph_formation_sim::load;
use ph_formation_sim::model::{BearingRate, Model, PositionsModel, SensorModel};
use ph_formation_sim::scenario::strip_model;

/// A swarm key for the `auth` runs.
const KEY: &str = "controller.auth_key=000102030405060708090a0b0c0d0e0f";

const KIND: BearingKind = BearingKind {
    exact_rate: false,
    with_range: false,
};

fn owned(sets: &[&str]) -> Vec<String> {
    sets.iter().map(|s| (*s).to_owned()).collect()
}

/// `scenario` with shared positions and the extra `sets`.
fn shared(scenario: &str, sets: &[&str]) -> Model {
    let mut all = owned(&["sensors.bearing_source=shared_positions"]);
    all.extend(owned(sets));
    load(scenario, &all).expect("load")
}

/// Agent `i`'s bearing of `j` (true state `q`, at rest) through `p`, drawn from an
/// ideal sensor's stream.
fn bearing(p: &SharedPositions, q: &[Vec2<f64>], i: usize, j: usize) -> Option<Vec2<f64>> {
    let v = vec![Vec2::zeros(); q.len()];
    let h = vec![0.0; q.len()];
    let world = World {
        q,
        v: &v,
        headings: &h,
    };
    let ids: Vec<u8> = (1..=q.len() as u8).collect();
    let s = Sensors::new(&SensorModel::ideal(BearingRate::FiniteDifference), 3);
    p.bearing(&world, &ids, i, j, KIND, &mut s.stream(i, 0))
        .map(|b| b.bearing)
}

/// formation-only's model and its agent 0's first radio neighbour.
fn pair(noise: f64, max_age: f64) -> (Model, PositionsModel, usize) {
    let m = shared("formation-only", &[]);
    let p = PositionsModel { noise, max_age };
    let j = m.graph.radio.of(0)[0];
    (m, p, j)
}

#[test]
fn a_heard_position_gives_the_bearing_until_it_is_older_than_max_age() {
    let (m, settings, j) = pair(0.0, 0.1);
    assert_eq!(m.agents[j].id as usize, j + 1, "ids 1..=4");
    let mut p = SharedPositions::new(&m, &settings);
    let mut q = vec![Vec2::zeros(); m.n()];
    q[j] = Vec2::new(3.0, 4.0);
    let mut inboxes = vec![Vec::new(); m.n()];
    // Nothing heard yet: no bearing.
    p.hear(0.0, 0, &q, &mut inboxes);
    assert_eq!(bearing(&p, &q, 0, j), None);
    // j's packet of tick 0 reaches agent 0 with a formation frame: the packet is taken
    // out, the frame stays.
    let frame = RadioFrame::new(&[0x84; 20]);
    inboxes[0].push(frame);
    inboxes[0].push(p.packet(j));
    // The core's packet under the scenario's integrity (crc16): 11 bytes and the CRC.
    assert_eq!(
        p.packet(j).as_bytes().len(),
        position_len(&Integrity::Crc16)
    );
    assert_eq!(p.packet(j).as_bytes()[0], POSITION_VERSION);
    p.hear(0.01, 1, &q, &mut inboxes);
    assert_eq!(inboxes[0], vec![frame]);
    assert_eq!(p.packets_heard(), 1);
    assert_eq!(bearing(&p, &q, 0, j), Some(Vec2::new(0.6, 0.8)));
    // j moves; agent 0 keeps using what it heard, until it is older than 0.1 s.
    q[j] = Vec2::new(-5.0, 0.0);
    inboxes[0].clear();
    p.hear(0.11, 11, &q, &mut inboxes);
    assert_eq!(bearing(&p, &q, 0, j), Some(Vec2::new(0.6, 0.8)));
    p.hear(0.111, 12, &q, &mut inboxes);
    assert_eq!(bearing(&p, &q, 0, j), None);
    // A fresh packet brings it back, at j's new position.
    inboxes[0].push(p.packet(j));
    p.hear(0.12, 13, &q, &mut inboxes);
    assert_eq!(bearing(&p, &q, 0, j), Some(Vec2::new(-1.0, 0.0)));
    // Only the receiver's own table: agent 0 heard nothing of the others.
    let k = m.graph.radio.of(0)[1];
    q[k] = Vec2::new(1.0, 0.0);
    assert_eq!(bearing(&p, &q, 0, k), None);
}

#[test]
fn position_noise_gives_bearing_errors_of_sigma_root_two_over_r() {
    // Both ends noisy and independent: the angle error's standard deviation is
    // √(σ² + σ²) / r (the components across the line of sight).
    let (sigma, r) = (0.01, 2.0);
    let (m, settings, j) = pair(sigma, 0.1);
    let mut p = SharedPositions::new(&m, &settings);
    let mut q = vec![Vec2::zeros(); m.n()];
    q[j] = Vec2::new(r, 0.0);
    let mut inboxes = vec![Vec::new(); m.n()];
    let trials = 20_000u64;
    let mut errors = Vec::with_capacity(trials as usize);
    for k in 0..trials {
        let t = k as f64 * 0.01;
        p.hear(t, 2 * k, &q, &mut inboxes);
        inboxes[0].push(p.packet(j));
        p.hear(t, 2 * k + 1, &q, &mut inboxes);
        let b = bearing(&p, &q, 0, j).expect("fresh");
        errors.push(b.y.atan2(b.x));
    }
    let n = trials as f64;
    let mean = errors.iter().sum::<f64>() / n;
    let sd = (errors.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / n).sqrt();
    let expected = sigma * 2f64.sqrt() / r;
    // The sample deviation is within 1/√(2n) = 0.5 % of the truth (one sd).
    assert!((sd / expected - 1.0).abs() < 0.03, "{sd} vs {expected}");
    assert!(mean.abs() < 5.0 * expected / n.sqrt(), "{mean}");
    // σ = 0: the exact bearing (to f32 precision of the positions).
    let (m, settings, j) = pair(0.0, 0.1);
    let mut p = SharedPositions::new(&m, &settings);
    p.hear(0.0, 0, &q, &mut inboxes);
    inboxes[0].push(p.packet(j));
    p.hear(0.01, 1, &q, &mut inboxes);
    assert_eq!(bearing(&p, &q, 0, j), Some(Vec2::new(1.0, 0.0)));
}

/// The outcome, final largest angle error, settle time and final displacement error of
/// `m`'s run.
fn outcome(m: &Model) -> (String, f64, Option<f64>, f64) {
    let r = run(m, &mut NullRecorder, &mut |_| {}).expect("run");
    (
        format!("{:?}", r.outcome),
        r.final_max_angle_error,
        r.settle_time,
        r.final_displacement_error,
    )
}

#[test]
fn sigma_zero_with_an_ideal_radio_converges_like_the_ideal_sensor() {
    let ideal = load("formation-only", &owned(&["duration=20"])).expect("load");
    let positions = shared("formation-only", &["duration=20"]);
    let (a, ea, sa, _) = outcome(&ideal);
    let (b, eb, sb, _) = outcome(&positions);
    assert_eq!((a.as_str(), b.as_str()), ("Converged", "Converged"));
    assert!(eb < 1e-3, "{eb} (ideal {ea})");
    // The bearings are of the packets of the last tick, one control period older than
    // the ideal sensor's: the settle time within a few percent.
    let (sa, sb) = (sa.expect("settled"), sb.expect("settled"));
    assert!((sb - sa).abs() < 0.05 * sa, "{sb} s vs {sa} s");
    // With every packet lost (positions and frames), nothing is measured: no convergence.
    let lost = shared("formation-only", &["duration=20", "radio.loss=1"]);
    // Every agent in its safe output all along: not in control.
    assert_eq!(outcome(&lost).0, "NotInControl");
}

#[test]
fn a_moving_formation_lags_by_its_speed_times_the_packets_age() {
    // The paper's square moves at v* = (3, 3) m/s. The leader's partner offset is the
    // partner's position of the last tick against its own of this one: the leader edge
    // settles short by |v*| T (T = 0.01 s), 4.24 cm, where the ideal sensor's is exact.
    let (_, _, _, ideal) = outcome(&load("paper", &[]).expect("load"));
    let (_, _, _, lag) = outcome(&shared("paper", &[]));
    assert!(ideal < 1e-4, "{ideal}");
    let expected = 18f64.sqrt() * 0.01;
    assert!((lag / expected - 1.0).abs() < 0.02, "{lag} vs {expected}");
}

/// The shared channel's air time and transmissions over `ticks` ticks of `m`, after
/// `warm` ticks (at the first ticks the agents have heard no positions yet, and their
/// frames carry fewer items than the ideal sensor's).
fn channel_over(m: &Model, warm: usize, ticks: usize) -> (f64, u64, u64) {
    let mut sim = SampledSim::new(m).expect("sim");
    sim.advance_ticks(0.0, warm);
    let a = sim.channel_stats().expect("a channel");
    sim.advance_ticks(warm as f64 * m.control_period(), ticks);
    let b = sim.channel_stats().expect("a channel");
    (
        b.air_time - a.air_time,
        b.transmissions - a.transmissions,
        b.access_dropped,
    )
}

#[test]
fn the_position_packets_are_load_on_the_shared_channel() {
    let base = ["duration=3", "radio.channel.preset=crazyflie"];
    let (warm, ticks) = (20, 150);
    let plain = load("formation-only", &owned(&base)).expect("load");
    let air = plain.radio.channel.as_ref().expect("channel").clone();
    for integrity in ["crc16", "link", "auth"] {
        let set = format!("controller.integrity={integrity}");
        let key = if integrity == "auth" { KEY } else { base[0] };
        let sets = [base[0], base[1], &set, key];
        let m = shared("formation-only", &sets);
        let plain = load("formation-only", &owned(&sets)).expect("load");
        let (air0, tx0, drop0) = channel_over(&plain, warm, ticks);
        let (air1, tx1, drop1) = channel_over(&m, warm, ticks);
        assert_eq!((drop0, drop1), (0, 0));
        // One packet per agent per tick, each the air time of the core's packet.
        let bytes = position_len(&m.integrity.core(&m.auth_key));
        let packets = (m.n() * ticks) as u64;
        assert_eq!(tx1 - tx0, packets, "{integrity}");
        let share = packets as f64 * air.air_time(bytes);
        assert!(
            ((air1 - air0) - share).abs() < 1e-9 * share,
            "{integrity} ({bytes} bytes): {} s more, expected {share} s",
            air1 - air0
        );
    }
}

/// Under `auth` a position is accepted only with the swarm's tag and a counter above the
/// last one accepted from its sender: a spoofed packet (another key), a replay and a
/// corrupted copy are refused and give no bearing; the genuine packet gives one.
#[test]
fn spoofed_and_replayed_positions_are_refused_under_auth() {
    let m = shared("formation-only", &["controller.integrity=auth", KEY]);
    let settings = PositionsModel {
        noise: 0.0,
        max_age: 1.0,
    };
    let j = m.graph.radio.of(0)[0];
    let mut p = SharedPositions::new(&m, &settings);
    let mut q = vec![Vec2::zeros(); m.n()];
    q[j] = Vec2::new(3.0, 4.0);
    let mut inboxes = vec![Vec::new(); m.n()];
    p.hear(0.0, 0, &q, &mut inboxes);
    let genuine = p.packet(j);
    assert_eq!(genuine.as_bytes().len(), MAX_POSITION_LEN);
    // A spoofer without the key: j's id at another position, tagged under its own key.
    let forged = {
        let packet = PositionPacket {
            sender: m.agents[j].id,
            position: [-3.0, 0.0],
        };
        let other = Integrity::Auth(SwarmKey::new([0x5a; 16]));
        let mut b = [0u8; MAX_POSITION_LEN];
        let n = packet.encode(&other, 1_000, &mut b).expect("encode");
        RadioFrame::new(&b[..n])
    };
    let mut corrupted = genuine.as_bytes().to_vec();
    corrupted[4] ^= 0x01;
    inboxes[0].push(forged);
    inboxes[0].push(RadioFrame::new(&corrupted));
    p.hear(0.01, 1, &q, &mut inboxes);
    assert_eq!(
        bearing(&p, &q, 0, j),
        None,
        "spoofed or corrupted: no bearing"
    );
    assert_eq!(p.packets_refused(), 2);
    // The genuine packet (negative control: the check accepts what it should).
    inboxes[0].push(genuine);
    p.hear(0.02, 2, &q, &mut inboxes);
    assert_eq!(bearing(&p, &q, 0, j), Some(Vec2::new(0.6, 0.8)));
    // j moves and sends again; then an attacker replays the first packet: refused, the
    // bearing stays the new one.
    q[j] = Vec2::new(-5.0, 0.0);
    p.hear(0.03, 3, &q, &mut inboxes);
    inboxes[0].push(p.packet(j));
    p.hear(0.04, 4, &q, &mut inboxes);
    assert_eq!(bearing(&p, &q, 0, j), Some(Vec2::new(-1.0, 0.0)));
    inboxes[0].push(genuine);
    p.hear(0.05, 5, &q, &mut inboxes);
    assert_eq!(p.packets_refused(), 3, "the replay is refused");
    assert_eq!(bearing(&p, &q, 0, j), Some(Vec2::new(-1.0, 0.0)));
}

/// docs/crazyflie.md, "The packets' share of the channel", on `crazyflie-app/formation.toml`
/// over 60 s: the packets' air time is their closed form (`24,004` = 4 agents × 6,001
/// ticks, each `(packet_bytes + overhead) · 8 / bit rate` = 84.5 µs), the utilisation
/// with and without them and ALOHA's collided link copies are the doc's (link copies:
/// 6,001 ticks × 10 links of the square's graph, twice with the packets).
#[test]
fn the_crazyflie_channel_figures_of_crazyflie_md_are_measured() {
    let square = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../crazyflie-app/formation.toml"
    );
    let doc = docs::read("docs/crazyflie.md");
    let para = docs::between(
        &doc,
        "The packets' share of the channel:",
        "the bearings survive it",
    );
    let runs = |access: &str, positions: bool| {
        let mut sets = vec![
            "radio.channel.preset=crazyflie".to_owned(),
            format!("radio.channel.access={access}"),
        ];
        if positions {
            sets.push("sensors.bearing_source=shared_positions".to_owned());
        }
        let m = load(square, &sets).expect("load");
        let r = run(&m, &mut NullRecorder, &mut |_| {}).expect("run");
        (m, r)
    };
    let (m, plain) = runs("aloha", false);
    let (_, with) = runs("aloha", true);
    let ch = m.radio.channel.as_ref().expect("channel");
    let bytes = position_len(&m.integrity.core(&m.auth_key));
    let ticks = (m.duration / m.control_period()).round() as u64 + 1;
    let packets = m.n() as u64 * ticks;
    let each = (bytes as f64 + ch.overhead_bytes) * 8.0 / ch.bit_rate;
    assert_eq!(
        docs::number(&para, "air time per 60 s:", " packets of"),
        packets as f64
    );
    assert!(docs::shows(
        each * 1e6,
        &docs::between(&para, "packets of", " µs")
    ));
    // The app's packet (docs/crazyflie.md: "13 bytes with `crc16`, 27 with `auth`") is the
    // core's; on the same channel it would take "96.5 µs on the air".
    use ph_formation_core::wire::{position, Integrity};
    let crc16 = position::position_len(&Integrity::Crc16);
    let sizes = docs::between(
        &doc,
        "in the core's position packet on P2P port 1 every tick (",
        " with `auth`",
    );
    assert_eq!(
        sizes,
        format!("{crc16} bytes with `crc16`, {}", position::MAX_POSITION_LEN)
    );
    let app_air = (crc16 as f64 + ch.overhead_bytes) * 8.0 / ch.bit_rate;
    let said = docs::between(
        &doc,
        "the app's packet with `crc16` is 13 bytes,",
        " µs on the air",
    );
    assert!(
        docs::shows(app_air * 1e6, &said),
        "{said} µs, closed form {app_air} s"
    );
    let (a, b) = (
        plain.channel.expect("channel"),
        with.channel.expect("channel"),
    );
    // The packets' air time, and the run's extra air time within the formation frames
    // of one tick of the four agents (60 bytes each): before any position is heard the
    // frames carry fewer items than with the ideal sensor (measured: 60 bytes fewer).
    let packets_air = packets as f64 * each;
    let extra = b.air_time - a.air_time;
    let slack = m.n() as f64 * 60.0 * 8.0 / ch.bit_rate;
    assert!(
        (extra - packets_air).abs() <= slack,
        "{extra} s vs {packets_air} s"
    );
    assert!(docs::shows(
        packets_air,
        &docs::between(&para, "9.5 % (", " s of air time")
    ));
    // Utilisation: air time over the run's time (docs/outputs.md).
    let util = |air: f64, t: f64| format!("{:.1}", 100.0 * air / t);
    let said = docs::between(&para, "utilisation from", " s of air time");
    assert!(
        said.starts_with(&format!(
            "{} % to {} %",
            util(a.air_time, plain.final_time),
            util(b.air_time, with.final_time)
        )),
        "{said}"
    );
    // ALOHA's collisions: "from 8.3 % (4,986 of 60,010) to 13.6 % (16,322 of 120,020".
    let links: u64 = 10;
    assert_eq!(
        (plain.frames.sent, with.frames.sent),
        (ticks * links, 2 * ticks * links)
    );
    let copies = docs::between(&para, "lost to collisions from", ", packets included");
    let stated: Vec<f64> = copies
        .split(|c: char| !(c.is_ascii_digit() || c == ',' || c == '.'))
        .filter_map(docs::parse)
        .collect();
    let pct = |c: u64, n: u64| (100.0 * c as f64 / n as f64 * 10.0).round() / 10.0;
    let want = [
        pct(a.collided, plain.frames.sent),
        a.collided as f64,
        plain.frames.sent as f64,
        pct(b.collided, with.frames.sent),
        b.collided as f64,
        with.frames.sent as f64,
    ];
    assert_eq!(stated, want, "docs/crazyflie.md: {copies}");
}

use support::bits;

#[test]
fn a_shared_positions_run_gives_the_same_bits_on_1_and_4_threads() {
    let n = PARALLEL_MIN_AGENTS + 300;
    let mut m = strip_model(n, 1.0).unwrap();
    m.radio.loss = 0.2;
    m.sensors.positions = Some(PositionsModel {
        noise: 0.003,
        max_age: 0.03,
    });
    let one = bits(&m, 20, 1);
    assert!(one == bits(&m, 20, 4), "the states differ");
    // The positions' noise is in the run (the test is not comparing ideal runs).
    let mut quiet = m.clone();
    if let Some(p) = quiet.sensors.positions.as_mut() {
        p.noise = 0.0;
    }
    assert!(one != bits(&quiet, 20, 1));
}

#[test]
fn every_positions_field_can_be_set() {
    let m = shared(
        "formation-only",
        &[
            "sensors.positions.noise_m=0.003",
            "sensors.positions.max_age_s=0.25",
        ],
    );
    let p = m.sensors.positions.clone().expect("shared positions");
    assert_eq!((p.noise, p.max_age), (0.003, 0.25));
    assert!(!ph_formation_sim::engine::direct_radio(&m));
    // The source alone: the defaults.
    let p = shared("formation-only", &[])
        .sensors
        .positions
        .expect("shared");
    assert_eq!((p.noise, p.max_age), (0.0, 0.1));
    let plain = load("formation-only", &[]).expect("load");
    assert!(plain.sensors.positions.is_none());
    assert!(ph_formation_sim::engine::direct_radio(&plain));
}

#[test]
fn bad_positions_settings_are_refused_with_file_field_and_reason() {
    let file = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios/formation-only.toml");
    let source = "sensors.bearing_source=shared_positions";
    let cases: &[(&[&str], &str, &str)] = &[
        (&["noise_m=-0.01"], "sensors.positions.noise_m", "≥ 0"),
        (&["noise_m=nan"], "sensors.positions.noise_m", "≥ 0"),
        (&["max_age_s=0"], "sensors.positions.max_age_s", "> 0"),
        (&["max_age_s=-1"], "sensors.positions.max_age_s", "> 0"),
        (&["max_age_s=nan"], "sensors.positions.max_age_s", "> 0"),
        (
            &["packet_bytes=10"],
            "sensors.positions.packet_bytes",
            "the core's position packet",
        ),
    ];
    for (sets, field, reason) in cases {
        let mut all = vec![source.to_owned()];
        all.extend(sets.iter().map(|s| format!("sensors.positions.{s}")));
        let e = load(file, &all).expect_err(sets[0]);
        let first = &e.0[0];
        assert_eq!(first.field, *field, "{sets:?}: {e}");
        assert_eq!(first.file, file, "{sets:?}: {e}");
        assert!(first.reason.contains(reason), "{sets:?}: {e}");
    }
    let with = |other: &str| {
        let sets = [source.to_owned(), other.to_owned()];
        load(file, &sets).expect_err(other).0[0].clone()
    };
    // One bearing source; no rates from positions; no radio in continuous mode.
    let e = with("sensors.camera.fov_deg=90");
    assert_eq!(e.field, "sensors.camera");
    assert!(e.reason.contains("one bearing source"), "{e}");
    assert_eq!(
        with("sensors.bearing_rate=exact").field,
        "sensors.bearing_rate"
    );
    assert_eq!(with("mode=continuous").field, "sensors.bearing_source");
    // Positions settings without the source have no effect: refused.
    let e = load(file, &owned(&["sensors.positions.noise_m=0.01"])).expect_err("no source");
    assert_eq!(e.0[0].field, "sensors.positions");
    let e = load(file, &owned(&["sensors.bearing_source=gps"])).expect_err("unknown source");
    assert!(e.to_string().contains("bearing_source"), "{e}");
    // Edges accepted.
    let ok = [source.to_owned(), "sensors.positions.noise_m=0".to_owned()];
    assert!(load(file, &ok).is_ok());
}

//! The channel through the radio: collisions, TDMA, range, faults on top, determinism.

use crate::engine::channel::ChannelStats;
use crate::engine::radio::{Radio, RadioFrame, RadioStats};
use crate::model::graph::{strip_triangles, Adjacency, Graph};
use crate::model::{Access, ChannelModel, RadioModel};
use ph_formation_core::Vec2;

const PERIOD: f64 = 0.01;

fn channel(access: Access, bit_rate: f64) -> ChannelModel {
    let mut c = ChannelModel {
        preset: "custom".to_owned(),
        access,
        bit_rate,
        overhead_bytes: 11.125,
        turnaround: 130e-6,
        range: None,
        aloha_window: PERIOD,
        slot: 0.0,
    };
    c.slot = c.turnaround + c.air_time(ph_formation_core::MAX_FRAME_LEN);
    c
}

fn everyone(n: usize) -> Adjacency {
    Adjacency::from_pairs(n, (0..n).flat_map(|a| (a + 1..n).map(move |b| [a, b])))
}

/// Every agent broadcasts one `len`-byte frame per tick for `ticks` ticks, at
/// positions `q`; the inboxes are emptied every tick. Returns the radio's counters, the
/// channel's, and the frames delivered per agent.
fn run(
    m: &RadioModel,
    q: &[Vec2<f64>],
    len: usize,
    ticks: usize,
    seed: u64,
) -> (RadioStats, ChannelStats, Vec<usize>) {
    let n = q.len();
    let graph = everyone(n);
    let mut r = Radio::new(m, n, seed, 1024);
    r.attach_channel(&graph, PERIOD);
    r.observe(q);
    let mut inboxes: Vec<Vec<RadioFrame>> = vec![Vec::new(); n];
    let mut got = vec![0; n];
    let frame = vec![0xA5u8; len];
    for k in 0..=ticks {
        let t = k as f64 * PERIOD;
        r.deliver(t, &mut inboxes);
        for (i, inbox) in inboxes.iter_mut().enumerate() {
            got[i] += inbox.len();
            inbox.clear();
        }
        if k < ticks {
            for i in 0..n {
                r.broadcast(t, i, graph.of(i), &frame);
            }
        }
    }
    // The ages as sampled at the ticks; then let everything in flight land.
    let ages = r.channel_stats().expect("channel");
    r.deliver(ticks as f64 * PERIOD + 10.0, &mut inboxes);
    for (i, inbox) in inboxes.iter().enumerate() {
        got[i] += inbox.len();
    }
    let mut c = r.channel_stats().expect("channel");
    (c.mean_age, c.max_age) = (ages.mean_age, ages.max_age);
    (*r.stats(), c, got)
}

fn line(n: usize, spacing: f64) -> Vec<Vec2<f64>> {
    (0..n).map(|i| Vec2::new(i as f64 * spacing, 0.0)).collect()
}

fn radio(c: ChannelModel) -> RadioModel {
    RadioModel {
        channel: Some(c),
        ..RadioModel::ideal()
    }
}

#[test]
fn aloha_collides_when_the_channel_is_overloaded() {
    // 4 agents, 40-byte frames: at 2 Mbit/s a frame is 205 µs on the air (8 % load);
    // at 100 kbit/s it is 4.1 ms, so four per 10 ms tick overload the medium.
    let q = line(4, 1.0);
    let (light, cl, _) = run(&radio(channel(Access::Aloha, 2e6)), &q, 40, 500, 1);
    let (heavy, ch, _) = run(&radio(channel(Access::Aloha, 1e5)), &q, 40, 500, 1);
    assert_eq!(cl.transmissions, 2000);
    assert_eq!(ch.transmissions, 2000);
    let lost_light = cl.collided as f64 / light.sent as f64;
    let lost_heavy = ch.collided as f64 / heavy.sent as f64;
    // Pure ALOHA with 3 other frames spread uniformly over the window: a copy is lost
    // with probability about 1 − (1 − 2τ/T)^3 (τ air time, T window).
    let expect = |tau: f64| 1.0 - (1.0 - 2.0 * tau / PERIOD).powi(3);
    let tau_light = channel(Access::Aloha, 2e6).air_time(40);
    assert!(
        (lost_light - expect(tau_light)).abs() < 0.03,
        "light load: {lost_light} vs {}",
        expect(tau_light)
    );
    assert!(lost_heavy > 0.9, "heavy load: only {lost_heavy} lost");
    // Every copy is accounted for: delivered, or lost to a collision.
    assert_eq!(heavy.delivered + ch.collided, heavy.sent);
    assert_eq!(heavy.channel_lost, ch.collided);
    assert_eq!(heavy.dropped(), ch.collided);
    assert!(ch.collided_transmissions > 0 && ch.collided_transmissions <= ch.transmissions);
    assert!((cl.utilisation(5.0) - 2000.0 * tau_light / 5.0).abs() < 1e-9);
}

#[test]
fn tdma_never_collides_and_its_latency_is_the_wait_for_the_slot() {
    let q = line(20, 1.0);
    let c = channel(Access::Tdma, 2e6);
    let superframe = c.superframe(20);
    assert!(
        superframe < PERIOD,
        "20 slots fit in one tick: {superframe}"
    );
    let (r, s, got) = run(&radio(c.clone()), &q, 60, 200, 3);
    assert_eq!(s.collided, 0);
    assert_eq!(s.collided_transmissions, 0);
    assert_eq!(r.delivered, r.sent);
    assert!(got.iter().all(|&g| g == 19 * 200), "{got:?}");
    // A frame waits for its own slot: at most one superframe, and agent 19 at t = 0
    // waits 19 slots.
    let w = s.max_access_wait;
    assert!(w >= 19.0 * c.slot - 1e-9 && w <= superframe + 1e-9, "{w}");
    // Every frame arrives before the next tick: neighbour data is one period old.
    assert!((s.max_age - PERIOD).abs() < 1e-9, "{}", s.max_age);
    assert!((s.mean_age - PERIOD).abs() < 1e-9, "{}", s.mean_age);

    // Overloaded (100 kbit/s: a slot is 6 ms, the superframe 120 ms): frames queue for
    // their slots and the ones that would wait beyond the queue limit are not sent,
    // but nothing ever collides.
    let c = channel(Access::Tdma, 1e5);
    let (r, s, _) = run(&radio(c), &q, 60, 200, 3);
    assert_eq!(s.collided, 0);
    assert!(s.access_dropped > 0);
    assert_eq!(r.queue_dropped, s.access_dropped * 19);
    assert_eq!(r.delivered + r.queue_dropped, r.sent);
}

#[test]
fn range_limits_who_hears_whom() {
    // A — B far from C — D, range 15 m: A and C never disturb each other's receivers.
    let q = vec![
        Vec2::new(0.0, 0.0),
        Vec2::new(10.0, 0.0),
        Vec2::new(100.0, 0.0),
        Vec2::new(110.0, 0.0),
    ];
    let mut c = channel(Access::Aloha, 1e5); // heavily overloaded if everyone heard
    c.range = Some(15.0);
    let (r, s, got) = run(&radio(c.clone()), &q, 40, 300, 5);
    // Each agent reaches 1 of its 3 neighbours.
    assert_eq!(s.out_of_range, 2 * 4 * 300);
    assert_eq!(r.delivered + s.collided + s.out_of_range, r.sent);
    assert!(got.iter().all(|&g| g > 0), "{got:?}");
    // Within a pair: two senders 4.1 ms each per 10 ms collide often, but far less than
    // with all four on one medium.
    c.range = None;
    let (_, all, _) = run(&radio(c), &q, 40, 300, 5);
    assert_eq!(all.out_of_range, 0);
    assert!(
        s.collided < all.collided / 3,
        "range {} vs everyone {}",
        s.collided,
        all.collided
    );
}

#[test]
fn channel_and_link_loss_combine() {
    let q = line(6, 1.0);
    let mut m = radio(channel(Access::Tdma, 2e6));
    m.loss = 0.3;
    m.latency = 0.002;
    let (r, s, _) = run(&m, &q, 50, 400, 9);
    assert_eq!(s.collided, 0);
    let lost = r.lost as f64 / r.sent as f64;
    assert!((0.27..0.33).contains(&lost), "{lost}");
    assert_eq!(r.delivered + r.lost, r.sent);
    assert_eq!(r.dropped(), r.lost);

    let mut m = radio(channel(Access::Aloha, 2e5));
    m.loss = 0.3;
    let (r, s, _) = run(&m, &q, 50, 400, 9);
    assert!(s.collided > 0 && r.lost > 0);
    // Loss applies to the copies that survived the channel.
    assert_eq!(r.delivered + r.lost + s.collided, r.sent);
    let lost = r.lost as f64 / (r.sent - s.collided) as f64;
    assert!((0.26..0.34).contains(&lost), "{lost}");
    assert_eq!(r.dropped(), r.lost + s.collided);
}

#[test]
fn same_seed_same_channel() {
    let q = line(8, 1.0);
    let m = radio(channel(Access::Aloha, 3e5));
    let a = run(&m, &q, 45, 300, 11);
    let b = run(&m, &q, 45, 300, 11);
    let c = run(&m, &q, 45, 300, 12);
    assert_eq!(a.0, b.0);
    assert_eq!(a.1, b.1);
    assert_eq!(a.2, b.2);
    assert_ne!(a.1.collided, c.1.collided, "the seed changes nothing");
}

#[test]
fn hidden_terminals_collide_at_the_receiver_that_hears_both() {
    // A — B — C, range 12 m: A and C do not hear each other, B hears both. A and C
    // send at the same instant (no random start): B loses both, nobody else loses.
    let mut c = channel(Access::Aloha, 2e6);
    c.aloha_window = 0.0;
    c.range = Some(12.0);
    let q = line(3, 10.0);
    let graph = everyone(3);
    let mut r = Radio::new(&radio(c), 3, 1, 64);
    r.attach_channel(&graph, PERIOD);
    r.observe(&q);
    r.broadcast(0.0, 0, graph.of(0), &[1; 30]);
    r.broadcast(0.0, 2, graph.of(2), &[2; 30]);
    let mut inboxes: Vec<Vec<RadioFrame>> = vec![Vec::new(); 3];
    r.deliver(PERIOD, &mut inboxes);
    let s = r.channel_stats().expect("channel");
    assert_eq!(s.collided, 2, "B loses A's and C's frame");
    assert_eq!(s.out_of_range, 2, "A → C and C → A");
    assert!(inboxes.iter().all(Vec::is_empty));
    // B alone: A and C both receive it.
    r.broadcast(PERIOD, 1, graph.of(1), &[3; 30]);
    r.deliver(2.0 * PERIOD, &mut inboxes);
    assert_eq!(inboxes[0].len(), 1);
    assert_eq!(inboxes[2].len(), 1);
    assert_eq!(r.channel_stats().expect("channel").collided, 2);
}

/// Inspections per link copy of a strip of `n` agents (each hears ≤ 4 neighbours on
/// the radio graph, everyone on the medium) over `ticks` ticks.
fn inspected_per_copy(range: Option<f64>, n: usize, ticks: usize) -> f64 {
    // The strip of `scenario::strip_model`: triangles (i, i+1, i+2), 0.5 m apart.
    let g = Graph::new(n, &strip_triangles(n), None);
    let graph = &g.radio;
    let mut c = channel(Access::Aloha, 2e5);
    c.range = range;
    let mut r = Radio::new(&radio(c), n, 1, 1024);
    r.attach_channel(graph, PERIOD);
    let h = 3f64.sqrt() / 2.0;
    let q: Vec<Vec2<f64>> = (0..n)
        .map(|i| Vec2::new(0.5 * i as f64, h * (i % 2) as f64))
        .collect();
    r.observe(&q);
    let mut inboxes: Vec<Vec<RadioFrame>> = vec![Vec::new(); n];
    for k in 0..ticks {
        let t = k as f64 * PERIOD;
        r.deliver(t, &mut inboxes);
        inboxes.iter_mut().for_each(Vec::clear);
        for i in 0..n {
            if k % (n / 20).max(1) == i % (n / 20).max(1) {
                r.broadcast(t, i, graph.of(i), &[7; 30]);
            }
        }
    }
    let s = r.channel_stats().expect("channel");
    assert!(s.transmissions > 0);
    s.inspected as f64 / r.stats().sent as f64
}

#[test]
fn the_collision_check_costs_the_same_per_copy_for_100_and_2000_agents() {
    // ALOHA at 200 kbit/s (1.9 ms frames); each agent broadcasts every n/20 ticks, so
    // the medium carries the same load (20 frames per 10 ms tick, overloaded) for every
    // n. Comparing each copy with every transmission would make the larger swarm's
    // inspections per copy ~20× larger. Everyone hears everyone, and a 2 m range (the
    // check then also skips overlapping transmissions the receiver does not hear).
    for range in [None, Some(2.0)] {
        let small = inspected_per_copy(range, 100, 400);
        let large = inspected_per_copy(range, 2000, 400);
        eprintln!("range {range:?}: {small:.3} → {large:.3} inspections per copy");
        assert!(small > 0.5, "{range:?}: the check did no work: {small}");
        assert!(large < 1.5 * small, "{range:?}: {small} → {large}");
    }
}

//! `host_sim::design`: constructions over every generator, refusals, scale, rendering.

use host_sim::design::{construct, verify, DesignOptions, Generator};

fn generators(n: usize) -> Vec<Generator> {
    vec![
        Generator::Polygon {
            n,
            spacing: 1.0,
            centre: false,
        },
        Generator::Polygon {
            n,
            spacing: 1.0,
            centre: true,
        },
        Generator::RectangularLattice { n, spacing: 1.0 },
        Generator::TriangularLattice { n, spacing: 1.0 },
        Generator::Strip { n, spacing: 1.0 },
        Generator::RandomDisc {
            n,
            spacing: 1.0,
            seed: 1,
        },
    ]
}

#[test]
fn every_generator_gives_a_valid_construction() {
    let opts = DesignOptions::default();
    for n in [10, 50, 200] {
        for g in generators(n) {
            let p = g.points().unwrap();
            let c = construct(&p, &opts).unwrap_or_else(|e| panic!("{}: {e}", g.describe()));
            verify(&p, &c, &opts).unwrap_or_else(|e| panic!("{}: {e}", g.describe()));
            let f = c.figures;
            println!(
                "{:<55} min ctl {:6.2}° min ang {:6.2}° tri/agent {} nb/agent {:2} longest {:6.3} mean {:5.3} overlap {}",
                g.describe(), f.min_controlled_deg, f.min_angle_deg, f.max_triangles_per_agent,
                f.max_neighbours_per_agent, f.longest_edge, f.mean_edge, f.overlapping
            );
        }
    }
}

#[test]
fn diag_random() {
    let p = Generator::RandomDisc {
        n: 200,
        spacing: 1.0,
        seed: 1,
    }
    .points()
    .unwrap();
    let c = construct(&p, &DesignOptions::default()).unwrap();
    let ang = |t: [usize; 3]| {
        let f = |o: usize, a: usize, b: usize| {
            let u = [p[a][0] - p[o][0], p[a][1] - p[o][1]];
            let w = [p[b][0] - p[o][0], p[b][1] - p[o][1]];
            (u[0] * w[1] - u[1] * w[0])
                .abs()
                .atan2(u[0] * w[0] + u[1] * w[1])
                .to_degrees()
        };
        [
            f(t[0], t[1], t[2]),
            f(t[1], t[2], t[0]),
            f(t[2], t[0], t[1]),
        ]
    };
    let mut v: Vec<(f64, usize)> = c
        .triangles
        .iter()
        .enumerate()
        .map(|(k, t)| (ang(t.vertices).iter().cloned().fold(180.0, f64::min), k))
        .collect();
    v.sort_by(|a, b| a.0.total_cmp(&b.0));
    for &(a, k) in v.iter().take(5) {
        let t = c.triangles[k].vertices;
        let r: Vec<f64> = t.iter().map(|&i| p[i][0].hypot(p[i][1])).collect();
        println!(
            "tri {k} {:?} min {a:.2} radii {:?} angles {:?}",
            t,
            r,
            ang(t)
        );
    }
}

#[test]
fn diag_big() {
    for g in [Generator::RandomDisc {
        n: 100_000,
        spacing: 1.0,
        seed: 1,
    }] {
        let t0 = std::time::Instant::now();
        let p = g.points().unwrap();
        let t1 = t0.elapsed();
        let c = construct(&p, &DesignOptions::default()).unwrap();
        let t2 = t0.elapsed();
        verify(&p, &c, &DesignOptions::default()).unwrap();
        let f = c.figures;
        println!("{} gen {t1:?} construct {t2:?} {f:?}", g.describe());
        let mut h = [0usize; 7];
        for t in &c.triangles {
            let q = t.vertices.map(|i| p[i]);
            let f = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
                let u = [a[0] - o[0], a[1] - o[1]];
                let w = [b[0] - o[0], b[1] - o[1]];
                (u[0] * w[1] - u[1] * w[0])
                    .abs()
                    .atan2(u[0] * w[0] + u[1] * w[1])
                    .to_degrees()
            };
            let m = f(q[0], q[1], q[2])
                .min(f(q[1], q[2], q[0]))
                .min(f(q[2], q[0], q[1]));
            h[((m / 5.0) as usize).min(6)] += 1;
        }
        println!("min-angle histogram by 5 deg: {h:?}");
    }
}

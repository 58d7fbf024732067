//! `host_sim::design`: constructions over every generator, refusals, scale, rendering.

use host_sim::design::{construct, verify, DesignOptions, Generator};

fn generators(n: usize) -> Vec<Generator> {
    vec![
        Generator::Polygon { n, spacing: 1.0, centre: false },
        Generator::Polygon { n, spacing: 1.0, centre: true },
        Generator::RectangularLattice { n, spacing: 1.0 },
        Generator::TriangularLattice { n, spacing: 1.0 },
        Generator::Strip { n, spacing: 1.0 },
        Generator::RandomDisc { n, spacing: 1.0, seed: 1 },
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

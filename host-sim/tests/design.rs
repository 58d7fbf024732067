//! `ph_formation_sim::design`: constructions over every generator, refusals, scale, rendering
//! through the scenario loader, wire ids on the constructed graphs.

use ph_formation_sim::design::{
    adjacency_from_triangles, check_distance2, compare, construct, distance2_colouring,
    render_scenario, verify, Construction, DesignError, DesignOptions, Generator, Perturbation,
    Point, Scale, ScenarioOptions, Template, VerifyError,
};
use std::f64::consts::PI;

fn generators(n: usize) -> Vec<Generator> {
    Generator::every_shape(n, 1.0, 1).into()
}

fn angle_at(p: Point, a: Point, b: Point) -> f64 {
    let u = [a[0] - p[0], a[1] - p[1]];
    let w = [b[0] - p[0], b[1] - p[1]];
    (u[0] * w[1] - u[1] * w[0])
        .abs()
        .atan2(u[0] * w[0] + u[1] * w[1])
}

/// The properties the brief asks for, checked here without the module's own `verify`.
fn check(p: &[Point], c: &Construction, opts: &DesignOptions, what: &str) {
    let n = p.len();
    assert_eq!(c.triangles.len(), n - 2, "{what}: M = N − 2");
    let tris: Vec<[usize; 3]> = c.triangles.iter().map(|t| t.vertices).collect();
    // The scenario loader's own triangulated-Laman check (SPEC §3).
    ph_formation_sim::model::graph::laman_order(n, &tris)
        .unwrap_or_else(|e| panic!("{what}: {e:?}"));
    let margin = opts.margin_deg.to_radians();
    let mut per_agent = vec![0usize; n];
    for t in &c.triangles {
        for v in t.vertices {
            per_agent[v] += 1;
        }
        let [x, y] = t.angles;
        assert_ne!(x.apex, y.apex, "{what}");
        for a in t.angles {
            assert!(t.vertices.contains(&a.apex));
            let far: Vec<Point> = t
                .vertices
                .iter()
                .filter(|&&v| v != a.apex)
                .map(|&v| p[v])
                .collect();
            let actual = angle_at(p[a.apex], far[0], far[1]);
            assert!(
                (actual - a.desired).abs() < 1e-12,
                "{what}: desired = realised"
            );
            assert!(
                a.desired > margin && a.desired < PI - margin,
                "{what}: {}",
                a.desired
            );
        }
        assert!(x.desired + y.desired < PI - margin, "{what}: third angle");
    }
    let adj = adjacency_from_triangles(n, &tris);
    assert!(
        per_agent.iter().all(|&k| k <= opts.max_triangles),
        "{what}: MT"
    );
    assert!(
        adj.iter().all(|l| l.len() <= opts.max_neighbours),
        "{what}: NB"
    );
    assert!(
        adj[c.leader[0]].contains(&c.leader[1]),
        "{what}: leader edge is an edge"
    );
    verify(p, c, opts).unwrap_or_else(|e| panic!("{what}: {e}"));
}

#[test]
fn every_generator_gives_a_valid_construction() {
    let opts = DesignOptions::default();
    for n in [10, 50, 200] {
        for g in generators(n) {
            let p = g.points().unwrap();
            let c = construct(&p, &opts).unwrap_or_else(|e| panic!("{}: {e}", g.describe()));
            check(&p, &c, &opts, &g.describe());
            let f = c.figures;
            println!(
                "{:<62} | min controlled {:6.2}° | min angle {:6.2}° | tri/agent {} | nb/agent {:2} | longest {:7.3} | mean {:6.3} | overlapping {}",
                g.describe(),
                f.min_controlled_deg,
                f.min_angle_deg,
                f.max_triangles_per_agent,
                f.max_neighbours_per_agent,
                f.longest_edge,
                f.mean_edge,
                f.overlapping
            );
        }
    }
}

#[test]
fn lattices_and_strips_are_built_from_their_natural_triangles() {
    let opts = DesignOptions::default();
    for (g, angle) in [
        (
            Generator::TriangularLattice {
                n: 200,
                spacing: 2.0,
            },
            60.0,
        ),
        (
            Generator::Strip {
                n: 200,
                spacing: 2.0,
            },
            60.0,
        ),
        (
            Generator::RectangularLattice {
                n: 200,
                spacing: 2.0,
            },
            45.0,
        ),
    ] {
        let p = g.points().unwrap();
        let c = construct(&p, &opts).unwrap();
        let f = c.figures;
        assert!(
            (f.min_angle_deg - angle).abs() < 1e-9,
            "{}: {f:?}",
            g.describe()
        );
        assert!(
            f.longest_edge <= 2.0 * 2f64.sqrt() + 1e-9,
            "{}: {f:?}",
            g.describe()
        );
        assert_eq!(f.overlapping, 0, "{}", g.describe());
    }
}

#[test]
fn constructions_are_deterministic_and_honour_the_leader() {
    let p = Generator::RandomDisc {
        n: 300,
        spacing: 1.0,
        seed: 4,
    }
    .points()
    .unwrap();
    let opts = DesignOptions::default();
    assert_eq!(construct(&p, &opts).unwrap(), construct(&p, &opts).unwrap());
    let opts = DesignOptions {
        leader: Some([17, 42]),
        ..opts
    };
    let c = construct(&p, &opts).unwrap();
    assert_eq!(c.leader, [17, 42]);
    assert_eq!(&c.triangles[0].vertices[..2], &[17, 42]);
    check(&p, &c, &opts, "leader 17-42");
}

#[test]
fn capacity_is_respected_when_tight() {
    let p = Generator::TriangularLattice {
        n: 200,
        spacing: 1.0,
    }
    .points()
    .unwrap();
    // A non-start agent has one neighbour more than it has triangles, so NB = MT + 1 is
    // the tightest pair that binds both.
    let opts = DesignOptions {
        max_triangles: 4,
        max_neighbours: 5,
        ..Default::default()
    };
    let c = construct(&p, &opts).unwrap();
    check(&p, &c, &opts, "MT = 4, NB = 5");
    assert_eq!(c.figures.max_triangles_per_agent, 4);
}

#[test]
fn verify_names_the_broken_triangle_or_point() {
    let p = Generator::Strip { n: 6, spacing: 1.0 }.points().unwrap();
    let opts = DesignOptions::default();
    let c = construct(&p, &opts).unwrap();
    verify(&p, &c, &opts).unwrap();
    let mut bad = c.clone();
    bad.leader = [0, 5];
    let e = verify(&p, &bad, &opts).unwrap_err();
    assert_eq!(e, VerifyError::LeaderNotAnEdge([0, 5]));
    assert_eq!(e.to_string(), "leader edge [0, 5] is not an edge");
    let mut bad = c;
    bad.triangles.pop();
    let e = verify(&p, &bad, &opts).unwrap_err();
    assert_eq!(e.to_string(), "6 points need 4 triangles, got 3");
}

#[test]
fn refusals_say_which_points_and_why() {
    let opts = DesignOptions::default();
    let e = construct(&[[0.0, 0.0], [1.0, 0.0]], &opts).unwrap_err();
    assert_eq!(e, DesignError::TooFewPoints(2));
    assert!(e.to_string().contains("at least 3 points"));

    let e = construct(&[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 0.0]], &opts).unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, DesignError::DuplicatePoints { ref pairs, .. } if pairs == &[[1, 3]]));
    assert!(msg.contains("points 1 and 3 (agents 2 and 4)"), "{msg}");

    let line: Vec<Point> = (0..10).map(|i| [i as f64, 2.0 * i as f64]).collect();
    let msg = construct(&line, &opts).unwrap_err().to_string();
    assert!(msg.contains("all 10 points lie on one line"), "{msg}");

    // A nearly flat zig-zag: every triangle has angles of about 2°.
    let flat: Vec<Point> = (0..10).map(|i| [i as f64, 0.02 * (i % 2) as f64]).collect();
    let e = construct(&flat, &opts).unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, DesignError::NoConstruction { .. }), "{msg}");
    assert!(
        msg.contains("within 5° of 0 or 180°") && msg.contains("agent 1"),
        "{msg}"
    );

    // Capacity: one triangle per agent admits only three agents.
    let p = Generator::Strip { n: 6, spacing: 1.0 }.points().unwrap();
    let tight = DesignOptions {
        max_triangles: 1,
        ..Default::default()
    };
    let msg = construct(&p, &tight).unwrap_err().to_string();
    assert!(
        msg.contains("more than 1 triangles") && msg.contains("cannot be attached"),
        "{msg}"
    );
    assert!(!msg.contains("(0 candidates) or would give"), "{msg}");

    let bad = DesignOptions {
        leader: Some([3, 3]),
        ..Default::default()
    };
    let msg = construct(&p, &bad).unwrap_err().to_string();
    assert!(
        msg.contains("leader edge (3, 3)") && msg.contains("different"),
        "{msg}"
    );
    let bad = DesignOptions {
        leader: Some([0, 9]),
        ..Default::default()
    };
    assert!(construct(&p, &bad)
        .unwrap_err()
        .to_string()
        .contains("only 6 points"));
    let bad = DesignOptions {
        margin_deg: 70.0,
        ..Default::default()
    };
    assert!(construct(&p, &bad)
        .unwrap_err()
        .to_string()
        .contains("option `margin`"));
}

#[test]
#[ignore = "slow lane: `cargo xtask test` runs it (phase \"slow tests\")"]
fn a_hundred_thousand_points() {
    let p = Generator::RandomDisc {
        n: 100_000,
        spacing: 1.0,
        seed: 1,
    }
    .points()
    .unwrap();
    let opts = DesignOptions::default();
    let c = construct(&p, &opts).unwrap();
    assert_eq!(c.triangles.len(), 99_998);
    assert_eq!(c.figures.agents, 100_000);
    verify(&p, &c, &opts).unwrap();
    assert!(c.figures.min_angle_deg > opts.margin_deg);
    // Wire ids for the same graph fit in one byte.
    let tris: Vec<[usize; 3]> = c.triangles.iter().map(|t| t.vertices).collect();
    let adj = adjacency_from_triangles(p.len(), &tris);
    let ids = distance2_colouring(&adj, &[]).unwrap();
    check_distance2(&adj, &[], &ids).unwrap();
}

#[test]
#[ignore = "slow lane: `cargo xtask test` runs it (phase \"slow tests\")"]
fn wire_ids_on_large_lattices_and_strips() {
    let n = 100_000;
    let lattice = Generator::TriangularLattice { n, spacing: 1.0 }
        .points()
        .unwrap();
    let c = construct(&lattice, &DesignOptions::default()).unwrap();
    let graphs = [
        (
            "constructed triangular lattice",
            c.triangles.iter().map(|t| t.vertices).collect::<Vec<_>>(),
        ),
        // The strip's construction is (i, i+1, i+2) (see `lattices_and_strips_…`).
        ("strip", (0..n - 2).map(|i| [i, i + 1, i + 2]).collect()),
        // A square lattice split along alternating diagonals.
        ("square lattice", square_lattice(316)),
    ];
    for (what, tris) in graphs {
        let m = tris.iter().flatten().max().unwrap() + 1;
        let adj = adjacency_from_triangles(m, &tris);
        let plain = distance2_colouring(&adj, &[]).unwrap();
        check_distance2(&adj, &[], &plain).unwrap();
        // Extra conflicts: each agent with the agent 3 places further in index order.
        let extra: Vec<[usize; 2]> = (0..m - 3).map(|i| [i, i + 3]).collect();
        let ids = distance2_colouring(&adj, &extra).unwrap();
        check_distance2(&adj, &extra, &ids).unwrap();
        let used = |c: &[u8]| c.iter().copied().max().unwrap_or(0) as usize + 1;
        println!(
            "{what} ({m} agents): {} wire ids, {} with extra pairs",
            used(&plain),
            used(&ids)
        );
        assert!(used(&ids) <= 64, "{what}: {}", used(&ids));
    }
}

/// Triangles of a `k × k` square lattice, each cell cut by a diagonal.
fn square_lattice(k: usize) -> Vec<[usize; 3]> {
    let id = |r: usize, c: usize| r * k + c;
    let mut t = Vec::new();
    for r in 0..k - 1 {
        for c in 0..k - 1 {
            if (r + c) % 2 == 0 {
                t.push([id(r, c), id(r, c + 1), id(r + 1, c + 1)]);
                t.push([id(r, c), id(r + 1, c + 1), id(r + 1, c)]);
            } else {
                t.push([id(r, c), id(r, c + 1), id(r + 1, c)]);
                t.push([id(r, c + 1), id(r + 1, c + 1), id(r + 1, c)]);
            }
        }
    }
    t
}

/// The rendered scenario without `[target]` (the loader does not know it yet), through
/// the loader's parser and validator.
fn load(text: &str) -> ph_formation_sim::model::Model {
    let mut table: toml::Table = toml::from_str(text).expect("rendered TOML parses");
    table.remove("target");
    let stripped = toml::to_string(&table).expect("re-serialises");
    ph_formation_sim::load_toml(&stripped, "rendered", &[])
        .unwrap_or_else(|e| panic!("{e}\n{}", &text[..text.len().min(3000)]))
}

#[test]
fn rendered_scenarios_parse_and_load() {
    let opts = DesignOptions::default();
    for n in [10, 50, 200] {
        for g in generators(n) {
            let p = g.points().unwrap();
            let c = construct(&p, &opts).unwrap();
            let so = ScenarioOptions {
                name: format!("test-{n}"),
                source: g.describe(),
                command: "host-sim design --test".to_owned(),
                perturbation: Perturbation {
                    fraction: 0.05,
                    rotate: true,
                    seed: 3,
                    ..Perturbation::default()
                },
                ..Default::default()
            };
            let text = render_scenario(&p, &c, &opts, &so).unwrap();
            let table: toml::Table = toml::from_str(&text).unwrap();
            assert_eq!(table["agents"].as_array().unwrap().len(), n);
            assert_eq!(table["triangles"].as_array().unwrap().len(), n - 2);
            let target = table["target"]["positions"].as_array().unwrap();
            assert_eq!(target.len(), n);
            assert_eq!(
                target[n - 1].as_array().unwrap()[0].as_float(),
                Some(p[n - 1][0])
            );
            let model = load(&text);
            assert_eq!(model.agents.len(), n);
            assert_eq!(model.triangles.len(), n - 2);
            let leader = model.leader.expect("leader");
            assert_eq!([leader.a, leader.b], c.leader);
            // The initial positions start unfolded and near the target.
            let q: Vec<Point> = model.agents.iter().map(|a| a.position).collect();
            let tris: Vec<[usize; 3]> = c.triangles.iter().map(|t| t.vertices).collect();
            let cmp = compare(&q, &p, &tris).unwrap();
            assert!(
                cmp.folded.is_empty() && !cmp.fit.reflected,
                "{}",
                g.describe()
            );
            assert!(cmp.fit.rms_rel <= 0.05, "{}: {:?}", g.describe(), cmp.fit);
        }
    }
}

#[test]
fn header_options_and_template() {
    let p = Generator::TriangularLattice {
        n: 12,
        spacing: 1.0,
    }
    .points()
    .unwrap();
    let opts = DesignOptions::default();
    let c = construct(&p, &opts).unwrap();
    let template = Template::parse(
        "agents = []\nduration = 7.0\n[gains]\nstiffness = 7.0\ndamping = 0.5\nestimator_gain = 9.0\n\
         [controller]\nangle_margin_deg = 3.0\nmax_force = 50.0\n[leader]\nagents = [1, 2]\nstiffness = 2.5\n\
         damping = [0.1, 0.2]\ndisplacement = [1.0, 0.0]\n",
        "my.toml",
    )
    .unwrap();
    let so = ScenarioOptions {
        name: "lattice".to_owned(),
        command: "host-sim design --lattice tri --n 12".to_owned(),
        source: "triangular lattice".to_owned(),
        velocity_reference: [0.5, -0.25],
        template: Some(template),
        ..Default::default()
    };
    let text = render_scenario(&p, &c, &opts, &so).unwrap();
    assert!(text.starts_with("# Generated by `host-sim design`"));
    for want in [
        "# Command: host-sim design --lattice tri --n 12",
        "smallest controlled angle margin 60.000°",
        "gains from my.toml",
        "stiffness = 7.0",
        "max_force = 50.0",
        "velocity_reference = [0.5, -0.25]",
        "damping = [0.1, 0.2]",
        "duration = 7.0",
    ] {
        assert!(text.contains(want), "missing {want:?} in\n{text}");
    }
    let model = load(&text);
    assert_eq!(model.triangles[0].angles[0].stiffness, 7.0);
    assert_eq!(model.leader.unwrap().stiffness, 2.5);
    // Without a template: the paper's gains.
    let text = render_scenario(&p, &c, &opts, &ScenarioOptions::default()).unwrap();
    assert!(text.contains("stiffness = 1000.0") && text.contains("velocity_damping = 1.8"));
    load(&text);
}

#[test]
fn initial_positions_refuse_a_margin_the_construction_does_not_keep() {
    let p = Generator::Polygon {
        n: 200,
        spacing: 1.0,
        centre: false,
    }
    .points()
    .unwrap();
    let opts = DesignOptions::default();
    let c = construct(&p, &opts).unwrap();
    let template =
        Template::parse("agents = []\n[controller]\nangle_margin_deg = 40.0\n", "t").unwrap();
    let so = ScenarioOptions {
        template: Some(template),
        ..Default::default()
    };
    let msg = render_scenario(&p, &c, &opts, &so).unwrap_err().to_string();
    assert!(
        msg.contains("within the scenario's angle margin 40°"),
        "{msg}"
    );
}

#[test]
fn points_files() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("shape.csv");
    std::fs::write(&csv, "x,y\n0,0\n2,0\n1,1.7\n3,1.7\n").unwrap();
    let p = ph_formation_sim::design::read_points(&csv).unwrap();
    assert_eq!(p.len(), 4);
    let c = construct(&p, &DesignOptions::default()).unwrap();
    assert_eq!(c.triangles.len(), 2);
    let other = dir.path().join("shape.txt");
    std::fs::write(&other, "0,0\n").unwrap();
    let msg = ph_formation_sim::design::read_points(&other)
        .unwrap_err()
        .to_string();
    assert!(msg.contains("shape.txt") && msg.contains(".csv"), "{msg}");
    // A rendered scenario is itself a points file (its [target]).
    let toml_path = dir.path().join("s.toml");
    let text = render_scenario(
        &p,
        &c,
        &DesignOptions::default(),
        &ScenarioOptions::default(),
    )
    .unwrap();
    std::fs::write(&toml_path, text).unwrap();
    assert_eq!(
        ph_formation_sim::design::read_points(&toml_path).unwrap(),
        p
    );
}

/// Points on a circle: grown with the default 5° margin the construction's smallest
/// controlled angle is 180°/N-ish (7.2° for a 50-gon, which never converges); the margin is
/// raised until it is well away from 0 and 180°. Shapes that are fine keep the default.
#[test]
fn thin_constructions_are_grown_again_with_a_higher_margin() {
    let opts = DesignOptions::default();
    for g in [
        Generator::Polygon {
            n: 50,
            spacing: 1.0,
            centre: false,
        },
        Generator::Polygon {
            n: 200,
            spacing: 1.0,
            centre: true,
        },
    ] {
        let c = construct(&g.points().unwrap(), &opts).unwrap();
        assert!(
            c.margin_deg >= 20.0,
            "{}: margin {}",
            g.describe(),
            c.margin_deg
        );
        assert!(
            c.figures.min_controlled_deg >= ph_formation_sim::design::laman::RAISE_BELOW_DEG,
            "{}: {:?}",
            g.describe(),
            c.figures
        );
    }
    let lattice = Generator::TriangularLattice {
        n: 50,
        spacing: 1.0,
    };
    let c = construct(&lattice.points().unwrap(), &opts).unwrap();
    assert_eq!(c.margin_deg, opts.margin_deg);
    assert!((c.figures.min_controlled_deg - 60.0).abs() < 1e-6);
}

/// `Scale::Spacing`: every agent moves at most the fraction of the median nearest-neighbour
/// distance (a 1 m-sided 200-gon with its centre: 0.1 m, also for the centre, whose
/// nearest neighbour is 32 m away), and some agent moves more than half of that.
#[test]
fn spacing_perturbation_is_local() {
    let g = Generator::Polygon {
        n: 200,
        spacing: 1.0,
        centre: true,
    };
    let p = g.points().unwrap();
    let c = construct(&p, &DesignOptions::default()).unwrap();
    let pert = Perturbation {
        fraction: 0.1,
        scale: Scale::Spacing,
        rotate: false,
        seed: 5,
    };
    let init = ph_formation_sim::design::initial_positions(&p, &c, &pert, 5.0, 0.05).unwrap();
    assert!(
        (init.max_displacement - 0.1).abs() < 1e-9,
        "{}",
        init.max_displacement
    );
    let moved: Vec<f64> = p
        .iter()
        .zip(&init.positions)
        .map(|(a, b)| ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt())
        .collect();
    let most = moved.iter().copied().fold(0.0, f64::max);
    assert!(most <= 0.1 + 1e-12 && most > 0.05, "{most}");
    // The same fraction of the formation's size moves agents about 32× further.
    let size = Perturbation {
        scale: Scale::Size,
        ..pert
    };
    let init = ph_formation_sim::design::initial_positions(&p, &c, &size, 5.0, 0.05).unwrap();
    assert!(init.max_displacement > 3.0, "{}", init.max_displacement);
}

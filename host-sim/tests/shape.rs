//! The right shape: the outcome compares the final formation with the target (given in
//! `[target]` or built from the desired angles) up to translation, rotation, scale and a
//! whole-formation mirror; a folded triangle is `wrong_shape`, a fold onto a neighbour a
//! `collision`; designed formations validate and converge.

use ph_formation_sim::design::{
    construct, render_scenario, DesignOptions, Generator, Perturbation, Scale,
};
use ph_formation_sim::design::{ScenarioOptions, Template};
use ph_formation_sim::{load_toml, Outcome, Simulation};

fn angle_deg(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let u = [a[0] - p[0], a[1] - p[1]];
    let w = [b[0] - p[0], b[1] - p[1]];
    (u[0] * w[1] - u[1] * w[0])
        .abs()
        .atan2(u[0] * w[0] + u[1] * w[1])
        .to_degrees()
}

/// A scenario over `target` with these triangles (angles at the first two vertices, from
/// the target), initial positions `init`, initial velocities `vel`, and `[target]` when
/// given. Gains of `formation-only` (c = 10, d = 1, c_e = 10, D^r = 0.5).
fn scenario(
    target: &[[f64; 2]],
    tris: &[[usize; 3]],
    init: &[[f64; 2]],
    vel: &[[f64; 2]],
    given: Option<&[[f64; 2]]>,
) -> String {
    let mut s = String::from(
        "name = \"shape\"\nduration = 60.0\n[controller]\nmax_force = 1.0e3\n[gains]\nstiffness = 10.0\ndamping = 1.0\nestimator_gain = 10.0\n[agent_defaults]\nfriction = 0.5\n",
    );
    for (i, (p, v)) in init.iter().zip(vel).enumerate() {
        s += &format!(
            "[[agents]]\nid = {}\nposition = [{:?}, {:?}]\nvelocity = [{:?}, {:?}]\n",
            i + 1,
            p[0],
            p[1],
            v[0],
            v[1]
        );
    }
    for &[a, b, c] in tris {
        let (pa, pb, pc) = (target[a], target[b], target[c]);
        s += &format!(
            "[[triangles]]\nvertices = [{}, {}, {}]\nangles = [{{ apex = {}, desired_deg = {} }}, {{ apex = {}, desired_deg = {} }}]\n",
            a + 1,
            b + 1,
            c + 1,
            a + 1,
            angle_deg(pa, pb, pc),
            b + 1,
            angle_deg(pb, pa, pc)
        );
    }
    if let Some(t) = given {
        let pts: Vec<String> = t
            .iter()
            .map(|p| format!("[{:?}, {:?}]", p[0], p[1]))
            .collect();
        s += &format!("[target]\npositions = [{}]\n", pts.join(", "));
    }
    s
}

fn mirror_across(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    let d = [b[0] - a[0], b[1] - a[1]];
    let t = ((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / (d[0] * d[0] + d[1] * d[1]);
    let foot = [a[0] + t * d[0], a[1] + t * d[1]];
    [2.0 * foot[0] - p[0], 2.0 * foot[1] - p[1]]
}

/// Five agents, three triangles; agent 4's triangle is not symmetric, so its mirror
/// image across edge 2–3 is far from every other agent.
const FAN: [[f64; 2]; 5] = [
    [0.0, 0.0],
    [1.0, 0.0],
    [0.5, 0.87],
    [1.45, 1.05],
    [0.0, 1.5],
];
const FAN_TRIS: [[usize; 3]; 3] = [[0, 1, 2], [1, 2, 3], [0, 2, 4]];

fn run(text: &str) -> (ph_formation_sim::Model, ph_formation_sim::Run) {
    let m = load_toml(text, "shape", &[]).unwrap_or_else(|e| panic!("{e}"));
    let r = Simulation::new(&m).keep_series(false).run().unwrap();
    (m, r)
}

/// `wrong_shape` with every angle satisfied and triangle 2–3–4 named as folded.
fn assert_folded_234(r: &ph_formation_sim::Run) {
    assert_eq!(r.outcome(), Outcome::WrongShape, "{}", r.result.reason);
    assert!(r.result.final_max_angle_error < 1e-3);
    assert!(
        r.result
            .reason
            .contains("triangle folded across an edge ([2, 3, 4])"),
        "{}",
        r.result.reason
    );
}

#[test]
fn a_triangle_folded_away_from_any_neighbour_is_wrong_shape() {
    let mut init = FAN.to_vec();
    init[3] = mirror_across(FAN[3], FAN[1], FAN[2]);
    let text = scenario(&FAN, &FAN_TRIS, &init, &[[0.0; 2]; 5], Some(&FAN));
    let (m, r) = run(&text);
    assert!(m.target.from_file);
    assert_folded_234(&r);
    assert_eq!(r.exit_code(), 14);
    let s = r.summary_json(&m);
    assert_eq!(s["outcome"], "wrong_shape");
    assert_eq!(
        s["shape"]["folded_triangles"],
        serde_json::json!([[2, 3, 4]])
    );
    // The same start without a [target]: the target follows the initial orientation, so
    // the folded shape is the one asked for.
    let text = scenario(&FAN, &FAN_TRIS, &init, &[[0.0; 2]; 5], None);
    let (m, r) = run(&text);
    assert!(!m.target.from_file);
    assert_eq!(r.outcome(), Outcome::Converged, "{}", r.result.reason);
}

#[test]
fn a_fold_onto_a_neighbour_is_a_collision() {
    // A 60° strip: agent 5 mirrored across edge 3–4 lands on agent 2. A push across that
    // edge at 8 m/s carries it there.
    let h = 3f64.sqrt() / 2.0;
    let strip: Vec<[f64; 2]> = (0..5)
        .map(|i| [0.5 * i as f64, h * (i % 2) as f64])
        .collect();
    let tris = [[0, 1, 2], [1, 2, 3], [2, 3, 4]];
    let (a, b, p) = (strip[2], strip[3], strip[4]);
    let across = mirror_across(p, a, b);
    let d = [across[0] - p[0], across[1] - p[1]];
    let n = d[0].hypot(d[1]);
    let mut vel = vec![[0.0; 2]; 5];
    vel[4] = [8.0 * d[0] / n, 8.0 * d[1] / n];
    let (_, r) = run(&scenario(&strip, &tris, &strip, &vel, None));
    assert_eq!(r.outcome(), Outcome::Collision, "{}", r.result.reason);
    assert!(
        r.result.reason.contains("agents 2 and 5 collided"),
        "{}",
        r.result.reason
    );
}

#[test]
fn a_whole_formation_mirror_image_is_converged() {
    let mirrored: Vec<[f64; 2]> = FAN.iter().map(|p| [-p[0], p[1]]).collect();
    let init: Vec<[f64; 2]> = FAN.iter().map(|p| [p[0] + 0.03, p[1] - 0.02]).collect();
    let text = scenario(&FAN, &FAN_TRIS, &init, &[[0.0; 2]; 5], Some(&mirrored));
    let (m, r) = run(&text);
    assert_eq!(r.outcome(), Outcome::Converged, "{}", r.result.reason);
    let s = r.summary_json(&m);
    assert_eq!(s["shape"]["reflected"], true);
    assert!(s["shape"]["max_error_rel"].as_f64().unwrap() < 1e-3, "{s}");
}

#[test]
fn a_target_that_does_not_realise_the_angles_is_refused() {
    let mut wrong = FAN.to_vec();
    wrong[4] = [0.3, 2.5];
    let text = scenario(&FAN, &FAN_TRIS, &FAN, &[[0.0; 2]; 5], Some(&wrong));
    let e = load_toml(&text, "shape", &[]).unwrap_err().to_string();
    assert!(
        e.contains("target.positions") && e.contains("triangles[2]"),
        "{e}"
    );
    let text = scenario(&FAN, &FAN_TRIS, &FAN, &[[0.0; 2]; 5], Some(&FAN[..4]));
    let e = load_toml(&text, "shape", &[]).unwrap_err().to_string();
    assert!(e.contains("has 4 points but there are 5 agents"), "{e}");
}

fn generators(n: usize) -> Vec<Generator> {
    Generator::every_shape(n, 1.0, 1).into()
}

/// A designed scenario, gains of `formation-only`, every agent displaced by up to 10 % of
/// the spacing (the median nearest-neighbour distance; `rotate`: and the whole formation
/// turned by a random angle), as `host-sim design` does by default.
fn designed(g: &Generator, duration: f64, rotate: bool) -> (Vec<[f64; 2]>, String) {
    let p = g.points().unwrap();
    let opts = DesignOptions::default();
    let c = construct(&p, &opts).unwrap();
    let template = ph_formation_sim::scenario::builtin("formation-only").unwrap();
    let so = ScenarioOptions {
        name: "designed".to_owned(),
        source: g.describe(),
        duration: Some(duration),
        perturbation: Perturbation {
            fraction: 0.1,
            scale: Scale::Spacing,
            rotate,
            seed: 2,
        },
        template: Some(Template::parse(template.text, "builtin:formation-only").unwrap()),
        ..Default::default()
    };
    let text = render_scenario(&p, &c, &opts, &so).unwrap();
    (p, text)
}

#[test]
fn designed_formations_validate_and_the_target_from_angles_is_theirs() {
    for n in [10, 50, 200] {
        for g in generators(n) {
            let (p, text) = designed(&g, 100.0, true);
            let m = load_toml(&text, "designed", &[])
                .unwrap_or_else(|e| panic!("{}: {e}", g.describe()));
            assert_eq!(m.target.positions, p);
            // Without [target]: rebuilt from the desired angles and the initial
            // orientation, the same shape.
            let mut table: toml::Table = toml::from_str(&text).unwrap();
            table.remove("target");
            let m2 = load_toml(&toml::to_string(&table).unwrap(), "designed", &[]).unwrap();
            let tris: Vec<[usize; 3]> = m2.triangles.iter().map(|t| t.vertices).collect();
            let c =
                ph_formation_sim::model::shape::compare(&m2.target.positions, &p, &tris).unwrap();
            assert!(
                c.fit.max_rel < 1e-9 && c.folded.is_empty() && !c.fit.reflected,
                "{}: {:?}",
                g.describe(),
                c.fit
            );
        }
    }
}

fn converge_all(gens: Vec<Generator>, duration: f64, rotate: bool) {
    let mut failed = Vec::new();
    for g in gens {
        let (_, text) = designed(&g, duration, rotate);
        let (m, r) = run(&text);
        let s = r.summary_json(&m);
        println!(
            "{:<60} {:>17} settle {:>8} s, shape error {:.2e}, wall {:.1} s",
            g.describe(),
            r.outcome().as_str(),
            s["settle_time_s"],
            s["shape"]["max_error_rel"].as_f64().unwrap_or(f64::NAN),
            r.result.wall_seconds
        );
        if r.outcome() != Outcome::Converged {
            failed.push(format!("{}: {}", g.describe(), r.result.reason));
        }
    }
    assert!(failed.is_empty(), "{failed:#?}");
}

#[test]
fn designed_formations_of_10_converge_from_a_10_percent_perturbation() {
    converge_all(generators(10), 200.0, true);
}

#[test]
fn designed_formations_of_50_converge_from_a_10_percent_perturbation() {
    converge_all(generators(50), 100.0, false);
}

/// Regular polygons (with and without centre) are the hard case: near neighbours on a
/// circle make angles of 180°/N, so the construction raises its margin and controls
/// triangles across the ring (edges of 15–63 m for 1 m sides).
#[test]
fn designed_formations_of_200_converge_from_a_10_percent_perturbation() {
    converge_all(generators(200), 150.0, false);
}

/// The case: the formation starts in its target shape (no `[target]`: the target
/// is built from the angles and the initial orientation) and agent 4 is pushed at 10 m/s
/// through the middle of its base edge 2–3. It comes to rest mirrored, every controlled
/// angle satisfied, away from any neighbour: `wrong_shape`, naming the triangle. (Measured
/// with this start: 2–3 m/s come back to the target, 4–6 m/s collapse an estimate, 8 m/s
/// hits agent 1, 10 and 12 m/s fold, 16 m/s has not settled in 60 s.)
#[test]
fn a_push_across_an_edge_that_folds_a_triangle_is_wrong_shape() {
    let (a, b, p) = (FAN[1], FAN[2], FAN[3]);
    let mid = [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0];
    let d = [mid[0] - p[0], mid[1] - p[1]];
    let n = d[0].hypot(d[1]);
    let mut vel = vec![[0.0; 2]; 5];
    vel[3] = [10.0 * d[0] / n, 10.0 * d[1] / n];
    let (m, r) = run(&scenario(&FAN, &FAN_TRIS, &FAN, &vel, None));
    assert!(!m.target.from_file);
    assert_folded_234(&r);
    let s = r.summary_json(&m);
    assert!(s["min_distance"].as_f64().unwrap_or(0.0) > 0.05, "{s}");
}

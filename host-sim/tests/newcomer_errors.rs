//! The errors a newcomer meets first (issue 32): a scenario without `[gains]` runs with
//! the documented defaults; a graph that is not rigid names the first triangle that
//! cannot attach by its agent ids and line; an unknown field suggests the nearest known
//! one. And the README's figures of the paper run stay true.

use ph_formation_sim::scenario::GainsSpec;

/// formation-only's four agents and two triangles, without `[gains]`.
const NO_GAINS: &str = r#"
name = "no-gains"
duration = 1.0

[[agents]]
id = 1
position = [0.9, 2.2]

[[agents]]
id = 2
position = [2.2, 2.8]

[[agents]]
id = 3
position = [1.8, 1.1]

[[agents]]
id = 4
position = [3.1, 1.9]

[[triangles]]
vertices = [1, 2, 3]
angles = [{ apex = 1, desired_deg = 90.0 }, { apex = 3, desired_deg = 45.0 }]

[[triangles]]
vertices = [2, 3, 4]
angles = [{ apex = 2, desired_deg = 45.0 }, { apex = 3, desired_deg = 45.0, damping = 2.0 }]
"#;

#[test]
fn a_scenario_without_gains_gets_those_of_formation_only() {
    let m =
        ph_formation_sim::load_toml(NO_GAINS, "no-gains.toml", &[]).expect("valid without [gains]");
    let reference = ph_formation_sim::load("formation-only", &[]).expect("formation-only");
    let gains = |m: &ph_formation_sim::Model| -> Vec<(f64, f64, f64)> {
        m.triangles
            .iter()
            .flat_map(|t| &t.angles)
            .map(|a| (a.stiffness, a.damping, a.estimator_gain))
            .collect()
    };
    let mut expected = gains(&reference);
    assert_eq!(expected[0], (10.0, 1.0, 10.0));
    assert_eq!(
        expected[0],
        (
            GainsSpec::DEFAULT_STIFFNESS,
            GainsSpec::DEFAULT_DAMPING,
            GainsSpec::DEFAULT_ESTIMATOR_GAIN
        )
    );
    expected[3].1 = 2.0; // the angle's own damping still wins
    assert_eq!(gains(&m), expected);
    // A bad [gains] value is still one error, naming gains.stiffness.
    let text = NO_GAINS.replace(
        "duration = 1.0",
        "duration = 1.0\n[gains]\nstiffness = -1.0",
    );
    let e = ph_formation_sim::load_toml(&text, "bad.toml", &[]).expect_err("negative stiffness");
    assert_eq!(e.0.len(), 1, "{e}");
    assert_eq!(e.0[0].field, "gains.stiffness");
}

#[test]
fn a_non_rigid_graph_names_the_triangle_by_ids_and_line() {
    // Six agents, four triangles (N = M + 2) but not rigid: [1, 2, 4] adds no agent (its
    // three are joined by the first two) and [4, 5, 6] shares no edge with them.
    let text = format!(
        "{NO_GAINS}{}",
        r#"
[[agents]]
id = 5
position = [4.0, 3.0]

[[agents]]
id = 6
position = [5.0, 1.0]

[[triangles]]
vertices = [1, 2, 4]
angles = [{ apex = 1, desired_deg = 60.0 }, { apex = 2, desired_deg = 60.0 }]

[[triangles]]
vertices = [4, 5, 6]
angles = [{ apex = 5, desired_deg = 60.0 }, { apex = 6, desired_deg = 60.0 }]
"#
    );
    let line = |needle: &str| text.lines().position(|l| l.contains(needle)).expect("line");
    // The header `[[triangles]]` is the line before `vertices` (1-based: the same index).
    let (l124, l456) = (line("[1, 2, 4]"), line("[4, 5, 6]"));
    let e = ph_formation_sim::load_toml(&text, "non-rigid.toml", &[]).expect_err("not rigid");
    assert_eq!(e.0.len(), 1, "{e}");
    let msg = e.to_string();
    let expected = [
        "field `triangles[2]`".to_owned(),
        format!("triangle [1, 2, 4] (line {l124}) cannot be attached"),
        "adds no new agent".to_owned(),
        format!("2 triangles cannot be attached: [1, 2, 4] (line {l124}), [4, 5, 6] (line {l456})"),
    ];
    for part in expected {
        assert!(msg.contains(&part), "`{part}` not in: {msg}");
    }
}

#[test]
fn an_unknown_field_suggests_the_nearest_known_one() {
    let text = NO_GAINS.replace("duration = 1.0", "duration = 1.0\n[gains]\nstifness = 3.0");
    let e = ph_formation_sim::load_toml(&text, "typo.toml", &[]).expect_err("unknown field");
    assert_eq!(e.0.len(), 1);
    assert!(
        e.0[0].reason.contains("unknown field `stifness`")
            && e.0[0].reason.ends_with("did you mean `stiffness`?"),
        "{e}"
    );
    // Through --set too.
    let e = ph_formation_sim::load("paper", &["radio.los=0.1".to_owned()]).expect_err("unknown");
    assert!(e.to_string().contains("did you mean `loss`?"), "{e}");
}

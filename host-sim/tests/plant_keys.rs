//! `[plant]` is a tagged table: one variant per vehicle (`plant.model`), each taking only
//! its own keys. A key of another vehicle is refused by `host-sim validate` with the file,
//! the field and the reason, for every vehicle; the vehicle's own key passes (the negative
//! control: the same file is accepted when the key belongs to the model).

use std::path::Path;
use std::process::Command;

/// A scenario file: `paper.toml` with `plant` appended as its `[plant]` table.
fn scenario_with(dir: &Path, name: &str, plant: &str) -> std::path::PathBuf {
    let base = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/paper.toml");
    let text = std::fs::read_to_string(&base).expect("read paper.toml");
    assert!(
        !text.contains("[plant]"),
        "paper.toml already has a [plant]"
    );
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, format!("{text}\n[plant]\n{plant}\n")).expect("write scenario");
    path
}

/// `host-sim validate FILE`: its exit status and standard error.
fn validate(path: &Path) -> (bool, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .arg("validate")
        .arg(path)
        .output()
        .expect("run host-sim validate");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn every_vehicle_refuses_another_vehicles_key_and_takes_its_own() {
    let dir = tempfile::tempdir().expect("temp dir");
    // (model, a key of another vehicle, a key of its own).
    let cases = [
        ("point_mass", "time_constant_s = 0.3", None),
        (
            "velocity_tracking",
            "second_lead_s2 = 0.05",
            Some("time_constant_s = 0.3"),
        ),
        (
            "crazyflie_pid",
            "max_tilt_deg = 30.0",
            Some("second_lead_s2 = 0.05"),
        ),
    ];
    // One case per vehicle the schema knows (as its error for an unknown model lists
    // them): a new vehicle adds its case here.
    let (ok, err) = validate(&scenario_with(dir.path(), "unknown", "model = \"nope\""));
    assert!(!ok && err.contains("field `plant.model`"), "{err}");
    let list = err
        .split("the models are ")
        .nth(1)
        .expect("the models listed");
    let mut known: Vec<&str> = list.trim().split(", ").collect();
    known.sort_unstable();
    let mut models: Vec<&str> = cases.iter().map(|c| c.0).collect();
    models.sort_unstable();
    assert_eq!(models, known);
    for (model, foreign, own) in cases {
        let name = format!("{model}-foreign");
        let file = scenario_with(
            dir.path(),
            &name,
            &format!("model = \"{model}\"\n{foreign}"),
        );
        let (ok, err) = validate(&file);
        let key = foreign.split(' ').next().expect("key");
        assert!(!ok, "{model}: {foreign} accepted");
        assert!(
            err.contains(&format!("{name}.toml")),
            "{model}: no file in {err}"
        );
        assert!(
            err.contains(&format!("field `plant.{key}`")),
            "{model}: no field in {err}"
        );
        assert!(
            err.contains(&format!("unknown field `{key}`"))
                && err.contains(&format!("model = \"{model}\""))
                && err.contains("each model takes only its own keys"),
            "{model}: no reason in {err}"
        );
        if let Some(own) = own {
            let file = scenario_with(
                dir.path(),
                &format!("{model}-own"),
                &format!("model = \"{model}\"\n{own}"),
            );
            let (ok, err) = validate(&file);
            assert!(ok, "{model}: its own key {own} refused: {err}");
        }
    }
    // The default model is the point mass: a bare foreign key is refused as its.
    let file = scenario_with(dir.path(), "bare", "lead_s = 0.1");
    let (ok, err) = validate(&file);
    assert!(
        !ok && err.contains("field `plant.lead_s`") && err.contains("point_mass"),
        "{err}"
    );
    // And an empty `[plant]` is the point mass, accepted.
    let (ok, err) = validate(&scenario_with(dir.path(), "empty", ""));
    assert!(ok, "{err}");
}

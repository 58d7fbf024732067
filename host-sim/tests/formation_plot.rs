//! Pictures before running: `host-sim validate SCENARIO --plot FILE` and
//! `host-sim design … --plot FILE` draw the formation (report/plot/formation.rs).

use std::process::Command;

/// The contents of the SVG's text elements, trimmed.
fn texts(svg: &str) -> Vec<String> {
    svg.split("<text")
        .skip(1)
        .filter_map(|t| {
            let body = &t[t.find('>')? + 1..];
            Some(body[..body.find("</text>")?].trim().to_owned())
        })
        .collect()
}

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_host-sim"))
}

#[test]
fn validate_plot_draws_the_labelled_graph() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let png = tmp.path().join("g.png");
    let svg = tmp.path().join("g.svg");
    for file in [&png, &svg] {
        let o = bin()
            .args(["-q", "validate", "paper", "--plot"])
            .arg(file)
            .output()
            .expect("spawn");
        assert_eq!(o.status.code(), Some(0), "{o:?}");
    }
    let bytes = std::fs::read(&png).expect("png");
    assert!(bytes.starts_with(b"\x89PNG\r\n\x1a\n") && bytes.len() > 10_000);
    let text = std::fs::read_to_string(&svg).expect("svg");
    assert!(text.contains("paper — formation: 4 agents, 2 triangles, 5 edges"));
    let labels = texts(&text);
    for id in ["1", "2", "3", "4"] {
        assert!(labels.iter().any(|l| l == id), "agent {id} not labelled");
    }
    // paper's desired angles: 90° at 1 and 45° (three of them), SPEC §9.
    assert_eq!(text.matches("90.0°").count(), 1);
    assert_eq!(text.matches("45.0°").count(), 3);
    assert!(text.contains("leader edge"));
}

#[test]
fn design_plot_draws_the_designed_formation_and_a_bad_file_is_an_error() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let svg = tmp.path().join("d.svg");
    let toml = tmp.path().join("d.toml");
    let o = bin()
        .args(["-q", "design", "--shape", "polygon", "-n", "5", "-o"])
        .arg(&toml)
        .arg("--plot")
        .arg(&svg)
        .output()
        .expect("spawn");
    assert_eq!(o.status.code(), Some(0), "{o:?}");
    let text = std::fs::read_to_string(&svg).expect("svg");
    assert!(text.contains("5 agents, 3 triangles"), "{}", &text[..400]);
    assert!(
        texts(&text).iter().any(|l| l == "5"),
        "agent 5 not labelled"
    );
    let o = bin()
        .args([
            "-q",
            "validate",
            "paper",
            "--plot",
            "/nonexistent/dir/g.png",
        ])
        .output()
        .expect("spawn");
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("/nonexistent/dir/g.png"));
}

#[test]
fn trajectory_and_shape_plots_label_the_agents() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let out = tmp.path().join("p");
    let o = bin()
        .args(["-q", "run", "paper", "--duration", "2", "--out"])
        .arg(&out)
        .output()
        .expect("spawn");
    assert_eq!(o.status.code(), Some(10), "{o:?}");
    for figure in ["trajectories.svg", "shape.svg"] {
        let labels = texts(&std::fs::read_to_string(out.join(figure)).expect("svg"));
        for id in ["1", "2", "3", "4"] {
            assert!(labels.iter().any(|l| l == id), "{figure}: agent {id}");
        }
    }
}

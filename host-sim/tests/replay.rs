//! `replay.html` (host-sim/src/report/replay/): written by `host-sim run` with the plots,
//! self-contained (no network reference), bounded in size, its data equal to
//! `timeseries.csv`; `host-sim view`. The ignored test `replay_in_headless_chromium` loads
//! it in a real browser (`cargo xtask test` runs it; Chromium from
//! `scripts/browser-deps.sh`).

use ph_formation_sim::report::replay::{ReplayData, MAX_AGENTS, MAX_BYTES, MAX_CELLS};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_host-sim"));
    // Never open a browser from a test.
    c.env_remove("BROWSER")
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY");
    c
}

fn run(args: &[&str]) -> Output {
    let o = bin().args(args).output().expect("spawn host-sim");
    assert!(
        !String::from_utf8_lossy(&o.stderr).contains("panicked"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

/// Runs `scenario` into `dir/name` and returns the directory.
fn run_into(dir: &Path, name: &str, scenario: &str, extra: &[&str]) -> PathBuf {
    let out = dir.join(name);
    let mut args = vec!["-q", "run", scenario, "--out", out.to_str().expect("utf-8")];
    args.extend_from_slice(extra);
    let o = run(&args);
    // Any outcome (0 converged, 10 not converged for a short run …), not an error.
    assert!(matches!(o.status.code(), Some(0 | 10..=14)), "{o:?}");
    out
}

/// The rows of `timeseries.csv`: header and numbers.
fn csv(dir: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(dir.join("timeseries.csv")).expect("csv");
    let mut lines = text.lines();
    let header = lines
        .next()
        .expect("header")
        .split(',')
        .map(str::to_owned)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(|v| v.parse().expect("number")).collect())
        .collect();
    (header, rows)
}

/// The data object of the page (`var D = {…};`, one line).
fn page_data(html: &str) -> Value {
    let start = html.find("var D = ").expect("var D") + "var D = ".len();
    let line = html[start..].lines().next().expect("data line");
    serde_json::from_str(line.trim_end_matches(';')).expect("data is JSON")
}

/// `a` equals `b` to 1e-6 relative.
fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-6 * b.abs()
}

/// Checks agent positions `x`, `y` (drawn agents `ids`) at time `t` against the CSV row
/// of that time.
fn check_positions(dir: &Path, t: f64, ids: &[String], x: &[f64], y: &[f64]) {
    let (header, rows) = csv(dir);
    let row = rows
        .iter()
        .min_by(|a, b| (a[0] - t).abs().total_cmp(&(b[0] - t).abs()))
        .expect("rows");
    assert!(
        (row[0] - t).abs() <= 1e-9 * t.abs().max(1.0),
        "no row at t = {t}"
    );
    let col = |n: String| header.iter().position(|h| *h == n).expect("column");
    assert!(!ids.is_empty());
    for (k, id) in ids.iter().enumerate() {
        let (cx, cy) = (row[col(format!("x_{id}"))], row[col(format!("y_{id}"))]);
        assert!(
            close(x[k], cx) && close(y[k], cy),
            "agent {id} at t = {t}: drawn ({}, {}), timeseries.csv ({cx}, {cy})",
            x[k],
            y[k]
        );
    }
}

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .expect("array")
        .iter()
        .map(|x| x.as_f64().unwrap_or(f64::NAN))
        .collect()
}

#[test]
fn run_writes_a_self_contained_replay_whose_data_is_the_time_series() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let dir = run_into(tmp.path(), "p", "paper", &["--duration", "5"]);
    let html = std::fs::read_to_string(dir.join("replay.html")).expect("replay.html");
    for bad in [
        "http://", "https://", "src=", "href=", "fetch(", "url(", "@import",
    ] {
        assert!(!html.contains(bad), "replay.html contains {bad}");
    }
    assert!(html.len() <= MAX_BYTES);
    let d = page_data(&html);
    let ids: Vec<String> = d["ids"]
        .as_array()
        .expect("ids")
        .iter()
        .map(|v| v.as_str().expect("id").to_owned())
        .collect();
    assert_eq!(ids, ["1", "2", "3", "4"]);
    assert_eq!(d["leaders"], serde_json::json!([0, 1]));
    assert_eq!(d["edges"].as_array().expect("edges").len(), 5);
    let (t, x, y) = (numbers(&d["t"]), numbers(&d["x"]), numbers(&d["y"]));
    let (_, rows) = csv(&dir);
    assert_eq!(d["rows"], rows.len());
    assert_eq!(t.len(), rows.len(), "a short run keeps every row");
    let a = ids.len();
    for f in [0, t.len() / 2, t.len() - 1] {
        check_positions(&dir, t[f], &ids, &x[f * a..][..a], &y[f * a..][..a]);
    }
    // Edge colours: the largest |angle error| over the angles at each edge.
    let err = numbers(&d["edge_err"]);
    let first_max = err[..5].iter().copied().fold(0.0, f64::max);
    // (written with 3 significant digits: colours need no more)
    assert!(
        (first_max - rows[0][6]).abs() <= 5e-3 * rows[0][6],
        "{first_max}"
    );
}

#[test]
fn no_plots_writes_no_replay_and_view_writes_a_missing_one() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let dir = run_into(
        tmp.path(),
        "f",
        "formation-only",
        &["--duration", "1", "--no-plots"],
    );
    assert!(dir.join("timeseries.csv").is_file());
    assert!(!dir.join("replay.html").exists());
    let o = run(&["view", "--no-open", dir.to_str().expect("utf-8")]);
    assert_eq!(o.status.code(), Some(0), "{o:?}");
    let page = dir.join("replay.html");
    assert_eq!(
        String::from_utf8_lossy(&o.stdout).trim(),
        page.to_str().unwrap()
    );
    assert!(page.is_file());
    // Not a run directory: exit 1, naming the file.
    let o = run(&["view", "--no-open", tmp.path().to_str().expect("utf-8")]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("summary.json"));
}

#[test]
fn a_large_run_is_thinned_to_the_budget_with_its_leaders() {
    // A synthetic run directory: 1,500 agents on a line, 120 rows, leaders 1,498 and 1,499.
    let n = 1_500;
    let rows = 120;
    let tmp = tempfile::tempdir().expect("tempdir");
    let ids: Vec<usize> = (0..n).collect();
    let edges: Vec<[usize; 2]> = (1..n).map(|i| [i - 1, i]).collect();
    let summary = serde_json::json!({
        "scenario": "line", "outcome": "converged", "agents": ids, "edges": edges,
        "leaders": [n - 2, n - 1], "criteria": {"angle_tolerance_rad": 1e-3},
    });
    std::fs::write(tmp.path().join("summary.json"), summary.to_string()).expect("summary");
    let mut text = String::from("t,V,max_angle_err");
    for i in 0..n {
        text.push_str(&format!(",x_{i},y_{i},vx_{i},vy_{i}"));
    }
    text.push('\n');
    for r in 0..rows {
        text.push_str(&format!("{},1,0.1", r as f64 * 0.01));
        for i in 0..n {
            text.push_str(&format!(",{},{},0.5,0", i as f64 + r as f64 * 0.005, r));
        }
        text.push('\n');
    }
    std::fs::write(tmp.path().join("timeseries.csv"), text).expect("csv");
    let data = ReplayData::load(tmp.path()).expect("load");
    assert!(data.ids().len() <= MAX_AGENTS);
    assert!(data.ids().iter().any(|i| i == "1498") && data.ids().iter().any(|i| i == "1499"));
    assert!(data.frames() >= 2 && data.frames() < rows);
    assert!(data.frames() * 4 * data.ids().len() <= MAX_CELLS);
    let path = ph_formation_sim::report::write_replay(tmp.path()).expect("write");
    let size = std::fs::metadata(path).expect("size").len() as usize;
    assert!(size <= MAX_BYTES, "{size} bytes");
}

/// A sweep directory: `points.csv` over two axes, one point with a collision.
fn sweep_dir(root: &Path) -> PathBuf {
    let dir = root.join("sweep");
    std::fs::create_dir_all(&dir).expect("mkdir");
    let mut text = String::from(
        "point,radio.loss,controller.estimator,runs,errors,converged,converged_lo,converged_hi,collision,collision_lo,collision_hi,settled,settle_p10,settle_p50,settle_p90\n",
    );
    for (k, (loss, est, conv)) in [
        (0.0, "shared", 1.0),
        (0.2, "shared", 0.75),
        (0.0, "measured", 1.0),
    ]
    .iter()
    .enumerate()
    {
        text.push_str(&format!(
            "{k},{loss},{est},4,0,{conv},0.5,1.0,{},0.0,0.5,4,40.0,41.0,42.0\n",
            1.0 - conv
        ));
    }
    std::fs::write(dir.join("points.csv"), text).expect("points.csv");
    dir
}

#[test]
fn view_writes_a_sweep_page_over_the_axes() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let dir = sweep_dir(tmp.path());
    let o = run(&["view", "--no-open", dir.to_str().expect("utf-8")]);
    assert_eq!(o.status.code(), Some(0), "{o:?}");
    let page = dir.join("sweep.html");
    assert_eq!(
        String::from_utf8_lossy(&o.stdout).trim(),
        page.to_str().unwrap()
    );
    let html = std::fs::read_to_string(&page).expect("sweep.html");
    for bad in ["http://", "https://", "src=", "href=", "fetch("] {
        assert!(!html.contains(bad), "sweep.html contains {bad}");
    }
    let d = page_data(&html);
    assert_eq!(
        d["axes"],
        serde_json::json!(["radio.loss", "controller.estimator"])
    );
    assert_eq!(d["outcomes"], serde_json::json!(["converged", "collision"]));
    assert_eq!(d["rows"][1][5], serde_json::json!(0.75));
    assert_eq!(d["rows"][2][2], serde_json::json!("measured"));
}

// ---------------------------------------------------------------------------------------
// In a real browser

/// Headless Chromium: `$CHROMIUM`, else `chromium` or `chromium-browser` on the PATH.
fn chromium() -> PathBuf {
    if let Some(c) = std::env::var_os("CHROMIUM") {
        return PathBuf::from(c);
    }
    let path = std::env::var_os("PATH").unwrap_or_default();
    for name in ["chromium", "chromium-browser"] {
        if let Some(p) = std::env::split_paths(&path)
            .map(|d| d.join(name))
            .find(|p| p.is_file())
        {
            return p;
        }
    }
    panic!("no chromium on the PATH: run scripts/browser-deps.sh (Debian package chromium)");
}

/// Runs headless Chromium on `page#hash` with `mode` (`--dump-dom`, `--screenshot=…`);
/// returns stdout. Fails on any console message or page error (the page logs nothing).
fn browse(profile: &Path, page: &Path, hash: &str, mode: &[&str]) -> String {
    let url = format!("file://{}#{hash}", page.display());
    let o = Command::new(chromium())
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-dev-shm-usage",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--hide-scrollbars",
            "--enable-logging=stderr",
            "--v=0",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .args(mode)
        .arg(&url)
        .output()
        .expect("start chromium");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "chromium failed on {url}: {err}");
    let console: Vec<&str> = err.lines().filter(|l| l.contains(":CONSOLE")).collect();
    assert!(console.is_empty(), "console output on {url}: {console:#?}");
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// The text of `<pre id="{id}" …>…</pre>` in a dumped DOM.
fn pre(dom: &str, id: &str) -> String {
    let open = format!("id=\"{id}\"");
    let at = dom
        .find(&open)
        .unwrap_or_else(|| panic!("no #{id} in the DOM"));
    let body = &dom[at..];
    let start = body.find('>').expect(">") + 1;
    let end = body.find("</pre>").expect("</pre>");
    body[start..end]
        .replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&amp;", "&")
}

/// Width, height and RGB pixels of a PNG.
fn decode(png_path: &Path) -> (usize, usize, Vec<[u8; 3]>) {
    let mut decoder = png::Decoder::new(std::fs::File::open(png_path).expect("screenshot"));
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = decoder.read_info().expect("png");
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).expect("frame");
    let bpp = info.color_type.samples();
    let pixels = buf[..info.buffer_size()]
        .chunks_exact(bpp)
        .map(|p| {
            if bpp >= 3 {
                [p[0], p[1], p[2]]
            } else {
                [p[0]; 3]
            }
        })
        .collect();
    (info.width as usize, info.height as usize, pixels)
}

/// Non-background pixels and distinct colours of a PNG screenshot.
fn ink(png_path: &Path) -> (usize, usize, Vec<u8>) {
    let mut decoder = png::Decoder::new(std::fs::File::open(png_path).expect("screenshot"));
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = decoder.read_info().expect("png");
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).expect("frame");
    let bpp = info.color_type.samples();
    let pixels: Vec<[u8; 3]> = buf[..info.buffer_size()]
        .chunks_exact(bpp)
        .map(|p| {
            if bpp >= 3 {
                [p[0], p[1], p[2]]
            } else {
                [p[0]; 3]
            }
        })
        .collect();
    let inked = pixels.iter().filter(|p| **p != [255, 255, 255]).count();
    let mut colours: Vec<[u8; 3]> = pixels.clone();
    colours.sort_unstable();
    colours.dedup();
    (inked, colours.len(), pixels.concat())
}

#[test]
#[ignore = "needs headless Chromium (scripts/browser-deps.sh); cargo xtask test runs it"]
fn replay_in_headless_chromium() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let dir = run_into(tmp.path(), "paper", "paper", &[]);
    let page = dir.join("replay.html");
    let profile = tmp.path().join("profile");

    // The hook's drawn positions at the first frame, two times between and the last,
    // against timeseries.csv.
    let dom = browse(
        &profile,
        &page,
        "probe=first,0.3,41.7,last",
        &["--dump-dom"],
    );
    assert_eq!(pre(&dom, "ph-errors"), "[]", "page errors");
    let probes: Value = serde_json::from_str(&pre(&dom, "ph-probe")).expect("probe JSON");
    let probes = probes.as_array().expect("array");
    assert_eq!(probes.len(), 4);
    let last_t = csv(&dir).1.last().expect("rows")[0];
    let times: Vec<f64> = probes.iter().map(|p| p["t"].as_f64().expect("t")).collect();
    assert_eq!(times[0], 0.0);
    assert!(times[1] <= 0.3 && times[1] > 0.2, "{times:?}");
    assert!(times[2] <= 41.7 && times[2] > 41.6, "{times:?}");
    assert!((times[3] - last_t).abs() < 1e-9, "{times:?}");
    for p in probes {
        let ids: Vec<String> = p["ids"]
            .as_array()
            .expect("ids")
            .iter()
            .map(|v| v.as_str().expect("id").to_owned())
            .collect();
        let (x, y) = (numbers(&p["x"]), numbers(&p["y"]));
        check_positions(&dir, p["t"].as_f64().expect("t"), &ids, &x, &y);
    }

    // Screenshots of the view alone at the first and the last frame: drawn, and different.
    let mut shots = Vec::new();
    for at in ["first", "last"] {
        let png = tmp.path().join(format!("{at}.png"));
        browse(
            &profile,
            &page,
            &format!("t={at}&shot"),
            &[
                "--window-size=960,600",
                &format!("--screenshot={}", png.display()),
            ],
        );
        let (inked, colours, pixels) = ink(&png);
        assert!(
            inked > 500 && colours > 10,
            "{at} frame looks blank: {inked} non-white pixels, {colours} colours"
        );
        shots.push(pixels);
    }
    assert_ne!(shots[0], shots[1], "first and last frames look the same");

    // The optional fields a later run may write (headings, field of view, dropped links)
    // are drawn without error.
    let mut d = page_data(&std::fs::read_to_string(&page).expect("page"));
    let cells = d["x"].as_array().expect("x").len();
    let edge_cells = d["edge_err"].as_array().expect("edge_err").len();
    d["heading"] = serde_json::json!(vec![0.7; cells]);
    d["fov"] = serde_json::json!(0.6);
    d["edge_dropped"] = serde_json::json!((0..edge_cells).map(|k| k % 3 == 0).collect::<Vec<_>>());
    let optional = tmp.path().join("optional.html");
    std::fs::write(
        &optional,
        ph_formation_sim::report::replay::page(&d.to_string()),
    )
    .expect("write");
    let dom = browse(&profile, &optional, "probe=last", &["--dump-dom"]);
    assert_eq!(
        pre(&dom, "ph-errors"),
        "[]",
        "page errors with the optional fields"
    );
    assert!(pre(&dom, "ph-probe").contains("\"frame\""));

    // A sweep's page draws without error.
    let sweep = sweep_dir(tmp.path());
    let o = run(&["view", "--no-open", sweep.to_str().expect("utf-8")]);
    assert_eq!(o.status.code(), Some(0), "{o:?}");
    let dom = browse(&profile, &sweep.join("sweep.html"), "", &["--dump-dom"]);
    assert_eq!(pre(&dom, "ph-errors"), "[]", "sweep page errors");
    assert!(dom.contains("data-ready=\"1\""));
}

// ---------------------------------------------------------------------------------------
// Layout, scale bar and first frame, in a real browser (issue 47 item 3)

/// A box `{left, top, right, bottom}` of the page's `layout()` lies in a `w` × `h`
/// viewport.
fn inside(b: &Value, w: f64, h: f64) -> bool {
    let n = |k: &str| b[k].as_f64().expect("box side");
    n("left") >= 0.0 && n("top") >= 0.0 && n("right") <= w && n("bottom") <= h
}

/// The legend and the controls of a page `layout` lie in its viewport.
fn legend_and_controls_in_view(layout: &Value) -> bool {
    let w = layout["window"][0].as_f64().expect("width");
    let h = layout["window"][1].as_f64().expect("height");
    inside(&layout["legend"], w, h) && inside(&layout["controls"], w, h)
}

/// The metres of a scale bar's label ("20 cm", "5 m", "2 km").
fn label_metres(label: &str) -> f64 {
    let (v, unit) = label.split_once(' ').expect("number and unit");
    let v: f64 = v.parse().expect("number");
    match unit {
        "cm" => v / 100.0,
        "m" => v,
        "km" => v * 1000.0,
        other => panic!("unit {other}"),
    }
}

/// The scale bar's label, at `metres_per_pixel`, matches its drawn length to 1 %.
fn bar_matches(bar: &Value, metres_per_pixel: f64) -> bool {
    let m = label_metres(bar["label"].as_str().expect("label"));
    let drawn = bar["pixels"].as_f64().expect("pixels") * metres_per_pixel;
    (drawn - m).abs() <= 0.01 * m
}

/// Every agent's drawn position of a probe lies in the canvas, and the drawn extent of the
/// formation (its bounding box's larger side, pixels) over the canvas's smaller side.
fn first_frame(probe: &Value) -> (bool, f64) {
    let (px, py) = (numbers(&probe["px"]), numbers(&probe["py"]));
    let w = probe["canvas"][0].as_f64().expect("W");
    let h = probe["canvas"][1].as_f64().expect("H");
    let all_in = px.iter().zip(&py).all(|(&x, &y)| {
        x.is_finite() && y.is_finite() && (0.0..=w).contains(&x) && (0.0..=h).contains(&y)
    });
    let span = |v: &[f64]| {
        v.iter().copied().fold(f64::MIN, f64::max) - v.iter().copied().fold(f64::MAX, f64::min)
    };
    (all_in, span(&px).max(span(&py)) / w.min(h))
}

/// Dumps `page#hash` at window `size`: the probes (`#probe=…`) and the layout.
fn probe_layout(profile: &Path, page: &Path, hash: &str, size: (u32, u32)) -> (Vec<Value>, Value) {
    let dom = browse(
        profile,
        page,
        &format!("{hash}&layout"),
        &[
            &format!("--window-size={},{}", size.0, size.1),
            "--dump-dom",
        ],
    );
    assert_eq!(pre(&dom, "ph-errors"), "[]", "page errors at {size:?}");
    let probes: Value = serde_json::from_str(&pre(&dom, "ph-probe")).expect("probe JSON");
    let layout = serde_json::from_str(&pre(&dom, "ph-layout")).expect("layout JSON");
    (probes.as_array().expect("probes").clone(), layout)
}

/// The longest run of `colour` pixels on row `y` of a screenshot.
fn longest_run(w: usize, pixels: &[[u8; 3]], y: usize, colour: [u8; 3]) -> usize {
    let (mut best, mut run) = (0, 0);
    for p in &pixels[y * w..][..w] {
        run = if *p == colour { run + 1 } else { 0 };
        best = best.max(run);
    }
    best
}

#[test]
#[ignore = "needs headless Chromium (scripts/browser-deps.sh); cargo xtask test runs it"]
fn replay_layout_scale_and_first_frame_in_headless_chromium() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let dir = run_into(tmp.path(), "paper", "paper", &[]);
    let page = dir.join("replay.html");
    let profile = tmp.path().join("profile");
    // The screenshots stay in target/ (CARGO_TARGET_TMPDIR), not committed.
    let shots = Path::new(env!("CARGO_TARGET_TMPDIR")).join("replay-screenshots");
    std::fs::create_dir_all(&shots).expect("screenshot dir");

    for size in [(1200, 900), (1366, 768), (1920, 1080)] {
        let (probes, layout) = probe_layout(&profile, &page, "probe=first,last", size);
        // The viewport is the window less the browser's own bars.
        let vw = layout["window"][0].as_u64().expect("width") as u32;
        let vh = layout["window"][1].as_u64().expect("height") as u32;
        assert!(vw <= size.0 && vh <= size.1 && vh >= size.1 / 2, "{layout}");
        assert!(
            legend_and_controls_in_view(&layout),
            "legend or controls out of the {size:?} window: {layout}"
        );
        // t = 0: every agent on the canvas, the formation at least 20 % of it.
        let (first, last) = (&probes[0], &probes[1]);
        assert_eq!(first["t"], 0.0);
        let (all_in, extent) = first_frame(first);
        assert!(all_in && extent >= 0.2, "t = 0 at {size:?}: {first}");
        // The scale bar: its label is its drawn length at the page's scale, to 1 %.
        for p in [first, last] {
            let mpp = p["metres_per_pixel"].as_f64().expect("mpp");
            assert!(bar_matches(&p["scale_bar"], mpp), "{p}");
            assert_eq!(
                label_metres(p["scale_bar"]["label"].as_str().expect("label")),
                p["scale_bar"]["metres"].as_f64().expect("metres")
            );
        }
        // It adapts to the zoom: the formation grows tenfold, so does the bar.
        assert!(
            last["scale_bar"]["metres"].as_f64() > first["scale_bar"]["metres"].as_f64(),
            "{first} {last}"
        );
        // Negative control: the first frame's bar read at the last frame's scale.
        let last_mpp = last["metres_per_pixel"].as_f64().expect("mpp");
        assert!(!bar_matches(&first["scale_bar"], last_mpp));

        // A screenshot of that viewport at t = 0: the bar drawn at its length, every agent
        // drawn where the hook says, the legend's swatches present.
        let png = shots.join(format!("replay-{}x{}-t0.png", size.0, size.1));
        browse(
            &profile,
            &page,
            "t=first",
            &[
                &format!("--window-size={vw},{vh}"),
                &format!("--screenshot={}", png.display()),
            ],
        );
        let (w, h, pixels) = decode(&png);
        assert_eq!((w, h), (vw as usize, vh as usize), "screenshot size");
        let view = &layout["view"];
        let (left, top) = (
            view["left"].as_f64().expect("left") + 1.0, // the canvas's 1 px border
            view["top"].as_f64().expect("top") + 1.0,
        );
        let bar = &first["scale_bar"];
        let bar_row = (top + bar["y"].as_f64().expect("y") + 1.0) as usize;
        let drawn = longest_run(w, &pixels, bar_row, [10, 11, 12]);
        let want = bar["pixels"].as_u64().expect("pixels") as usize;
        assert!(
            drawn.abs_diff(want) <= 1,
            "scale bar {drawn} px drawn, {want} px labelled"
        );
        for (x, y) in numbers(&first["px"]).iter().zip(numbers(&first["py"])) {
            let (x, y) = ((left + x) as usize, (top + y) as usize);
            let p = pixels[y * w + x];
            // an agent's dot (#222) or a leader's (#1a2a9a)
            assert!(
                p == [0x22; 3] || p == [0x1a, 0x2a, 0x9a],
                "no agent dot at ({x}, {y}): {p:?}"
            );
        }
        let legend_row = (layout["legend"]["top"].as_f64().expect("top") + 8.0) as usize;
        assert!(
            pixels[legend_row * w..][..w].contains(&[0x2a, 0x9d, 0x3a]),
            "no green swatch on the legend's first line"
        );
    }

    // Negative control of the layout: the old order (view, controls, chart, then the legend)
    // puts the legend below the fold at 1200 × 900.
    let html = std::fs::read_to_string(&page).expect("page");
    let old = html.replacen("<p id=\"legend\"></p>\n", "", 1).replacen(
        "<canvas id=\"chart\" width=\"960\" height=\"220\"></canvas>\n",
        "<canvas id=\"chart\" width=\"960\" height=\"220\"></canvas>\n<p id=\"legend\"></p>\n",
        1,
    );
    assert_ne!(old, html, "the old layout was not rebuilt");
    let old_page = tmp.path().join("old-layout.html");
    std::fs::write(&old_page, old).expect("write");
    let (_, layout) = probe_layout(&profile, &old_page, "probe=first", (1200, 900));
    assert!(!legend_and_controls_in_view(&layout), "{layout}");

    // Cameras: with a field of view and range in the data (summary.json's
    // world.sensors.camera) a pale blue wedge per agent, at the world's nominal heading;
    // without them none.
    let mut d = page_data(&html);
    let wedge_pixels = |d: &Value, name: &str| {
        let page = tmp.path().join(format!("{name}.html"));
        std::fs::write(
            &page,
            ph_formation_sim::report::replay::page(&d.to_string()),
        )
        .expect("write");
        let png = shots.join(format!("replay-{name}-t0.png"));
        browse(
            &profile,
            &page,
            "t=first&shot",
            &[
                "--window-size=960,600",
                &format!("--screenshot={}", png.display()),
            ],
        );
        let (_, _, pixels) = decode(&png);
        // rgba(120,120,200,0.12) over white: about (240, 240, 250)
        pixels
            .iter()
            .filter(|p| p[0] == p[1] && p[2] > p[0].saturating_add(5) && p[0] > 225)
            .count()
    };
    let without = wedge_pixels(&d, "no-camera");
    d["fov"] = serde_json::json!(87f64.to_radians() / 2.0);
    d["camera_range"] = serde_json::json!(0.8);
    d["heading_nominal"] = serde_json::json!(0.0);
    let with = wedge_pixels(&d, "camera");
    assert!(
        with > 2_000 && without < 100,
        "wedge pixels {with} with, {without} without"
    );

    // Negative control of the view: the previous fit (one scale for the widest, final
    // frame) makes the formation at t = 0 a speck.
    let (probes, _) = probe_layout(&profile, &page, "probe=first&view=follow", (1200, 900));
    let (all_in, extent) = first_frame(&probes[0]);
    assert!(all_in && extent < 0.2, "{}", probes[0]);
}

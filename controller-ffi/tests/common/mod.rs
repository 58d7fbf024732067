//! Helpers of the C tests and of the QEMU demo's test (`tests/tests/qemu_demo.rs`):
//! building the C programs (`c/build.sh`) and reading their `DEMO` lines.
#![allow(dead_code)] // Each test binary uses a part.

use std::path::{Path, PathBuf};
use std::process::Command;

/// Largest difference of a relative position `q_i − q_1` from the target, in metres.
pub const TOLERANCE: f64 = 1e-2;

/// The paper's target square 1-2-4-3 as `q_i − q_1` (SPEC §9, `z* = q1 − q2 =
/// (10, −10)`).
pub const SQUARE: [[f64; 2]; 4] = [[0.0, 0.0], [-10.0, 10.0], [10.0, 10.0], [0.0, 20.0]];

/// The workspace root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// A scratch directory of this test binary.
pub fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch directory");
    dir
}

/// Runs `controller-ffi/c/build.sh <what> <out>` (which builds the staticlib with cargo
/// and compiles the C program against it); returns the path it printed.
pub fn build(what: &str, out: &Path) -> PathBuf {
    build_with(what, out, &[])
}

/// [`build`] with environment variables (e.g. `CFAPP_CFLAGS`).
pub fn build_with(what: &str, out: &Path, env: &[(&str, &str)]) -> PathBuf {
    let script = root().join("controller-ffi/c/build.sh");
    let run = Command::new("bash")
        .envs(env.iter().copied())
        .arg(&script)
        .arg(what)
        .arg(out)
        .output()
        .expect("run controller-ffi/c/build.sh");
    assert!(
        run.status.success(),
        "{} {what} failed ({}):\n{}{}",
        script.display(),
        run.status,
        String::from_utf8_lossy(&run.stdout),
        String::from_utf8_lossy(&run.stderr)
    );
    let path = String::from_utf8_lossy(&run.stdout)
        .lines()
        .last()
        .unwrap_or_default()
        .to_string();
    PathBuf::from(path)
}

/// Parses `DEMO final t=<t> rel=<x1>,<y1>;…` (the line of qemu-demo and of the C
/// demo): `(t, [q_i − q_1])`.
pub fn parse_demo_final(log: &str) -> Result<(f64, Vec<[f64; 2]>), String> {
    let line = log
        .lines()
        .rev()
        .find(|l| l.contains("DEMO final"))
        .ok_or("no 'DEMO final' line")?;
    let field = |name: &str| -> Result<&str, String> {
        let start = line
            .find(&format!(" {name}="))
            .ok_or(format!("no '{name}=' in {line:?}"))?
            + name.len()
            + 2;
        Ok(line[start..].split_whitespace().next().unwrap_or(""))
    };
    let t: f64 = field("t")?
        .parse()
        .map_err(|e| format!("bad t in {line:?}: {e}"))?;
    let rel = field("rel")?
        .split(';')
        .map(|pair| {
            let xy: Vec<f64> = pair
                .split(',')
                .map(|x| {
                    x.trim()
                        .parse::<f64>()
                        .map_err(|e| format!("bad number {x:?}: {e}"))
                })
                .collect::<Result<_, _>>()?;
            match xy[..] {
                [x, y] => Ok([x, y]),
                _ => Err(format!("expected x,y, got {pair:?}")),
            }
        })
        .collect::<Result<Vec<_>, String>>()?;
    Ok((t, rel))
}

/// Largest distance between corresponding points (an error if their numbers differ).
pub fn max_difference(a: &[[f64; 2]], b: &[[f64; 2]]) -> Result<f64, String> {
    if a.len() != b.len() {
        return Err(format!("{} positions against {}", a.len(), b.len()));
    }
    Ok(a.iter()
        .zip(b)
        .map(|(p, q)| (p[0] - q[0]).hypot(p[1] - q[1]))
        .fold(0.0, f64::max))
}

//! The figures of `crazyflie-app/README.md` against their sources, so that they cannot
//! drift: `PH_AGENT_SIZE` (the header), the stack figures (docs/c-api.md's table,
//! which `crazyflie_app.rs` checks against a QEMU measurement), `CONFIG_APP_STACKSIZE`
//! (app-config), the frames per tick (the app's four agents, built from its exported
//! blobs through the C API) and the packets per second; and docs/c-api.md's blob
//! format version against the library's.

use std::path::PathBuf;

use ph_formation_ffi::api::{ph_agent_init_blob, ph_frames};
use ph_formation_ffi::storage::ph_agent;
use ph_formation_ffi::{ph_status, PH_AGENT_SIZE, PH_MAX_FRAMES_PER_TICK, PH_MAX_FRAME_LEN};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn read(path: &str) -> String {
    std::fs::read_to_string(root().join(path)).unwrap_or_else(|e| panic!("read {path}: {e}"))
}

/// The number right after `before` in `text` (digits and thousands commas; a decimal
/// point allowed).
fn after(text: &str, before: &str) -> f64 {
    let start = text
        .find(before)
        .unwrap_or_else(|| panic!("{before:?} not found"))
        + before.len();
    let digits: String = text[start..]
        .chars()
        .take_while(|c| c.is_ascii_digit() || *c == ',' || *c == '.')
        .filter(|c| *c != ',')
        .collect();
    digits
        .trim_end_matches('.')
        .parse()
        .unwrap_or_else(|e| panic!("no number after {before:?}: {e}"))
}

/// `#define NAME <n>` of the header's 32-bit (Cortex-M) branch.
fn header_32bit(name: &str) -> f64 {
    let header = read("controller-ffi/include/ph_formation.h");
    let branch = &header[header.find("#if defined(PH_PTR32)").expect("32-bit branch")..];
    after(branch, &format!("#define {name} "))
}

#[test]
fn readme_agent_size_is_the_headers() {
    let readme = read("crazyflie-app/README.md");
    let stated = after(&readme, "`PH_AGENT_SIZE` = **");
    assert_eq!(
        stated,
        header_32bit("PH_AGENT_SIZE"),
        "crazyflie-app/README.md"
    );
}

#[test]
fn readme_stack_figures_are_the_measured_ones() {
    let readme = read("crazyflie-app/README.md");
    let doc = read("docs/c-api.md");
    let row = "| Crazyflie app, configuration from the blob | ";
    let init = after(&doc, row);
    let tick = after(&doc, &format!("{row}{} | ", fmt_thousands(init)));
    assert_eq!(
        after(&readme, "the app's peak is **"),
        init,
        "README init peak"
    );
    assert_eq!(after(&readme, "a tick needs **"), tick, "README tick");
    let words = after(&read("crazyflie-app/app-config"), "\nCONFIG_APP_STACKSIZE=");
    assert_eq!(
        after(&readme, "`CONFIG_APP_STACKSIZE="),
        words,
        "README stack words"
    );
    assert_eq!(
        after(&readme, "stack bytes = **"),
        words * 4.0,
        "README stack bytes"
    );
    let ratio = after(&readme, "margin = **");
    assert!(
        (ratio - words * 4.0 / init.max(tick)).abs() < 0.005,
        "README ratio {ratio} vs {}",
        words * 4.0 / init.max(tick)
    );
}

fn fmt_thousands(x: f64) -> String {
    let n = x as u64;
    if n >= 1000 {
        format!("{},{:03}", n / 1000, n % 1000)
    } else {
        n.to_string()
    }
}

#[repr(C, align(8))]
struct Memory([u8; PH_AGENT_SIZE]);

/// Frames each agent of the app's formation sends per tick (from its exported blob).
fn frames_per_agent() -> Vec<usize> {
    (1..=4)
        .map(|id| {
            let path = format!("crazyflie-app/src/blobs/agent{id}.blob");
            let blob = std::fs::read(root().join(&path)).expect("blob");
            let mut mem = Box::new(Memory([0; PH_AGENT_SIZE]));
            let a = mem.0.as_mut_ptr().cast::<ph_agent>();
            let mut frames = [[0u8; PH_MAX_FRAME_LEN]; PH_MAX_FRAMES_PER_TICK];
            let mut lens = [0u8; PH_MAX_FRAMES_PER_TICK];
            let mut n = 0;
            // SAFETY: valid memory and buffers of the stated sizes.
            unsafe {
                assert_eq!(
                    ph_agent_init_blob(a, PH_AGENT_SIZE, blob.as_ptr(), blob.len()),
                    ph_status::PH_OK
                );
                assert_eq!(
                    ph_frames(
                        a,
                        frames.as_mut_ptr(),
                        lens.as_mut_ptr(),
                        PH_MAX_FRAMES_PER_TICK,
                        &mut n
                    ),
                    ph_status::PH_OK
                );
            }
            n
        })
        .collect()
}

#[test]
fn readme_radio_figures_are_the_apps() {
    let readme = read("crazyflie-app/README.md");
    let frames = frames_per_agent();
    assert_eq!(
        frames.iter().max().map(|&n| n as f64),
        Some(after(&readme, "every agent sends **")),
        "frames per agent per tick: {frames:?}"
    );
    let period_ms = after(
        &read("crazyflie-app/src/app.c"),
        "#define CONTROL_PERIOD_MS ",
    );
    // One position packet per agent per tick besides the frames.
    let per_second = frames.iter().map(|&n| n + 1).sum::<usize>() as f64 * 1000.0 / period_ms;
    assert_eq!(
        after(&readme, "formation puts\n  **"),
        per_second,
        "P2P packets/s"
    );
}

#[test]
fn c_api_doc_states_the_blob_version() {
    let doc = read("docs/c-api.md");
    assert_eq!(
        after(&doc, "| 4 | format version ("),
        f64::from(ph_formation_ffi::blob::BLOB_VERSION),
        "docs/c-api.md blob layout"
    );
}

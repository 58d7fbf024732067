//! `host-sim export (--agent ID | --all) SCENARIO`: agents' configurations as the C
//! API's checked configuration blob (`controller-ffi`, docs/c-api.md "Configuration"),
//! so that a formation designed and simulated on the laptop is flashed without
//! retyping numbers. A blob is the scenario's configuration of that agent rounded to
//! `f32` ([`crate::model::Model::agent_config_f32`]), checked by the core as the
//! firmware will (`Agent::new` with the C API's capacities), versioned and CRC-32
//! checksummed.
//!
//! `--all -o DIR` writes every agent's `agent<ID>.blob` and `ph_blobs.c` +
//! `ph_blobs.h`: every blob in one C table indexed by wire id, which the Crazyflie
//! app (`crazyflie-app/src/formation.c`) searches by its radio address at boot
//! (docs/crazyflie.md). `--vehicle crazyflie` first checks the limits against what
//! the vehicle can do (`super::vehicle`).

use super::ExportArgs;
use crate::exit_code;
use crate::model::Model;
use ph_formation_ffi::blob::{encode_blob_with, BlobPolicy, PH_MAX_BLOB_LEN};
use ph_formation_ffi::PH_MAX_TRIANGLES;
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};

/// Why an agent cannot be exported, or its files cannot be written.
#[derive(Debug, thiserror::Error)]
pub(super) enum ExportError {
    /// The agent's `f32` configuration cannot be built.
    #[error("agent {agent}: {source}")]
    Config {
        /// The agent's id.
        agent: String,
        /// Why.
        source: crate::model::ModelError,
    },
    /// The C API's encoder refuses the configuration.
    #[error("agent {agent}: the C API refuses this agent's configuration: {error:?}")]
    Blob {
        /// The agent's id.
        agent: String,
        /// The encoder's reason.
        error: ph_formation_ffi::blob::BlobError,
    },
    /// `--all` without `-o DIR`.
    #[error("--all writes several files: give the directory with -o DIR")]
    NoDirectory,
    /// A directory cannot be created.
    #[error("cannot create {}: {source}", path.display())]
    CreateDir {
        /// The directory.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// A file cannot be written.
    #[error("cannot write {}: {source}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// Standard output cannot be written.
    #[error("cannot write to stdout: {0}")]
    Stdout(std::io::Error),
}

/// One agent's blob.
pub(super) struct Exported {
    /// The id as written in the scenario.
    name: String,
    /// Wire id (what the app matches against its radio address).
    pub(super) id: u8,
    triangles: usize,
    pub(super) blob: Vec<u8>,
}

/// Runs `host-sim export`; returns the exit code.
pub(super) fn export_command(args: &ExportArgs, quiet: bool) -> u8 {
    let model = match crate::api::load(&args.scenario, &args.set) {
        Ok(m) => m,
        Err(e) => return super::report(&e),
    };
    let indices: Vec<usize> = match (&args.agent, args.all) {
        (Some(agent), false) => match model.agents.iter().position(|a| &a.name == agent) {
            Some(i) => vec![i],
            None => {
                let ids: Vec<&str> = model.agents.iter().map(|a| a.name.as_str()).collect();
                eprintln!(
                    "error: --agent {agent}: scenario {} has no agent with that id (its agents: {})",
                    model.source,
                    ids.join(", ")
                );
                return exit_code::USAGE;
            }
        },
        (None, true) => (0..model.agents.len()).collect(),
        _ => {
            eprintln!("error: give exactly one of --agent ID and --all");
            return exit_code::USAGE;
        }
    };
    if let Some(vehicle) = args.vehicle {
        if let Err(e) = vehicle.check(&model, &indices) {
            eprintln!("error: {e}");
            return exit_code::USAGE;
        }
    }
    let mut exported = Vec::with_capacity(indices.len());
    for i in indices {
        match export_agent(&model, i) {
            Ok(e) => exported.push(e),
            Err(e) => {
                eprintln!("error: {e}");
                return exit_code::USAGE;
            }
        }
    }
    let written = if args.all {
        match &args.out {
            Some(dir) => write_all(dir, &exported, &model.source),
            None => Err(ExportError::NoDirectory),
        }
    } else {
        write_one(args, &exported, &model.source)
    };
    if let Err(e) = written {
        eprintln!("error: {e}");
        return exit_code::IO;
    }
    if !quiet {
        for e in &exported {
            eprintln!(
                "agent {} (wire id {}) of {}: {}-byte blob (format {}), {} triangles",
                e.name,
                e.id,
                model.source,
                e.blob.len(),
                ph_formation_ffi::blob::BLOB_VERSION,
                e.triangles,
            );
        }
        if let Some(out) = &args.out {
            eprintln!("-> {}", out.display());
        }
    }
    exit_code::CONVERGED
}

/// Agent `i`'s blob, checked by the C API's encoder.
pub(super) fn export_agent(model: &Model, i: usize) -> Result<Exported, ExportError> {
    let name = model
        .agents
        .get(i)
        .map(|a| a.name.clone())
        .unwrap_or_default();
    let config = model
        .agent_config_f32::<PH_MAX_TRIANGLES>(i)
        .map_err(|source| ExportError::Config {
            agent: name.clone(),
            source,
        })?;
    let mut buf = [0u8; PH_MAX_BLOB_LEN];
    let policy = blob_policy(model, i);
    let n = encode_blob_with(&config, policy.as_ref(), &mut buf).map_err(|error| {
        ExportError::Blob {
            agent: name.clone(),
            error,
        }
    })?;
    Ok(Exported {
        name,
        id: config.id,
        triangles: config.triangles.len(),
        blob: buf[..n].to_vec(),
    })
}

/// The scenario's `[policy]` for agent `i`'s blob, with its initial position as the
/// pre-flight reference (`None` without `[policy]`).
fn blob_policy(model: &Model, i: usize) -> Option<BlobPolicy> {
    let p = model.policy.as_ref()?;
    let start = model.agents.get(i).map_or([0.0; 2], |a| a.position);
    let f = |x: [f64; 2]| x.map(|v| v as f32);
    Some(BlobPolicy {
        hold_timeout_ms: p.hold_timeout_ms,
        fence: p.fence.then(|| (f(p.fence_min), f(p.fence_max))),
        battery_land: p.battery_land as f32,
        battery_ms: p.battery_ms,
        min_separation: p.min_separation as f32,
        start: f(start),
        start_tolerance: model.start_tolerance as f32,
    })
}

/// `--agent ID`: the blob (or with `--c-array` its C source) to `-o FILE` or stdout.
fn write_one(args: &ExportArgs, exported: &[Exported], source: &str) -> Result<(), ExportError> {
    let Some(e) = exported.first() else {
        return Ok(());
    };
    let bytes = if args.c_array {
        c_source(&e.blob, &e.name, source).into_bytes()
    } else {
        e.blob.clone()
    };
    match &args.out {
        Some(path) => std::fs::write(path, &bytes).map_err(|source| ExportError::Write {
            path: path.clone(),
            source,
        }),
        None => std::io::stdout()
            .write_all(&bytes)
            .map_err(ExportError::Stdout),
    }
}

/// `--all -o DIR`: `agent<ID>.blob` per agent, `ph_blobs.c` and `ph_blobs.h`.
fn write_all(dir: &Path, exported: &[Exported], source: &str) -> Result<(), ExportError> {
    std::fs::create_dir_all(dir).map_err(|source| ExportError::CreateDir {
        path: dir.to_path_buf(),
        source,
    })?;
    let write = |name: &str, bytes: &[u8]| {
        let path = dir.join(name);
        std::fs::write(&path, bytes).map_err(|source| ExportError::Write { path, source })
    };
    for e in exported {
        write(&format!("agent{}.blob", e.name), &e.blob)?;
    }
    write("ph_blobs.h", BLOBS_HEADER.as_bytes())?;
    write("ph_blobs.c", table_source(exported, source).as_bytes())
}

/// The declarations of `ph_blobs.c` (the same for every export).
const BLOBS_HEADER: &str = "\
/* Every agent's configuration blob, indexed by wire id: ph_blobs[id] (NULL if the
   scenario has no agent id) is ph_blob_lens[id] bytes for ph_agent_init_blob().
   Written by `host-sim export --all` with ph_blobs.c; see docs/crazyflie.md. */
#pragma once

#include <stddef.h>
#include <stdint.h>

extern const uint8_t *const ph_blobs[];
extern const size_t ph_blob_lens[];
/* Entries of ph_blobs and ph_blob_lens (the largest id + 1). */
extern const size_t ph_blob_count;
";

/// `ph_blobs.c`: one array per agent and the tables indexed by wire id.
fn table_source(exported: &[Exported], source: &str) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "/* Configuration blobs of every agent of {source}, written by\n   \
         `host-sim export --all`. Do not edit: re-export (docs/crazyflie.md). */\n\
         #include \"ph_blobs.h\"\n"
    );
    let count = exported
        .iter()
        .map(|e| usize::from(e.id) + 1)
        .max()
        .unwrap_or(0);
    let mut by_id = vec![None; count];
    for e in exported {
        let _ = writeln!(s, "/* agent {} (wire id {}) */", e.name, e.id);
        let _ = writeln!(
            s,
            "static const uint8_t blob_{}[{}] = {{",
            e.id,
            e.blob.len()
        );
        hex_lines(&mut s, &e.blob);
        let _ = writeln!(s, "}};\n");
        if let Some(slot) = by_id.get_mut(usize::from(e.id)) {
            *slot = Some(e);
        }
    }
    let _ = writeln!(s, "const uint8_t *const ph_blobs[{}] = {{", count.max(1));
    for (id, e) in by_id.iter().enumerate() {
        match e {
            Some(_) => {
                let _ = writeln!(s, "    blob_{id},");
            }
            None => {
                let _ = writeln!(s, "    NULL,");
            }
        }
    }
    let _ = writeln!(s, "}};\nconst size_t ph_blob_lens[{}] = {{", count.max(1));
    for e in &by_id {
        let _ = writeln!(s, "    {},", e.map_or(0, |e| e.blob.len()));
    }
    let _ = writeln!(s, "}};\nconst size_t ph_blob_count = {count};");
    s
}

fn hex_lines(s: &mut String, blob: &[u8]) {
    for line in blob.chunks(12) {
        let hex: Vec<String> = line.iter().map(|b| format!("0x{b:02x}")).collect();
        let _ = writeln!(s, "    {},", hex.join(", "));
    }
}

/// The blob as a C source file: `const uint8_t ph_blob[]` and its length, to compile
/// into firmware that passes it to `ph_agent_init_blob`.
fn c_source(blob: &[u8], agent: &str, source: &str) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "/* Configuration blob of agent {agent} of {source}, written by `host-sim export`.\n   \
         Pass it to ph_agent_init_blob(); see docs/c-api.md. Do not edit: re-export. */"
    );
    let _ = writeln!(s, "#include <stddef.h>\n#include <stdint.h>\n");
    let _ = writeln!(s, "const uint8_t ph_blob[{}] = {{", blob.len());
    hex_lines(&mut s, blob);
    let _ = writeln!(s, "}};\nconst size_t ph_blob_len = sizeof ph_blob;");
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_is_indexed_by_wire_id() {
        let e = |id: u8, len: usize| Exported {
            name: id.to_string(),
            id,
            triangles: 1,
            blob: vec![0xab; len],
        };
        let s = table_source(&[e(1, 3), e(3, 14)], "x.toml");
        assert!(s.contains("static const uint8_t blob_3[14] = {"), "{s}");
        assert!(
            s.contains("const uint8_t *const ph_blobs[4] = {\n    NULL,\n    blob_1,\n    NULL,\n    blob_3,\n};"),
            "{s}"
        );
        assert!(
            s.contains("const size_t ph_blob_lens[4] = {\n    0,\n    3,\n    0,\n    14,\n};"),
            "{s}"
        );
        assert!(s.contains("const size_t ph_blob_count = 4;"), "{s}");
    }
}

//! `host-sim export --agent ID SCENARIO`: one agent's configuration as the C API's
//! checked configuration blob (`controller-ffi`, docs/c-api.md "Configuration"), so
//! that a formation designed and simulated on the laptop is flashed without retyping
//! numbers. The blob is the scenario's configuration of that agent rounded to `f32`
//! ([`crate::model::Model::agent_config_f32`]), checked by the core as the firmware
//! will (`Agent::new` with the C API's capacities), versioned and CRC-32 checksummed.

use super::ExportArgs;
use crate::exit_code;
use controller_ffi::blob::{encode_blob, PH_MAX_BLOB_LEN};
use controller_ffi::PH_MAX_TRIANGLES;
use std::fmt::Write as _;
use std::io::Write as _;

/// Runs `host-sim export`; returns the exit code.
pub(super) fn export_command(args: &ExportArgs, quiet: bool) -> u8 {
    let model = match crate::api::load(&args.scenario, &args.set) {
        Ok(m) => m,
        Err(e) => return super::report(&e),
    };
    let Some(i) = model.agents.iter().position(|a| a.name == args.agent) else {
        let ids: Vec<&str> = model.agents.iter().map(|a| a.name.as_str()).collect();
        eprintln!(
            "error: --agent {}: scenario {} has no agent with that id (its agents: {})",
            args.agent,
            model.source,
            ids.join(", ")
        );
        return exit_code::USAGE;
    };
    let config = match model.agent_config_f32::<PH_MAX_TRIANGLES>(i) {
        Ok(c) => c,
        Err(reason) => {
            eprintln!("error: --agent {}: {reason}", args.agent);
            return exit_code::USAGE;
        }
    };
    let mut buf = [0u8; PH_MAX_BLOB_LEN];
    let n = match encode_blob(&config, &mut buf) {
        Ok(n) => n,
        Err(e) => {
            eprintln!(
                "error: --agent {}: the C API refuses this agent's configuration: {e:?}",
                args.agent
            );
            return exit_code::USAGE;
        }
    };
    let blob = &buf[..n];
    let bytes = if args.c_array {
        c_source(blob, &args.agent, &model.source).into_bytes()
    } else {
        blob.to_vec()
    };
    let written = match &args.out {
        Some(path) => std::fs::write(path, &bytes)
            .map_err(|e| format!("cannot write {}: {e}", path.display())),
        None => std::io::stdout()
            .write_all(&bytes)
            .map_err(|e| format!("cannot write to stdout: {e}")),
    };
    if let Err(e) = written {
        eprintln!("error: {e}");
        return exit_code::IO;
    }
    if !quiet {
        eprintln!(
            "agent {} (wire id {}) of {}: {n}-byte blob (format {}), {} triangles{}",
            args.agent,
            config.id,
            model.source,
            controller_ffi::blob::BLOB_VERSION,
            config.triangles.len(),
            args.out
                .as_ref()
                .map(|p| format!(" -> {}", p.display()))
                .unwrap_or_default()
        );
    }
    exit_code::CONVERGED
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
    for line in blob.chunks(12) {
        let hex: Vec<String> = line.iter().map(|b| format!("0x{b:02x}")).collect();
        let _ = writeln!(s, "    {},", hex.join(", "));
    }
    let _ = writeln!(s, "}};\nconst size_t ph_blob_len = sizeof ph_blob;");
    s
}

//! `host-sim`: the ph-formation simulator's command line (see `ph_formation_sim::cli`).
fn main() -> std::process::ExitCode {
    std::process::ExitCode::from(ph_formation_sim::cli::main())
}

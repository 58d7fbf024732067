//! `host-sim`: the ph-formation simulator's command line (see `host_sim::cli`).
fn main() -> std::process::ExitCode {
    std::process::ExitCode::from(host_sim::cli::main())
}

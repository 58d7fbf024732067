#!/usr/bin/env bash
# Runs every test of ph-formation on a fresh Debian machine with rustup.
# Installs what it needs first (rustup target and components, qemu-system-arm,
# defmt-print, the QEMU instruction-counting plugin). Idempotent.
set -euo pipefail
cd "$(dirname "$0")/.."

step() { printf '\n==> %s\n' "$*"; }

step "toolchain (rust-toolchain.toml) and firmware dependencies"
rustup show active-toolchain >/dev/null
rustup target add thumbv7em-none-eabihf >/dev/null
rustup component add rustfmt clippy llvm-tools >/dev/null
bash scripts/firmware-deps.sh

step "format"
cargo fmt --all --check

step "clippy (host, all targets)"
cargo clippy --workspace --all-targets -- -D warnings

step "clippy and release builds for thumbv7em-none-eabihf (controller-core with and without defmt, firmware)"
cargo clippy -p controller-core --target thumbv7em-none-eabihf -- -D warnings
cargo clippy -p controller-core --target thumbv7em-none-eabihf --features defmt -- -D warnings
cargo build -p controller-core --target thumbv7em-none-eabihf --release
cargo build -p controller-core --target thumbv7em-none-eabihf --release --features defmt
cargo clippy -p firmware-example --target thumbv7em-none-eabihf --release --all-targets -- -D warnings

step "host tests (controller-core, host-sim, cross-crate tests)"
cargo test

step "firmware under QEMU: sizes, instructions per step, stack, no soft f64, demo, UART session"
bash scripts/firmware-check.sh

step "QEMU tests: demo vs host-sim, UART link, host-in-the-loop runs"
cargo build -p firmware-example --target thumbv7em-none-eabihf --release --bins
cargo test -p ph-formation-tests --test qemu_demo --test qemu_uart -- --include-ignored
cargo test -p host-sim --test hil -- --include-ignored

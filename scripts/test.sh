#!/usr/bin/env bash
# Runs every test of ph-formation on a fresh Debian machine with rustup.
# Installs what it needs first (rustup target and components, qemu-system-arm,
# defmt-print, the QEMU instruction-counting plugin, Chromium, valgrind, a Python venv
# with PyPI's mcap and cflib; idempotent), then runs
# every check with `cargo xtask test` (xtask/src/test_cmd.rs), which ends with
# the duration of each phase.
set -euo pipefail
cd "$(dirname "$0")/.."

XTASK_TEST_STARTED=$(date +%s.%N)
export XTASK_TEST_STARTED

printf '\n==> %s\n' "toolchain (rust-toolchain.toml) and firmware dependencies"
rustup show active-toolchain >/dev/null
rustup target add thumbv7em-none-eabihf >/dev/null
rustup component add rustfmt clippy llvm-tools >/dev/null
bash scripts/firmware-deps.sh
bash scripts/browser-deps.sh
bash scripts/bench-deps.sh    # valgrind, for cargo xtask bench-counts
bash scripts/python-deps.sh   # target/py-venv: PyPI mcap (tests/mcap.rs), cflib (tests/serve.rs)

XTASK_TEST_INSTALLED=$(date +%s.%N)
export XTASK_TEST_INSTALLED
exec cargo xtask test "$@"

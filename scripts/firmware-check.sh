#!/usr/bin/env bash
# Moved to Rust: `cargo xtask firmware-check` (xtask/src/firmware_check/).
exec cargo xtask firmware-check "$@"

#!/usr/bin/env bash
# Install what `cargo xtask bench-counts` needs (valgrind's callgrind), on a fresh Debian
# machine, as root (or with sudo). Idempotent: nothing happens when valgrind is there.
set -euo pipefail
if command -v valgrind >/dev/null 2>&1; then
    exit 0
fi
sudo=()
if ((EUID != 0)); then
    if command -v sudo >/dev/null 2>&1; then
        sudo=(sudo)
    else
        echo "bench-deps: need root to apt-get install valgrind" >&2
        exit 1
    fi
fi
echo "bench-deps: apt-get install valgrind"
"${sudo[@]}" apt-get update -qq
DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -qq valgrind >/dev/null

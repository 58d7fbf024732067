#!/usr/bin/env bash
# Install what the replay viewer's browser test needs (host-sim/tests/replay_browser.rs),
# on a fresh Debian machine, as root. Idempotent: nothing is done when a Chromium is
# already there.
#
#   chromium               apt (Debian bookworm): headless Chromium, driven from the test
#                          by its command line (--headless --dump-dom / --screenshot)
set -euo pipefail

log() { echo "browser-deps: $*"; }

if command -v chromium >/dev/null 2>&1; then
    log "chromium present ($(chromium --version 2>/dev/null || echo 'version unknown'))"
    exit 0
fi

if ((EUID != 0)); then
    if command -v sudo >/dev/null 2>&1; then
        sudo=(sudo)
    else
        echo "browser-deps: need root to apt-get install chromium" >&2
        exit 1
    fi
else
    sudo=()
fi
log "apt-get install chromium"
"${sudo[@]}" apt-get -o DPkg::Lock::Timeout=600 update -qq
DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get -o DPkg::Lock::Timeout=600 install -y -qq --no-install-recommends chromium >/dev/null
log "chromium installed ($(chromium --version 2>/dev/null || echo 'version unknown'))"

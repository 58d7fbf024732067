#!/usr/bin/env bash
# Install what the end-to-end test of `host-sim serve` needs (crazyflie-app/tools/
# serve_e2e.py; docs/crazyflie.md "Simulated Crazyflies over udp://"): Bitcraze's
# client library cflib from PyPI, pinned, in a virtual environment under the target
# directory (Debian's python3 is externally managed: no system-wide pip), on a fresh
# Debian machine. Idempotent: nothing is done when the environment imports cflib.
#
#   python3, python3-venv  apt (Debian bookworm), only when missing
#   cflib==0.1.34          pip, into ${CARGO_TARGET_DIR:-target}/cflib-venv
#
# Prints nothing else; the environment's python is
# ${CARGO_TARGET_DIR:-target}/cflib-venv/bin/python.
set -euo pipefail
cd "$(dirname "$0")/.."

log() { echo "cflib-deps: $*"; }
CFLIB_VERSION=0.1.34
venv=${CARGO_TARGET_DIR:-target}/cflib-venv

if [[ -x $venv/bin/python ]] && "$venv/bin/python" -c "import cflib.crtp" 2>/dev/null; then
    log "cflib present in $venv"
    exit 0
fi

if ! python3 -c "import venv, ensurepip" 2>/dev/null; then
    if ((EUID != 0)); then
        if command -v sudo >/dev/null 2>&1; then
            sudo=(sudo)
        else
            echo "cflib-deps: need root to apt-get install python3-venv" >&2
            exit 1
        fi
    else
        sudo=()
    fi
    log "apt-get install python3 python3-venv"
    "${sudo[@]}" apt-get -o DPkg::Lock::Timeout=600 update -qq
    DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get -o DPkg::Lock::Timeout=600 install -y -qq --no-install-recommends python3 python3-venv >/dev/null
fi

log "python3 -m venv $venv; pip install cflib==$CFLIB_VERSION"
rm -rf "$venv"
python3 -m venv "$venv"
"$venv/bin/python" -m pip install -q --disable-pip-version-check "cflib==$CFLIB_VERSION"
"$venv/bin/python" -c "import cflib.crtp"
log "cflib $CFLIB_VERSION installed in $venv"

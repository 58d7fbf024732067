#!/usr/bin/env bash
# Install what the Python checks of the test command need, on a fresh Debian machine, as
# root (or with sudo): a virtual environment at target/py-venv with the PyPI packages
# below (a venv, because Debian's Python refuses `pip install` outside one, PEP 668).
# Idempotent: nothing is installed when the venv already has them.
#
#   mcap==1.6.0   Foxglove's MCAP reader, the independent reader of run.mcap
#                 (host-sim/tests/mcap_check.py, run by host-sim/tests/mcap.rs)
#   cflib==0.1.34 Bitcraze's client library, flying `host-sim serve`'s drones
#                 (crazyflie-app/tools/{serve_e2e,swarm}.py, run by host-sim/tests/serve.rs)
set -euo pipefail
cd "$(dirname "$0")/.."
venv=target/py-venv
packages=(mcap==1.6.0 cflib==0.1.34)

log() { echo "python-deps: $*"; }

if [ -x "$venv/bin/python" ] && "$venv/bin/python" -c 'import mcap, cflib.crtp' 2>/dev/null; then
    log "$venv has ${packages[*]}"
    exit 0
fi
if ! python3 -c 'import venv, ensurepip' 2>/dev/null; then
    sudo=()
    if ((EUID != 0)); then
        if command -v sudo >/dev/null 2>&1; then
            sudo=(sudo)
        else
            echo "python-deps: need root to apt-get install python3-venv" >&2
            exit 1
        fi
    fi
    log "apt-get install python3 python3-venv"
    "${sudo[@]}" apt-get -o DPkg::Lock::Timeout=600 update -qq
    DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get -o DPkg::Lock::Timeout=600 \
        install -y -qq --no-install-recommends python3 python3-venv >/dev/null
fi
rm -rf "$venv"
python3 -m venv "$venv"
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check "${packages[@]}"
log "installed ${packages[*]} in $venv"

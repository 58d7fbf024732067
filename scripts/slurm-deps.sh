#!/usr/bin/env bash
# Install what `cargo xtask cluster-test` needs, on a fresh Debian machine, as root:
#
#   slurm-wlm   apt: slurmctld, slurmd and the client commands (sbatch, squeue, sacct,
#               scancel); Debian bookworm: Slurm 22.05
#   munge       apt: the authentication daemon Slurm's daemons and commands talk through
#
# Idempotent: nothing is installed when slurmctld, slurmd, sbatch and munged are there.
# Then: cargo xtask cluster-test
set -euo pipefail

log() { echo "slurm-deps: $*"; }

missing=()
for cmd in slurmctld slurmd sbatch squeue scancel sacct munged; do
    command -v "$cmd" >/dev/null 2>&1 || PATH="$PATH:/usr/sbin:/sbin" command -v "$cmd" >/dev/null 2>&1 \
        || missing+=("$cmd")
done
if ((${#missing[@]} == 0)); then
    log "slurm and munge already installed"
    exit 0
fi
log "missing: ${missing[*]}"
if ((EUID != 0)); then
    if command -v sudo >/dev/null 2>&1; then
        sudo=(sudo)
    else
        echo "slurm-deps: need root to apt-get install slurm-wlm munge" >&2
        exit 1
    fi
else
    sudo=()
fi
export DEBIAN_FRONTEND=noninteractive
apt_opts=(-o DPkg::Lock::Timeout=600 -y -q --no-install-recommends)
"${sudo[@]}" apt-get -o DPkg::Lock::Timeout=600 update -q
# No daemon is started by the packages here (no systemd); policy-rc.d keeps it so where
# an init system would.
"${sudo[@]}" apt-get "${apt_opts[@]}" install slurm-wlm munge
log "installed: $(PATH="$PATH:/usr/sbin" slurmctld -V)"

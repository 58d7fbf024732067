#!/usr/bin/env bash
# Install what the firmware checks need, on a fresh Debian machine, as root.
# Idempotent: each step is skipped when its result is already there.
#
#   qemu-system-arm        apt (Debian bookworm: QEMU 7.2; netduinoplus2 = STM32F405)
#   gcc, libc6-dev         apt, to build the TCG plugin tools/qemu-insn
#   gcc-arm-none-eabi      apt, the C firmware and the Crazyflie app of controller-ffi
#                          (bare metal, no libc: newlib is not needed)
#   defmt-print 1.x        cargo install --locked (only if missing / not 1.x)
#   thumbv7em-none-eabihf, llvm-tools
#                          rustup (no-ops when rust-toolchain.toml already
#                          brought them)
#   tools/qemu-insn        built for the installed QEMU
#
# Then: cargo xtask firmware-check
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"

log() { echo "firmware-deps: $*"; }

# ------------------------------------------------------------------ apt
need_apt=()
command -v qemu-system-arm >/dev/null 2>&1 || need_apt+=(qemu-system-arm)
command -v gcc >/dev/null 2>&1 || need_apt+=(gcc)
[[ -e /usr/include/stdio.h ]] || need_apt+=(libc6-dev)
command -v arm-none-eabi-gcc >/dev/null 2>&1 || need_apt+=(gcc-arm-none-eabi)
command -v timeout >/dev/null 2>&1 || need_apt+=(coreutils)

if ((${#need_apt[@]} > 0)); then
    if ((EUID != 0)); then
        if command -v sudo >/dev/null 2>&1; then
            sudo=(sudo)
        else
            echo "firmware-deps: need root to apt-get install ${need_apt[*]}" >&2
            exit 1
        fi
    else
        sudo=()
    fi
    # Installing Debian's qemu-system-arm can remove a qemu-utils of another
    # QEMU version (e.g. from backports); put a matching one back if so.
    had_qemu_utils=0
    if dpkg-query -W -f='${Status}' qemu-utils 2>/dev/null | grep -q 'install ok installed'; then
        had_qemu_utils=1
    fi
    log "apt-get install ${need_apt[*]}"
    "${sudo[@]}" apt-get update -qq
    DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${need_apt[@]}"
    if ((had_qemu_utils)) && ! dpkg-query -W -f='${Status}' qemu-utils 2>/dev/null | grep -q 'install ok installed'; then
        log "reinstalling qemu-utils (removed by the qemu-system-arm install)"
        DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -qq --no-install-recommends qemu-utils
    fi
else
    log "qemu-system-arm, gcc, arm-none-eabi-gcc: present"
fi
log "$(qemu-system-arm --version | head -n1)"
log "$(arm-none-eabi-gcc --version | head -n1)"

# ----------------------------------------------------------------- rust
if ! command -v cargo >/dev/null 2>&1 && [[ -f $HOME/.cargo/env ]]; then
    # shellcheck disable=SC1091
    . "$HOME/.cargo/env"
fi
command -v rustup >/dev/null 2>&1 || { echo "firmware-deps: rustup not found (install Rust with rustup first)" >&2; exit 1; }

# Run inside the repository so the toolchain pinned by rust-toolchain.toml
# is the one that gets the target and component.
if ! rustup target list --installed | grep -qx thumbv7em-none-eabihf; then
    log "rustup target add thumbv7em-none-eabihf"
    rustup target add thumbv7em-none-eabihf
fi
host=$(rustc -vV | sed -n 's/^host: //p')
if [[ ! -x $(rustc --print sysroot)/lib/rustlib/$host/bin/llvm-size ]]; then
    log "rustup component add llvm-tools"
    rustup component add llvm-tools
fi

if defmt-print -V 2>/dev/null | head -n1 | grep -q '^defmt-print 1\.'; then
    log "$(defmt-print -V | head -n1): present"
else
    # --force: reached only when the binary is missing or not 1.x, which
    # cargo's own "already installed" check does not notice.
    log "cargo install --locked defmt-print (about a minute)"
    cargo install --locked --force defmt-print --version '^1'
fi

# --------------------------------------------------------------- plugin
plugin=$(tools/qemu-insn/build.sh)
log "plugin: $plugin"
log "done; run: cargo xtask firmware-check"

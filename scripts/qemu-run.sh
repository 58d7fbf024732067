#!/usr/bin/env bash
# Run a thumbv7em firmware ELF on QEMU's netduinoplus2 (an STM32F405) and
# decode its defmt output. Used as the cargo runner for
# thumbv7em-none-eabihf (.cargo/config.toml), so
#
#   cargo run -p firmware-example --target thumbv7em-none-eabihf --release
#
# ends up here as `scripts/qemu-run.sh <elf> [args…]`. Extra arguments are
# passed to QEMU (e.g. `-plugin …`).
#
# Exit code: QEMU's, i.e. the firmware's semihosting exit code (0 = success;
# the panic/HardFault handlers exit with 1). 124 means the run timed out. If
# QEMU succeeded but defmt-print failed, defmt-print's code.
#
# Environment:
#   QEMU_TIMEOUT      seconds before QEMU is killed (default 60)
#   QEMU_SYSTEM_ARM   QEMU binary (default qemu-system-arm)
#   DEFMT_PRINT       defmt-print binary (default defmt-print)
#   QEMU_RAW_OUT      if set, also save QEMU's raw (defmt-encoded) stdout there
#   QEMU_SERIAL       backend of USART1 (QEMU's serial0), default `null`; e.g.
#                     tcp:127.0.0.1:4444,server=on,wait=on,nodelay=on for the
#                     qemu-uart firmware (stdout carries the defmt log, so the
#                     serial port must not be stdio)
set -euo pipefail

if [[ $# -lt 1 ]]; then
    echo "usage: $0 <firmware.elf> [extra qemu args…]" >&2
    exit 2
fi
elf=$1
shift

qemu=${QEMU_SYSTEM_ARM:-qemu-system-arm}
defmt_print=${DEFMT_PRINT:-defmt-print}
limit=${QEMU_TIMEOUT:-60}

for tool in "$qemu" "$defmt_print" timeout; do
    if ! command -v "$tool" >/dev/null 2>&1; then
        echo "qemu-run: '$tool' not found; run scripts/firmware-deps.sh (as root) first" >&2
        exit 127
    fi
done
if [[ ! -f $elf ]]; then
    echo "qemu-run: no such ELF: $elf" >&2
    exit 2
fi

# --foreground keeps QEMU in the terminal's process group (in a background
# group it could stop on SIGTTOU). -k: SIGKILL if SIGTERM did not end it.
# No display, no monitor, USART1 on $QEMU_SERIAL: stdout carries only the
# firmware's semihosting output (the defmt stream).
# shellcheck disable=SC2054 # the commas are inside QEMU option values
qemu_cmd=(timeout --foreground -k 5 "$limit"
    "$qemu" -machine netduinoplus2 -display none -monitor none
    -serial "${QEMU_SERIAL:-null}"
    -semihosting-config enable=on,target=native
    -kernel "$elf" "$@")

set +e
if [[ -n ${QEMU_RAW_OUT:-} ]]; then
    "${qemu_cmd[@]}" </dev/null | tee "$QEMU_RAW_OUT" | "$defmt_print" -e "$elf"
    status=("${PIPESTATUS[@]}")
    qemu_rc=${status[0]}
    print_rc=${status[2]}
else
    "${qemu_cmd[@]}" </dev/null | "$defmt_print" -e "$elf"
    status=("${PIPESTATUS[@]}")
    qemu_rc=${status[0]}
    print_rc=${status[1]}
fi
set -e

if [[ $qemu_rc -eq 124 || $qemu_rc -eq 137 ]]; then
    echo "qemu-run: QEMU did not exit within ${limit}s (killed); the firmware hung or never called exit" >&2
    exit 124
fi
if [[ $qemu_rc -ne 0 ]]; then
    echo "qemu-run: firmware exited with code $qemu_rc" >&2
    exit "$qemu_rc"
fi
if [[ $print_rc -ne 0 ]]; then
    echo "qemu-run: defmt-print failed with code $print_rc" >&2
    exit "$print_rc"
fi

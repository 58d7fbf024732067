#!/usr/bin/env bash
# Builds the C programs of controller-ffi against its staticlib (release).
#
#   controller-ffi/c/build.sh host OUT_DIR       OUT_DIR/c-host-demo (system cc)
#   controller-ffi/c/build.sh firmware OUT_DIR   OUT_DIR/c-firmware.elf (arm-none-eabi-gcc,
#                                                STM32F405 / QEMU netduinoplus2)
#   controller-ffi/c/build.sh cfapp-host OUT_DIR       OUT_DIR/cfapp-host: the Crazyflie
#                                                app's code (crazyflie-app/src, its blobs)
#                                                driving four simulated vehicles
#   controller-ffi/c/build.sh cfapp-firmware OUT_DIR   OUT_DIR/cfapp-firmware.elf: the
#                                                same on the STM32F405 (stack figures)
#   controller-ffi/c/build.sh cfapp-flight OUT_DIR     OUT_DIR/cfapp-flight: the app's
#                                                flight states and commands against a
#                                                model of the firmware's commander and
#                                                supervisor (crazyflie-app/test/flight_test.c)
#   controller-ffi/c/build.sh cfapp-agent OUT_DIR      OUT_DIR/cfapp-agent: one simulated
#                                                Crazyflie for `host-sim serve` (the app's
#                                                appMain against the firmware stand-ins of
#                                                crazyflie-app/test/serve_*.c, CRTP over UDP)
#   (CFAPP_CFLAGS: extra flags for the app, e.g. -DFORMATION_USE_STRUCT)
#
# The staticlib: for the firmware `cargo rustc -p ph-formation-ffi --release --lib
# --target thumbv7em-none-eabihf --crate-type staticlib` (the staticlib alone: cargo
# applies the release profile's fat LTO only when the crate is not also built as an
# rlib; 10 % less code, 5 % fewer instructions per tick); for the host a plain
# `cargo build -p ph-formation-ffi --release`. The release profile has panic = "abort".
# Prints the path of what it built. Used by controller-ffi/tests/c_host.rs and
# c_firmware.rs; see docs/c-api.md. Environment: CC (host compiler, default cc),
# ARM_CC (default arm-none-eabi-gcc), CARGO_TARGET_DIR.
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/../.." && pwd)
target_dir=${CARGO_TARGET_DIR:-$root/target}
cargo=${CARGO:-cargo}

if [[ $# -ne 2 ]]; then
    echo "usage: $0 host|firmware OUT_DIR" >&2
    exit 2
fi
what=$1
out=$2
mkdir -p "$out"

# Every test build has the simulated Crazyflie (`sim-vehicle`: ph_vehicle_*, which the
# app's tests fly); one feature set for all of them, so that no build overwrites the
# library another test is linking. The flight build (crazyflie-app/Kbuild) leaves it off.
features=(--features sim-vehicle)

# Warnings are errors; the C is C11 with GNU attributes (aligned, section).
cflags=(-std=gnu11 -O2 -g -Wall -Wextra -Werror -Wshadow -Wstrict-prototypes
    -fno-math-errno -DPH_SIM_VEHICLE -I"$root/controller-ffi/include" -I"$here/demo")
demo=("$here/demo/paper_demo.c" "$here/demo/print.c")
# The Crazyflie app's portable code against the firmware stub (crazyflie-app/test).
app=$root/crazyflie-app
read -r -a app_flags <<<"${CFAPP_CFLAGS:-}"
app_cflags=(-I"$app/src" -I"$app/src/blobs" -I"$app/stub" -I"$app/test" "${app_flags[@]}")
app_src=("$app/src/agent_loop.c" "$app/src/formation.c" "$app/src/blobs/ph_blobs.c"
    "$app/test/swarm.c" "$here/demo/print.c")
arm_flags=(-mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard
    -ffreestanding -ffunction-sections -fdata-sections -nostdlib
    -T "$here/firmware/stm32f405.ld" -Wl,--gc-sections -Wl,-z,noexecstack)

case $what in
host)
    (cd "$root" && "$cargo" build -q -p ph-formation-ffi --release --lib "${features[@]}")
    lib=$target_dir/release/libph_formation_ffi.a
    # The host staticlib contains std: link what it needs (rustc
    # --print native-static-libs on linux-gnu: gcc_s, util, rt, pthread, m, dl, c).
    "${CC:-cc}" "${cflags[@]}" -o "$out/c-host-demo" \
        "$here/host/main.c" "$here/host/checks.c" "${demo[@]}" \
        "$lib" -lgcc_s -lutil -lrt -lpthread -lm -ldl
    echo "$out/c-host-demo"
    ;;
firmware)
    (cd "$root" && "$cargo" rustc -q -p ph-formation-ffi --release --lib "${features[@]}" \
        --target thumbv7em-none-eabihf --crate-type staticlib)
    lib=$target_dir/thumbv7em-none-eabihf/release/libph_formation_ffi.a
    # Hard-float ABI of thumbv7em-none-eabihf; no libc (the staticlib's
    # compiler_builtins provides memcpy/memset), libgcc for any helper.
    "${ARM_CC:-arm-none-eabi-gcc}" "${cflags[@]}" \
        -mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard \
        -ffreestanding -ffunction-sections -fdata-sections -nostdlib \
        -T "$here/firmware/stm32f405.ld" -Wl,--gc-sections -Wl,-z,noexecstack -Wl,-Map="$out/c-firmware.map" \
        -o "$out/c-firmware.elf" \
        "$here/firmware/startup.c" "$here/firmware/main.c" "${demo[@]}" \
        "$lib" -lgcc
    echo "$out/c-firmware.elf"
    ;;
cfapp-host)
    (cd "$root" && "$cargo" build -q -p ph-formation-ffi --release --lib "${features[@]}")
    lib=$target_dir/release/libph_formation_ffi.a
    "${CC:-cc}" "${cflags[@]}" "${app_cflags[@]}" -o "$out/cfapp-host" \
        "$app/test/host_main.c" "${app_src[@]}" \
        "$lib" -lgcc_s -lutil -lrt -lpthread -lm -ldl
    echo "$out/cfapp-host"
    ;;
cfapp-firmware)
    (cd "$root" && "$cargo" rustc -q -p ph-formation-ffi --release --lib "${features[@]}" \
        --target thumbv7em-none-eabihf --crate-type staticlib)
    lib=$target_dir/thumbv7em-none-eabihf/release/libph_formation_ffi.a
    "${ARM_CC:-arm-none-eabi-gcc}" "${cflags[@]}" "${app_cflags[@]}" -I"$here/firmware" \
        "${arm_flags[@]}" -Wl,-Map="$out/cfapp-firmware.map" -o "$out/cfapp-firmware.elf" \
        "$here/firmware/startup.c" "$app/test/qemu_main.c" "${app_src[@]}" \
        "$lib" -lgcc
    echo "$out/cfapp-firmware.elf"
    ;;
cfapp-flight)
    (cd "$root" && "$cargo" build -q -p ph-formation-ffi --release --lib "${features[@]}")
    lib=$target_dir/release/libph_formation_ffi.a
    "${CC:-cc}" "${cflags[@]}" "${app_cflags[@]}" -o "$out/cfapp-flight" \
        "$app/test/flight_test.c" "$app/test/firmware_model.c" "$app/src/flight.c" \
        "$app/src/commands.c" "$app/src/epoch.c" "$app/src/formation.c" \
        "$app/src/blobs/ph_blobs.c" \
        "$lib" -lgcc_s -lutil -lrt -lpthread -lm -ldl
    echo "$out/cfapp-flight"
    ;;
cfapp-agent)
    (cd "$root" && "$cargo" build -q -p ph-formation-ffi --release --lib "${features[@]}")
    lib=$target_dir/release/libph_formation_ffi.a
    # serve_sections.ld: the PARAM_GROUP/LOG_GROUP tables, as the firmware links them.
    "${CC:-cc}" "${cflags[@]}" "${app_cflags[@]}" -o "$out/cfapp-agent" \
        "$app/test/serve_agent.c" "$app/test/serve_crtp.c" "$app/src/app.c" \
        "$app/src/agent_loop.c" "$app/src/formation.c" "$app/src/flight.c" \
        "$app/src/commands.c" "$app/src/epoch.c" "$app/src/blobs/ph_blobs.c" \
        -Wl,-T,"$app/test/serve_sections.ld" \
        "$lib" -lgcc_s -lutil -lrt -lpthread -lm -ldl
    echo "$out/cfapp-agent"
    ;;
*)
    echo "$0: unknown target '$what' (host, firmware, cfapp-host, cfapp-firmware, cfapp-flight or cfapp-agent)" >&2
    exit 2
    ;;
esac

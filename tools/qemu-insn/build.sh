#!/usr/bin/env bash
# Build the qemu-insn TCG plugin (libqemu-insn.so next to this script) for
# the installed qemu-system-arm. Needs gcc. Idempotent: rebuilds only when the
# sources, this script or the QEMU version changed.
#
#   tools/qemu-insn/build.sh          # prints the path of the plugin
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
qemu=${QEMU_SYSTEM_ARM:-qemu-system-arm}
cc=${CC:-gcc}
so="$here/libqemu-insn.so"
stamp="$here/.libqemu-insn.stamp"

command -v "$qemu" >/dev/null || { echo "build.sh: $qemu not found (scripts/firmware-deps.sh installs it)" >&2; exit 1; }
command -v "$cc" >/dev/null || { echo "build.sh: $cc not found (apt-get install gcc)" >&2; exit 1; }

# "QEMU emulator version 7.2.22 (Debian …)" -> 7
version=$("$qemu" --version | sed -n 's/^QEMU emulator version \([0-9][0-9]*\)\..*/\1/p' | head -n1)
if [[ -z $version ]]; then
    echo "build.sh: cannot parse the version of $qemu" >&2
    exit 1
fi
# Plugin API version to declare: QEMU <= 8.2 knows only version 1; QEMU 9.0
# introduced version 2 and later releases refuse anything below 2.
if ((version <= 8)); then api=1; else api=2; fi

key="qemu-major=$version api=$api $(cat "$here/qemu-insn.c" "$here/qemu-plugin-api.h" "$0" | cksum)"
if [[ -f $so && -f $stamp && $(cat "$stamp") == "$key" ]]; then
    echo "$so"
    exit 0
fi

"$cc" -std=gnu11 -O2 -Wall -Wextra -Werror -fPIC -shared -fvisibility=hidden \
    -DQEMU_INSN_API_VERSION="$api" -o "$so.tmp" "$here/qemu-insn.c"
mv "$so.tmp" "$so"
echo "$key" >"$stamp"
echo "built $so (QEMU $version, plugin API $api)" >&2
echo "$so"

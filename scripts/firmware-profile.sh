#!/usr/bin/env bash
# Where do the instructions of one measured control step go?
#
#   scripts/firmware-profile.sh [REGION] [TOP]
#
# REGION is a region name printed by the `measure` firmware (default tri2:
# the whole step of an agent in 2 triangles; also tri2-rx, tri2-step,
# tri2-tx, tri8, …). Runs `measure` under QEMU with the qemu-insn plugin's
# per-address profile of that region (counts over all its occurrences,
# divided by the number of occurrences), maps each address to its source with
# addr2line (binutils; inlining resolved) and prints the instructions per
# step by source file, by innermost function (after inlining), and by the
# outermost function of the inlining chain. Deterministic, like the checks.
#
# Needs what scripts/firmware-deps.sh installs. Output also in
# target/firmware-check/profile-<REGION>.txt.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
region=${1:-tri2}
top=${2:-25}
target=thumbv7em-none-eabihf
elf=$root/target/$target/release/measure
out=${FIRMWARE_CHECK_OUT:-$root/target/firmware-check}
mkdir -p "$out"
host=$(rustc -vV | sed -n 's/^host: //p')
llvm_bin=$(rustc --print sysroot)/lib/rustlib/$host/bin

cargo build -q -p firmware-example --target "$target" --release --bin measure
plugin=$(tools/qemu-insn/build.sh)
marker=$("$llvm_bin/llvm-nm" "$elf" | awk '$3 == "PH_INSN_MARKERS" { print "0x" $1 }')

# Pass 1: region names -> ids.
scripts/qemu-run.sh "$elf" >"$out/profile-measure.log" 2>&1
read -r id repeats < <(sed -n "s/.*FWCHECK region id=\([0-9]*\) name=$region triangles=[0-9]* repeats=\([0-9]*\).*/\1 \2/p" \
    "$out/profile-measure.log" | head -n1) || true
if [[ -z ${id:-} ]]; then
    echo "firmware-profile: no region named '$region'; regions:" >&2
    sed -n 's/.*FWCHECK region id=[0-9]* name=\([^ ]*\).*/  \1/p' "$out/profile-measure.log" >&2
    exit 2
fi

# Pass 2: the per-address profile of that region.
raw=$out/profile-$region.raw
scripts/qemu-run.sh "$elf" -plugin "$plugin,marker=$marker,out=$raw,profile=$id" >/dev/null 2>&1
total=$(awk -v id="$id" '$1 == "qemu-insn" && $2 == "region=" id { sub("insns=", "", $4); s += $4 } END { print s + 0 }' "$raw")

# Address -> inlining chain (innermost first), then aggregate.
sed -n 's/^qemu-insn profile pc=\(0x[0-9a-f]*\) insns=\([0-9]*\)$/\1 \2/p' "$raw" | sort >"$out/profile-$region.pcs"
awk '{ print $1 }' "$out/profile-$region.pcs" |
    "${ADDR2LINE:-addr2line}" -e "$elf" -a -f -i -C >"$out/profile-$region.lines"

report=$out/profile-$region.txt
awk -v reps="$repeats" -v total="$total" -v top="$top" -v region="$region" '
    FNR == NR { count[$1] = $2; next }
    /^0x/ { flush(); pc = $0; sub(/^0x0*/, "0x", pc); n = 0; next }
    { if (n % 2 == 0) fn[n / 2] = $0; else file[(n - 1) / 2] = $0; n++ }
    function src(f,    s) {
        s = f; sub(/:[0-9]+(:[0-9]+)?$/, "", s)
        if (s ~ /controller-core\/src\//) { sub(/.*controller-core\/src\//, "controller-core/", s); return s }
        if (s ~ /firmware-example\/src\//) { sub(/.*firmware-example\/src\//, "firmware-example/", s); return s }
        if (s ~ /\/library\//) { sub(/.*\/library\//, "std: ", s); sub(/\/src\/.*/, "", s); return s }
        if (s ~ /registry\/src\//) { sub(/.*registry\/src\/[^\/]*\//, "", s); sub(/\/.*/, "", s); return "crate " s }
        if (s ~ /compiler-builtins|compiler_builtins/) return "compiler_builtins"
        return s
    }
    function flush(   c, k, d) {
        if (pc == "") return
        c = count[pc] / reps
        if (n == 0) { byfile["?"] += c; byfn["?"] += c; byouter["?"] += c; return }
        d = int(n / 2)
        byfile[src(file[0])] += c
        byfn[fn[0]] += c
        byouter[fn[d - 1]] += c
        pc = ""
    }
    function table(title, arr,    k, line, cmd) {
        printf "\n%s\n", title
        cmd = "sort -t\"\t\" -k1,1 -n -r | head -n " top
        for (k in arr) printf "%d\t%5.1f%%\t%s\n", arr[k] + 0.5, 100 * arr[k] / (total / reps), k | cmd
        close(cmd)
    }
    END {
        flush()
        printf "region %s: %d instructions per step (%d occurrences profiled)\n", region, total / reps, reps
        table("by source file (std/crates: by library)", byfile)
        table("by innermost function (after inlining)", byfn)
        table("by outermost function of the inlining chain", byouter)
    }
' <(awk '{ pc = $1; sub(/^0x0*/, "0x", pc); print pc, $2 }' "$out/profile-$region.pcs") "$out/profile-$region.lines" | tee "$report"

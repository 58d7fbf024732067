#!/usr/bin/env bash
# List the largest stack frames of a thumbv7em ELF (from the `sub sp, #N`
# and `sub.w sp, sp, #N` in function prologues; push/vpush not counted).
#
#   tools/stack-frames.sh target/thumbv7em-none-eabihf/release/measure [N]
set -euo pipefail
elf=${1:?usage: $0 <elf> [count]}
count=${2:-20}
host=$(rustc -vV | sed -n 's/^host: //p')
objdump=$(rustc --print sysroot)/lib/rustlib/$host/bin/llvm-objdump
"$objdump" -d --no-show-raw-insn --demangle "$elf" |
    awk '/^[0-9a-f]+ <.*>:$/ { fn = $0; sub(/^[0-9a-f]+ /, "", fn) }
         /sub(\.w)?[ \t]+sp, (sp, )?#0x[0-9a-f]+/ {
             match($0, /#0x[0-9a-f]+/); print substr($0, RSTART + 3, RLENGTH - 3), fn }' |
    while read -r hex fn; do printf '%8d  %s\n' "$((16#$hex))" "$fn"; done |
    sort -n -r | head -n "$count"

//! `cargo xtask stack-frames <elf> [N]`: the largest stack frames of a thumbv7em ELF,
//! from the `sub sp, #N` / `sub.w sp, sp, #N` of the function prologues (`push`/`vpush`
//! not counted), disassembled with the toolchain's `llvm-objdump`.

use crate::tools::{self, Llvm};
use std::path::Path;
use std::process::Command;

/// Prints the `count` largest frames of `elf`.
pub fn run(elf: &Path, count: usize) -> Result<(), String> {
    let objdump = Llvm::find()?.objdump;
    let asm = tools::output(
        Command::new(objdump)
            .args(["-d", "--no-show-raw-insn", "--demangle"])
            .arg(elf),
    )?;
    for (bytes, function) in frames(&asm).into_iter().take(count) {
        println!("{bytes:8}  {function}");
    }
    Ok(())
}

/// `(bytes, function)` of every stack adjustment in a disassembly, largest first.
fn frames(asm: &str) -> Vec<(u64, String)> {
    let mut function = String::new();
    let mut out = Vec::new();
    for line in asm.lines() {
        // `08000470 <name>:` starts a function.
        if let Some((addr, rest)) = line.split_once(' ') {
            if !addr.is_empty() && addr.chars().all(|c| c.is_ascii_hexdigit()) {
                if let Some(name) = rest.strip_suffix(':') {
                    function = name.to_owned();
                    continue;
                }
            }
        }
        // ` 8000478:      \tsub\tsp, #0x4`: address, mnemonic, operands.
        let Some((_, insn)) = line.split_once(':') else {
            continue;
        };
        let Some((op, operands)) = insn.trim().split_once(char::is_whitespace) else {
            continue;
        };
        let operands = operands.trim();
        if op != "sub" && op != "sub.w" {
            continue;
        }
        let imm = operands
            .strip_prefix("sp, sp, #0x")
            .or_else(|| operands.strip_prefix("sp, #0x"));
        if let Some(n) = imm.and_then(|h| u64::from_str_radix(h.trim(), 16).ok()) {
            out.push((n, function.clone()));
        }
    }
    out.sort_by(|a, b| b.0.cmp(&a.0).then_with(|| a.1.cmp(&b.1)));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_prologue_frames() {
        let asm = "08000470 <a::step>:\n 8000478:      \tsub\tsp, #0x4\n 800047e:      \tsub\tsp, #0x178\n\
                   08002220 <b::main>:\n 8002228:      \tsub.w\tsp, sp, #0x1680\n 800222c:      \tsub\tr0, #0x4\n";
        assert_eq!(
            frames(asm),
            [
                (0x1680, "<b::main>".to_owned()),
                (0x178, "<a::step>".to_owned()),
                (4, "<a::step>".to_owned())
            ]
        );
    }
}

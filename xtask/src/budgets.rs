//! `firmware-example/budgets.toml`: the resource budgets of the release firmware.

use qemu_harness::firmware::BUDGETED;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;

/// The budget file (see the comments in `firmware-example/budgets.toml`).
#[derive(Clone, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Budgets {
    /// Instructions of one whole control step, per step configuration.
    #[serde(default)]
    pub insn_step: BTreeMap<String, u64>,
    /// Instructions of `Agent::step` alone, per step configuration.
    #[serde(default)]
    pub insn_control_law: BTreeMap<String, u64>,
    /// Resource budgets of every budgeted binary.
    #[serde(default)]
    pub all_binaries: Resources,
    /// Resource budgets of one binary each, in addition to `all_binaries`.
    #[serde(default)]
    pub binary: BTreeMap<String, Resources>,
}

/// Resource budgets, in bytes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Resources {
    /// llvm-size `text`.
    pub text_bytes: Option<u64>,
    /// llvm-size `data`.
    pub data_bytes: Option<u64>,
    /// llvm-size `bss`.
    pub bss_bytes: Option<u64>,
    /// Peak stack use under QEMU.
    pub stack_bytes: Option<u64>,
    /// data + bss + peak stack.
    pub ram_plus_stack_bytes: Option<u64>,
}

/// One budgeted resource of a binary.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Resource {
    /// `text_bytes`.
    Text,
    /// `data_bytes`.
    Data,
    /// `bss_bytes`.
    Bss,
    /// `stack_bytes`.
    Stack,
    /// `ram_plus_stack_bytes`.
    RamPlusStack,
}

impl Resource {
    /// The key in the budget file.
    pub fn key(self) -> &'static str {
        match self {
            Resource::Text => "text_bytes",
            Resource::Data => "data_bytes",
            Resource::Bss => "bss_bytes",
            Resource::Stack => "stack_bytes",
            Resource::RamPlusStack => "ram_plus_stack_bytes",
        }
    }

    fn of(self, r: &Resources) -> Option<u64> {
        match self {
            Resource::Text => r.text_bytes,
            Resource::Data => r.data_bytes,
            Resource::Bss => r.bss_bytes,
            Resource::Stack => r.stack_bytes,
            Resource::RamPlusStack => r.ram_plus_stack_bytes,
        }
    }
}

/// A budget that applies: its key (as written in the file) and its limit.
pub type Limit = (String, u64);

impl Budgets {
    /// Parses the text of a budget file; `name` (the file) prefixes every error, which
    /// names the table or key and the reason.
    pub fn parse(text: &str, name: &str) -> Result<Self, String> {
        let b: Budgets = toml::from_str(text).map_err(|e| format!("{name}: {e}"))?;
        for bin in b.binary.keys() {
            if !BUDGETED.contains(&bin.as_str()) {
                return Err(format!(
                    "{name}: [binary.{bin}]: unknown binary '{bin}' (budgeted binaries: {})",
                    BUDGETED.join(", ")
                ));
            }
        }
        Ok(b)
    }

    /// Reads and parses a budget file.
    pub fn load(path: &Path) -> Result<Self, String> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
        Self::parse(&text, &path.display().to_string())
    }

    /// The budgets of `resource` that apply to binary `bin`: the generic one, then the
    /// binary's own.
    pub fn resource(&self, bin: &str, resource: Resource) -> Vec<Limit> {
        let key = resource.key();
        let mut out = Vec::new();
        if let Some(v) = resource.of(&self.all_binaries) {
            out.push((format!("all_binaries.{key}"), v));
        }
        if let Some(v) = self.binary.get(bin).and_then(|r| resource.of(r)) {
            out.push((format!("binary.{bin}.{key}"), v));
        }
        out
    }

    /// The whole-step budget of configuration `config`.
    pub fn step(&self, config: &str) -> Vec<Limit> {
        self.insn_step
            .get(config)
            .map(|&v| (format!("insn_step.{config}"), v))
            .into_iter()
            .collect()
    }

    /// The `Agent::step` budget of configuration `config`.
    pub fn control_law(&self, config: &str) -> Vec<Limit> {
        self.insn_control_law
            .get(config)
            .map(|&v| (format!("insn_control_law.{config}"), v))
            .into_iter()
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const FILE: &str = r#"
[insn_step]
tri2 = 4_210
[insn_control_law]
tri2 = 985
[all_binaries]
text_bytes = 65536
ram_plus_stack_bytes = 16384
[binary.qemu-uart]
text_bytes = 53200   # comment
"#;

    #[test]
    fn parses_tables_and_finds_the_budgets_that_apply() {
        let b = Budgets::parse(FILE, "b.toml").expect("parse");
        assert_eq!(b.step("tri2"), vec![("insn_step.tri2".to_owned(), 4210)]);
        assert_eq!(b.control_law("tri2")[0].1, 985);
        assert!(b.step("tri8").is_empty());
        assert_eq!(
            b.resource("qemu-uart", Resource::Text),
            vec![
                ("all_binaries.text_bytes".to_owned(), 65536),
                ("binary.qemu-uart.text_bytes".to_owned(), 53200)
            ]
        );
        assert_eq!(b.resource("measure", Resource::Text).len(), 1);
        assert!(b.resource("measure", Resource::Stack).is_empty());
    }

    #[test]
    fn unknown_keys_tables_and_binaries_are_errors_naming_them() {
        let e = Budgets::parse("[all_binaries]\ntext_byte = 1\n", "b.toml").expect_err("key");
        assert!(e.starts_with("b.toml") && e.contains("text_byte"), "{e}");
        let e = Budgets::parse("insn_step_tri2 = 1\n", "b.toml").expect_err("old flat key");
        assert!(e.contains("insn_step_tri2"), "{e}");
        let e = Budgets::parse("[binary.qemu-demo]\nstack = 1\n", "b.toml").expect_err("key");
        assert!(e.contains("stack"), "{e}");
        let e =
            Budgets::parse("[binary.qemu-dmeo]\nstack_bytes = 1\n", "b.toml").expect_err("binary");
        assert!(e.contains("[binary.qemu-dmeo]"), "{e}");
        let e = Budgets::parse("[insn_step]\ntri2 = -1\n", "b.toml").expect_err("negative");
        assert!(e.contains("tri2") || e.contains("line 2"), "{e}");
        let e = Budgets::parse("[insn_step]\ntri2 = \"x\"\n", "b.toml").expect_err("string");
        assert!(e.starts_with("b.toml"), "{e}");
    }

    #[test]
    fn the_repository_budget_file_parses() {
        let path = qemu_harness::firmware::workspace_root().join("firmware-example/budgets.toml");
        let b = Budgets::load(&path).expect("budgets.toml");
        assert!(!b.insn_step.is_empty() && !b.insn_control_law.is_empty());
        for bin in BUDGETED {
            assert!(!b.resource(bin, Resource::Text).is_empty(), "{bin}");
        }
    }
}

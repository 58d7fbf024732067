//! The layers of `host-sim/src` import one way only (`docs/architecture.md`), no source
//! file is too long to read in one sitting (a file of the engine, one stage, is shorter
//! still), and no two files of `host-sim/src/engine/` or of `controller-core/src/` import
//! each other, directly or around a loop (`layers/imports.rs`).
//!
//! Every file under `src/` belongs to the layer named by its first path component
//! (`src/engine/hil/qemu.rs` is in `engine`; `src/exit_code.rs` in `exit_code`); the
//! crate root (`lib.rs`, `main.rs`) is the facade and may name anything. Each file is
//! parsed with `syn`, and every path that starts with `crate::`, `super::` or `self::`
//! (in `use` items, in code, and in macro invocations) is resolved to the top-level
//! module it names. A layer may name itself and the layers [`LAYERS`] allows it;
//! anything else is a violation, reported with file, line and the rule.

#[path = "layers/imports.rs"]
mod imports;

use imports::module_path;
use proc_macro2::{TokenStream, TokenTree};
use std::path::{Path, PathBuf};
use syn::visit::Visit;

/// The layers, lowest first, and the lower layers each may import. `design` (a shape →
/// scenario generator, `host-sim design`) sits above `scenario`; `sweep` (Monte Carlo
/// sweeps) is a client of the API, below the command line.
const LAYERS: &[(&str, &[&str])] = &[
    ("exit_code", &[]),
    ("model", &["exit_code"]),
    ("scenario", &["exit_code", "model"]),
    ("design", &["exit_code", "model", "scenario"]),
    ("analysis", &["exit_code", "model"]),
    ("engine", &["exit_code", "model", "analysis"]),
    ("report", &["exit_code", "model", "analysis", "engine"]),
    (
        "api",
        &[
            "exit_code",
            "model",
            "scenario",
            "analysis",
            "engine",
            "report",
        ],
    ),
    (
        "sweep",
        &[
            "exit_code",
            "model",
            "scenario",
            "design",
            "analysis",
            "engine",
            "report",
            "api",
        ],
    ),
    (
        "cli",
        &[
            "exit_code",
            "model",
            "scenario",
            "design",
            "analysis",
            "engine",
            "report",
            "api",
            "sweep",
        ],
    ),
];

/// Hard limit on the length of a source file (lines).
const MAX_LINES: usize = 800;

/// Hard limit on the length of a file of the engine (`src/engine/`, lines): one stage of
/// the simulator per file.
const MAX_ENGINE_LINES: usize = 500;

/// One import that breaks the rules.
#[derive(Debug, PartialEq, Eq)]
struct Violation {
    file: String,
    line: usize,
    message: String,
}

fn allowed(from: &str) -> Option<&'static [&'static str]> {
    LAYERS.iter().find(|(l, _)| *l == from).map(|(_, a)| *a)
}

/// Walks one file: `module` is the module the code being visited is in.
struct Checker<'a> {
    file: &'a str,
    layer: &'a str,
    module: Vec<String>,
    found: Vec<Violation>,
}

impl Checker<'_> {
    /// Checks a path given as its leading segments (`crate`, `super`, names…).
    fn check(&mut self, segments: &[String], line: usize) {
        let mut abs = match segments.first().map(String::as_str) {
            Some("crate") => Vec::new(),
            Some("super") | Some("self") => self.module.clone(),
            _ => return, // another crate, a prelude name or a child module: same layer
        };
        let mut rest = segments.iter().skip(1);
        if segments[0] == "super" {
            abs.pop();
        }
        let mut next = rest.next();
        while let Some(s) = next {
            if s != "super" {
                break;
            }
            abs.pop();
            next = rest.next();
        }
        if abs.is_empty() {
            match next {
                Some(s) => abs.push(s.clone()),
                None => return,
            }
        }
        let target = abs[0].as_str();
        if target == self.layer {
            return;
        }
        let ok = allowed(self.layer).is_some_and(|a| a.contains(&target));
        if !ok {
            let rule = match allowed(target) {
                Some(_) => format!(
                    "`{}` may import only {:?}",
                    self.layer,
                    allowed(self.layer).unwrap_or(&[])
                ),
                None => format!("`{target}` is in no layer"),
            };
            self.found.push(Violation {
                file: self.file.to_owned(),
                line,
                message: format!(
                    "`{}` imports `{}` ({rule})",
                    self.layer,
                    segments.join("::")
                ),
            });
        }
    }

    /// Checks every leaf of a `use` tree as a full path.
    fn check_use(&mut self, tree: &syn::UseTree, prefix: &mut Vec<String>) {
        let leaf = |c: &mut Self, prefix: &mut Vec<String>, name: String, line: usize| {
            prefix.push(name);
            c.check(prefix, line);
            prefix.pop();
        };
        match tree {
            syn::UseTree::Path(p) => {
                prefix.push(p.ident.to_string());
                self.check_use(&p.tree, prefix);
                prefix.pop();
            }
            syn::UseTree::Name(n) => leaf(
                self,
                prefix,
                n.ident.to_string(),
                n.ident.span().start().line,
            ),
            syn::UseTree::Rename(r) => leaf(
                self,
                prefix,
                r.ident.to_string(),
                r.ident.span().start().line,
            ),
            syn::UseTree::Glob(g) => leaf(
                self,
                prefix,
                "*".to_owned(),
                g.star_token.spans[0].start().line,
            ),
            syn::UseTree::Group(g) => {
                for t in &g.items {
                    self.check_use(t, prefix);
                }
            }
        }
    }

    /// `crate :: x`, `super :: x` and `self :: x` inside a macro's tokens.
    fn check_tokens(&mut self, tokens: TokenStream) {
        let list: Vec<TokenTree> = tokens.into_iter().collect();
        for (k, t) in list.iter().enumerate() {
            match t {
                TokenTree::Group(g) => self.check_tokens(g.stream()),
                TokenTree::Ident(id) if matches!(id.to_string().as_str(), "crate" | "super") => {
                    let mut segments = vec![id.to_string()];
                    let mut j = k + 1;
                    while let (Some(TokenTree::Punct(a)), Some(TokenTree::Punct(b))) =
                        (list.get(j), list.get(j + 1))
                    {
                        if a.as_char() != ':' || b.as_char() != ':' {
                            break;
                        }
                        match list.get(j + 2) {
                            Some(TokenTree::Ident(s)) => segments.push(s.to_string()),
                            _ => break,
                        }
                        j += 3;
                    }
                    if segments.len() > 1 {
                        self.check(&segments, id.span().start().line);
                    }
                }
                _ => {}
            }
        }
    }
}

impl<'ast> Visit<'ast> for Checker<'_> {
    fn visit_item_mod(&mut self, m: &'ast syn::ItemMod) {
        if m.content.is_some() {
            self.module.push(m.ident.to_string());
            syn::visit::visit_item_mod(self, m);
            self.module.pop();
        }
    }

    fn visit_item_use(&mut self, u: &'ast syn::ItemUse) {
        self.check_use(&u.tree, &mut Vec::new());
    }

    fn visit_path(&mut self, p: &'ast syn::Path) {
        let segments: Vec<String> = p.segments.iter().map(|s| s.ident.to_string()).collect();
        if segments.len() > 1 {
            let line = p.segments[0].ident.span().start().line;
            self.check(&segments, line);
        }
        syn::visit::visit_path(self, p);
    }

    fn visit_macro(&mut self, m: &'ast syn::Macro) {
        self.check_tokens(m.tokens.clone());
        syn::visit::visit_macro(self, m);
    }
}

/// The violations in one file's text, `rel` being its path relative to `src/`.
fn violations_in(rel: &Path, text: &str) -> Result<Vec<Violation>, String> {
    let file = rel.display().to_string();
    let module = module_path(rel);
    let Some(layer) = module.first() else {
        return Ok(Vec::new()); // the crate root: the facade
    };
    if allowed(layer).is_none() {
        return Err(format!(
            "src/{file}: `{layer}` is in no layer: add it to LAYERS in tests/layers.rs and to docs/architecture.md"
        ));
    }
    let ast = syn::parse_file(text).map_err(|e| format!("src/{file}: {e}"))?;
    let mut c = Checker {
        file: format!("src/{file}").leak(),
        layer,
        module: module.clone(),
        found: Vec::new(),
    };
    c.visit_file(&ast);
    Ok(c.found)
}

fn sources() -> Vec<(PathBuf, String)> {
    sources_of(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src"))
}

/// Every `.rs` file under `src` (path relative to it, text), in path order.
fn sources_of(src: &Path) -> Vec<(PathBuf, String)> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
            .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
            .map(|e| e.expect("dir entry").path())
            .collect();
        entries.sort();
        for p in entries {
            if p.is_dir() {
                walk(&p, out);
            } else if p.extension().is_some_and(|x| x == "rs") {
                out.push(p);
            }
        }
    }
    let mut files = Vec::new();
    walk(src, &mut files);
    files
        .into_iter()
        .map(|p| {
            let text = std::fs::read_to_string(&p).expect("read source");
            (p.strip_prefix(src).expect("under src").to_owned(), text)
        })
        .collect()
}

#[test]
fn imports_point_down_the_layers() {
    let files = sources();
    assert!(files.len() > 40, "only {} source files found", files.len());
    let mut problems = Vec::new();
    for (rel, text) in &files {
        match violations_in(rel, text) {
            Ok(v) => problems.extend(
                v.into_iter()
                    .map(|v| format!("{}:{}: {}", v.file, v.line, v.message)),
            ),
            Err(e) => problems.push(e),
        }
    }
    assert!(
        problems.is_empty(),
        "{} layer violations (docs/architecture.md):\n{}",
        problems.len(),
        problems.join("\n")
    );
}

#[test]
fn no_source_file_is_longer_than_the_limit() {
    let long: Vec<String> = sources()
        .into_iter()
        .filter_map(|(rel, text)| {
            let n = text.lines().count();
            (n > MAX_LINES).then(|| format!("src/{}: {n} lines", rel.display()))
        })
        .collect();
    assert!(long.is_empty(), "longer than {MAX_LINES} lines: {long:?}");
}

#[test]
fn the_check_finds_upward_imports() {
    let bad = |rel: &str, text: &str| -> Vec<String> {
        violations_in(Path::new(rel), text)
            .expect("parses")
            .into_iter()
            .map(|v| format!("{}:{}", v.line, v.message))
            .collect()
    };
    // A use, a grouped use, a path in code, a `super` path out of the layer and a path
    // inside a macro: each found, with its line.
    let text = "use crate::report::CsvRecorder;\n\
                use crate::{model::Model, cli};\n\
                fn f() { let _ = crate::api::load; }\n\
                mod inner { use super::super::super::scenario::Source; }\n\
                fn g() { println!(\"{}\", crate::report::BASE_COLUMNS.len()); }\n";
    let found = bad("engine/driver.rs", text);
    assert_eq!(found.len(), 5, "{found:#?}");
    assert!(found[0].starts_with("1:`engine` imports `crate::report::CsvRecorder`"));
    assert!(found[1].starts_with("2:`engine` imports `crate::cli`"));
    assert!(found[2].starts_with("3:`engine` imports `crate::api::load`"));
    assert!(found[3].starts_with("4:`engine` imports `super::super::super::scenario::Source`"));
    assert!(found[4].starts_with("5:`engine` imports `crate::report::BASE_COLUMNS`"));
    // Downward and sideways-within-the-layer imports are fine; so are comments.
    let good = "//! See [`crate::report`].\n\
                use crate::model::Model;\n\
                use super::plant::Plant;\n\
                use crate::analysis::Monitor;\n\
                mod tests { use super::*; }\n";
    assert_eq!(bad("engine/driver.rs", good), Vec::<String>::new());
    // `super` from an inline module stays in the file's module.
    assert!(bad(
        "engine/driver.rs",
        "mod m { use super::super::plant::Plant; }\n"
    )
    .is_empty());
    // `super` from a layer's mod.rs leaves the layer.
    assert_eq!(bad("model/mod.rs", "use super::engine::Engine;\n").len(), 1);
    // A folder that is in no layer is refused.
    assert!(violations_in(Path::new("gui/mod.rs"), "").is_err());
    // The crate root may name anything.
    assert!(bad("lib.rs", "pub use cli::main;\nuse crate::cli::execute;\n").is_empty());
}

#[test]
fn engine_files_are_at_most_500_lines() {
    let long: Vec<String> = sources()
        .into_iter()
        .filter(|(rel, _)| rel.starts_with("engine"))
        .filter_map(|(rel, text)| {
            let n = text.lines().count();
            (n > MAX_ENGINE_LINES).then(|| format!("src/{}: {n} lines", rel.display()))
        })
        .collect();
    assert!(
        long.is_empty(),
        "longer than {MAX_ENGINE_LINES} lines: {long:?}"
    );
}

/// The files of `src` under `under` (relative to `src`, as `engine/driver.rs`).
fn part(src: &Path, under: &str) -> Vec<(String, String)> {
    sources_of(src)
        .into_iter()
        .filter(|(rel, _)| rel.starts_with(under))
        .map(|(rel, text)| (rel.display().to_string(), text))
        .collect()
}

#[test]
fn no_import_loops_between_files_of_the_engine_or_the_core() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let parts = [
        ("host-sim/src/engine", part(&root.join("src"), "engine")),
        (
            "controller-core/src",
            part(&root.join("../controller-core/src"), ""),
        ),
    ];
    let mut problems = Vec::new();
    for (name, files) in parts {
        assert!(files.len() > 20, "{name}: only {} files found", files.len());
        let graph = imports::Graph::of(&files).unwrap_or_else(|e| panic!("{name}: {e}"));
        problems.extend(graph.loops().into_iter().map(|l| format!("{name}: {l}")));
    }
    assert!(
        problems.is_empty(),
        "{} import loops between files (docs/architecture.md, \"One seam per stage\"):\n{}",
        problems.len(),
        problems.join("\n")
    );
}

#[test]
fn the_loop_check_finds_loops() {
    let files = |list: &[(&str, &str)]| -> Vec<(String, String)> {
        list.iter()
            .map(|(a, b)| ((*a).to_owned(), (*b).to_owned()))
            .collect()
    };
    let loops = |list: &[(&str, &str)]| imports::Graph::of(&files(list)).expect("parses").loops();
    // Two siblings that import each other: found, with the lines of the imports.
    let found = loops(&[
        ("engine/mod.rs", "mod a;\nmod b;\n"),
        ("engine/a.rs", "use super::b::B;\npub struct A;\n"),
        (
            "engine/b.rs",
            "pub struct B;\nfn f() { let _ = crate::engine::a::A; }\n",
        ),
    ]);
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(
        found[0].contains("engine/a.rs:1 → engine/b.rs:2 → engine/a.rs"),
        "{found:?}"
    );
    // Through a re-export of the parent (`super::A` is `a.rs`'s), and a child module named
    // by a relative path, which the parent imports: a loop of three.
    let found = loops(&[
        ("engine/mod.rs", "mod a;\nmod c;\npub use a::A;\n"),
        ("engine/a.rs", "use super::c::inner::C;\npub struct A;\n"),
        ("engine/c.rs", "mod inner;\n"),
        ("engine/c/inner.rs", "use super::super::A;\npub struct C;\n"),
    ]);
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(found[0].contains("engine/c/inner.rs"), "{found:?}");
    assert!(!found[0].contains("engine/mod.rs"), "{found:?}");
    // Declaring children, re-exporting them, and children naming each other one way only,
    // and a test module naming its own file: no loop.
    let found = loops(&[
        (
            "engine/mod.rs",
            "mod a;\nmod b;\npub use a::A;\npub use b::B;\n",
        ),
        ("engine/a.rs", "use super::B;\npub struct A;\n"),
        (
            "engine/b.rs",
            "pub struct B;\nmod tests { use super::*; }\n",
        ),
    ]);
    assert!(found.is_empty(), "{found:?}");
    // A child using its parent's own item while the parent uses the child: a loop; while
    // the parent only re-exports it: none.
    let found = loops(&[
        (
            "wire/mod.rs",
            "mod frame;\nuse frame::Frame;\npub struct Mode;\n",
        ),
        ("wire/frame.rs", "use super::Mode;\npub struct Frame;\n"),
    ]);
    assert_eq!(found.len(), 1, "{found:?}");
    let found = loops(&[
        (
            "wire/mod.rs",
            "mod frame;\npub use frame::Frame;\npub struct Mode;\n",
        ),
        ("wire/frame.rs", "use super::Mode;\npub struct Frame;\n"),
    ]);
    assert!(found.is_empty(), "{found:?}");
    // Re-exporting what another module (not a descendant) defines is an import.
    let found = loops(&[
        ("lib.rs", "mod config;\nmod wire;\n"),
        (
            "config.rs",
            "pub use crate::wire::Integrity;\npub struct Mode;\n",
        ),
        (
            "wire.rs",
            "use crate::config::Mode;\npub struct Integrity;\n",
        ),
    ]);
    assert_eq!(found.len(), 1, "{found:?}");
}

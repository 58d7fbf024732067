//! The file-level import graph inside one part of a crate (`host-sim/src/engine/`,
//! `controller-core/src/`), and the loops in it.
//!
//! Every `use` path and every path in code that starts with `crate::`, `super::`, `self::`
//! or names a child module is resolved to the file that holds what it names: the longest
//! prefix of the path that is a module gives a file, and when the next segment is a name
//! that file itself imports (a re-export such as `pub use source::World;`), the path is
//! followed to where that name comes from. An edge runs from the file that writes the
//! path to the file it resolves to. A module declaring its children (`mod camera;`) and
//! re-exporting what they define (`pub use camera::Camera;`, its interface) does not
//! import them; a private `use camera::Camera;` or a path in its code does. Two files
//! that reach each other through such edges are a loop.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use syn::visit::Visit;

/// The module path of a source file relative to its crate's `src/` (see `layers.rs`).
pub fn module_path(rel: &Path) -> Vec<String> {
    let mut parts: Vec<String> = rel
        .iter()
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    if let Some(last) = parts.pop() {
        let stem = last.trim_end_matches(".rs");
        if !matches!(stem, "mod" | "lib" | "main") {
            parts.push(stem.to_owned());
        }
    }
    parts
}

/// One file as the graph sees it: its module path, the names its file-level `use` items
/// bring in (name → absolute path) and every path it writes (absolute, with its line).
struct FileInfo {
    module: Vec<String>,
    imports: BTreeMap<String, Vec<String>>,
    /// Names its file-level `use` items bring in from other crates (`qemu_harness::qemu`).
    external: BTreeSet<String>,
    paths: Vec<(Vec<String>, usize)>,
}

/// Collects a file's paths; `module` is the module of the code being visited.
struct Collector<'a> {
    modules: &'a BTreeSet<Vec<String>>,
    module: Vec<String>,
    /// Inline modules entered (0: the file's own module).
    depth: usize,
    /// The `use` item being walked is a re-export (`pub use`, `pub(crate) use`).
    public: bool,
    info: FileInfo,
}

impl Collector<'_> {
    /// `segments` as an absolute module path, or `None` when it names another crate or a
    /// local item. `uses` tells a `use` path (whose first segment may be a child module).
    fn absolute(&self, segments: &[String]) -> Option<Vec<String>> {
        let first = segments.first()?;
        let mut abs = match first.as_str() {
            "crate" => Vec::new(),
            "self" => self.module.clone(),
            "super" => {
                let mut m = self.module.clone();
                m.pop();
                m
            }
            _ => {
                let mut child = self.module.clone();
                child.push(first.clone());
                if self.modules.contains(&child) {
                    child.extend(segments[1..].iter().cloned());
                    return Some(child);
                }
                // A name this file imported (`prefetch::prefetch` after `use …::prefetch`).
                let mut via = self.info.imports.get(first)?.clone();
                via.extend(segments[1..].iter().cloned());
                return Some(via);
            }
        };
        let mut rest = segments[1..].iter().peekable();
        while rest.peek().is_some_and(|s| *s == "super") {
            abs.pop();
            rest.next();
        }
        abs.extend(rest.cloned());
        Some(abs)
    }

    fn add(&mut self, segments: &[String], line: usize) {
        if let Some(abs) = self.absolute(segments) {
            self.info.paths.push((abs, line));
        }
    }

    /// Every leaf of a `use` tree: a path, and (at file level) the name it brings in.
    fn use_tree(&mut self, tree: &syn::UseTree, prefix: &mut Vec<String>) {
        let leaf = |c: &mut Self, path: Vec<String>, name: Option<String>, line| {
            let Some(abs) = c.absolute(&path) else {
                if let (Some(name), 0) = (name, c.depth) {
                    c.info.external.insert(name);
                }
                return;
            };
            if let (Some(name), 0) = (name, c.depth) {
                c.info.imports.insert(name, abs.clone());
            }
            // A module re-exporting its own descendants declares its interface: no
            // import (paths through it are followed to the descendant, [`resolve`]).
            let descendant = abs.len() > c.module.len() && abs.starts_with(&c.module);
            if !(c.public && descendant) {
                c.info.paths.push((abs, line));
            }
        };
        match tree {
            syn::UseTree::Path(p) => {
                prefix.push(p.ident.to_string());
                self.use_tree(&p.tree, prefix);
                prefix.pop();
            }
            syn::UseTree::Name(n) => {
                let name = n.ident.to_string();
                let mut path = prefix.clone();
                if name != "self" {
                    path.push(name.clone());
                }
                let local = if name == "self" {
                    prefix.last().cloned()
                } else {
                    Some(name)
                };
                leaf(self, path, local, n.ident.span().start().line);
            }
            syn::UseTree::Rename(r) => {
                let mut path = prefix.clone();
                if r.ident != "self" {
                    path.push(r.ident.to_string());
                }
                let line = r.ident.span().start().line;
                leaf(self, path, Some(r.rename.to_string()), line);
            }
            syn::UseTree::Glob(g) => {
                leaf(
                    self,
                    prefix.clone(),
                    None,
                    g.star_token.spans[0].start().line,
                );
            }
            syn::UseTree::Group(g) => {
                for t in &g.items {
                    self.use_tree(t, prefix);
                }
            }
        }
    }
}

impl<'ast> Visit<'ast> for Collector<'_> {
    fn visit_item_mod(&mut self, m: &'ast syn::ItemMod) {
        if m.content.is_some() {
            self.module.push(m.ident.to_string());
            self.depth += 1;
            syn::visit::visit_item_mod(self, m);
            self.depth -= 1;
            self.module.pop();
        }
    }

    fn visit_item_use(&mut self, u: &'ast syn::ItemUse) {
        self.public = !matches!(u.vis, syn::Visibility::Inherited);
        self.use_tree(&u.tree, &mut Vec::new());
        self.public = false;
    }

    fn visit_path(&mut self, p: &'ast syn::Path) {
        let segments: Vec<String> = p.segments.iter().map(|s| s.ident.to_string()).collect();
        if segments.len() > 1 {
            self.add(&segments, p.segments[0].ident.span().start().line);
        }
        syn::visit::visit_path(self, p);
    }
}

/// The import graph of a crate's files: `files` are (path relative to `src/`, text).
pub struct Graph {
    names: Vec<String>,
    /// `edges[a]`: the files `a` imports from, each with the line of its first such path.
    edges: Vec<BTreeMap<usize, usize>>,
}

impl Graph {
    /// Parses every file and resolves its paths (a file that does not parse is an error).
    pub fn of(files: &[(String, String)]) -> Result<Self, String> {
        let modules: BTreeMap<Vec<String>, usize> = files
            .iter()
            .enumerate()
            .map(|(k, (rel, _))| (module_path(Path::new(rel)), k))
            .collect();
        let set: BTreeSet<Vec<String>> = modules.keys().cloned().collect();
        let mut infos = Vec::new();
        for (rel, text) in files {
            let ast = syn::parse_file(text).map_err(|e| format!("{rel}: {e}"))?;
            let module = module_path(Path::new(rel));
            let mut c = Collector {
                modules: &set,
                module: module.clone(),
                depth: 0,
                public: false,
                info: FileInfo {
                    module,
                    imports: BTreeMap::new(),
                    external: BTreeSet::new(),
                    paths: Vec::new(),
                },
            };
            // The file-level `use` items first, so that code may name what they import.
            for item in &ast.items {
                if let syn::Item::Use(u) = item {
                    c.use_tree(&u.tree, &mut Vec::new());
                }
            }
            c.info.paths.clear();
            c.visit_file(&ast);
            infos.push(c.info);
        }
        let mut edges = vec![BTreeMap::new(); files.len()];
        for (from, info) in infos.iter().enumerate() {
            for (path, line) in &info.paths {
                let to = resolve(&modules, &infos, path, 0);
                if let Some(to) = to.filter(|&t| t != from) {
                    edges[from].entry(to).or_insert(*line);
                }
            }
            let _ = &info.module;
        }
        Ok(Self {
            names: files.iter().map(|(r, _)| r.clone()).collect(),
            edges,
        })
    }

    /// Every loop: each set of two or more files that reach one another, as its files in
    /// order with the line of one import along it (`a.rs:3 → b.rs:7 → a.rs`).
    pub fn loops(&self) -> Vec<String> {
        let sccs = tarjan(&self.edges);
        let mut out = Vec::new();
        for scc in sccs.into_iter().filter(|s| s.len() > 1) {
            let inside: BTreeSet<usize> = scc.iter().copied().collect();
            // One cycle through the component's first file, by a walk inside it.
            let start = *inside.iter().next().expect("non-empty");
            let mut walk = vec![start];
            let mut seen = BTreeSet::from([start]);
            let mut at = start;
            loop {
                let next = self.edges[at]
                    .keys()
                    .copied()
                    .filter(|t| inside.contains(t))
                    .find(|t| *t == start || !seen.contains(t))
                    .or_else(|| self.edges[at].keys().copied().find(|t| inside.contains(t)));
                let Some(next) = next else { break };
                walk.push(next);
                if next == start || !seen.insert(next) {
                    break;
                }
                at = next;
            }
            let steps: Vec<String> = walk
                .windows(2)
                .map(|w| format!("{}:{}", self.names[w[0]], self.edges[w[0]][&w[1]]))
                .chain(walk.last().map(|&l| self.names[l].clone()))
                .collect();
            let files: Vec<&str> = inside.iter().map(|&k| self.names[k].as_str()).collect();
            // Every import inside the loop, to see where to cut it.
            let mut text = format!("{files:?}: {}", steps.join(" → "));
            for &a in &inside {
                for (b, line) in &self.edges[a] {
                    if inside.contains(b) {
                        text +=
                            &format!("\n    {}:{line} imports {}", self.names[a], self.names[*b]);
                    }
                }
            }
            out.push(text);
        }
        out
    }
}

/// The file that the absolute path `path` names, following re-exports (at most 8 deep).
fn resolve(
    modules: &BTreeMap<Vec<String>, usize>,
    infos: &[FileInfo],
    path: &[String],
    depth: usize,
) -> Option<usize> {
    let k = (1..=path.len())
        .rev()
        .find(|&k| modules.contains_key(&path[..k]))
        .unwrap_or(0);
    let file = *modules.get(&path[..k])?;
    if path
        .get(k)
        .is_some_and(|n| infos[file].external.contains(n))
    {
        return None; // another crate's item, re-exported
    }
    if let (Some(name), true) = (path.get(k), depth < 8) {
        if let Some(via) = infos[file].imports.get(name) {
            let mut next = via.clone();
            next.extend(path[k + 1..].iter().cloned());
            if next.as_slice() != path {
                if let Some(to) = resolve(modules, infos, &next, depth + 1) {
                    return Some(to);
                }
            }
        }
    }
    Some(file)
}

/// Tarjan's strongly connected components of a small graph.
fn tarjan(edges: &[BTreeMap<usize, usize>]) -> Vec<Vec<usize>> {
    struct T<'e> {
        edges: &'e [BTreeMap<usize, usize>],
        index: Vec<Option<usize>>,
        low: Vec<usize>,
        on: Vec<bool>,
        stack: Vec<usize>,
        next: usize,
        out: Vec<Vec<usize>>,
    }
    fn visit(t: &mut T<'_>, v: usize) {
        t.index[v] = Some(t.next);
        t.low[v] = t.next;
        t.next += 1;
        t.stack.push(v);
        t.on[v] = true;
        for &w in t.edges[v].keys() {
            match t.index[w] {
                None => {
                    visit(t, w);
                    t.low[v] = t.low[v].min(t.low[w]);
                }
                Some(iw) if t.on[w] => t.low[v] = t.low[v].min(iw),
                Some(_) => {}
            }
        }
        if Some(t.low[v]) == t.index[v] {
            let mut scc = Vec::new();
            while let Some(w) = t.stack.pop() {
                t.on[w] = false;
                scc.push(w);
                if w == v {
                    break;
                }
            }
            t.out.push(scc);
        }
    }
    let n = edges.len();
    let mut t = T {
        edges,
        index: vec![None; n],
        low: vec![0; n],
        on: vec![false; n],
        stack: Vec::new(),
        next: 0,
        out: Vec::new(),
    };
    for v in 0..n {
        if t.index[v].is_none() {
            visit(&mut t, v);
        }
    }
    t.out
}

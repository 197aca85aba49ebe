//! No crate's modules import each other in a circle: reading every crate's sources (no GPU),
//! no top-level module (a file, or a folder with its submodules) reaches itself through the
//! modules it imports. Imports are read from the syntax tree: `use` trees (grouped ones
//! included) and every path in the code that starts with `crate::`, `super::` or `self::`.
//! Test modules and comments (doc links) are not imports. The crate root (`lib.rs`,
//! `main.rs`) re-exports its modules and is left out.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use syn::visit::Visit;

/// Every package's `src` folder: the facade's and each crate's under `crates/`.
fn source_folders() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut out = vec![root.join("src")];
    let mut crates: Vec<PathBuf> = std::fs::read_dir(root.join("crates"))
        .expect("crates/")
        .flatten()
        .map(|e| e.path().join("src"))
        .filter(|p| p.is_dir())
        .collect();
    crates.sort();
    out.extend(crates);
    out
}

/// The `.rs` files under `dir`, recursively.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())).flatten() {
        let path = entry.path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The module path of file `file` under `src` (`a/b.rs` and `a/b/mod.rs`: `["a", "b"]`; the
/// crate root: empty).
fn module_path(src: &Path, file: &Path) -> Vec<String> {
    let relative = file.strip_prefix(src).expect("under src");
    let mut parts: Vec<String> = relative.iter().map(|p| p.to_string_lossy().into_owned()).collect();
    let last = parts.pop().expect("a file name");
    let stem = last.trim_end_matches(".rs");
    if !(stem == "mod" || (parts.is_empty() && (stem == "lib" || stem == "main"))) {
        parts.push(stem.to_string());
    }
    parts
}

/// Collects the module paths a file's code names, resolved to paths from the crate root.
struct Imports {
    /// The module the visitor is in (the file's, then inline modules').
    module: Vec<String>,
    /// Absolute paths named, as segments after `crate`.
    named: Vec<Vec<String>>,
}

impl Imports {
    /// `segments` resolved from the current module, if it starts with `crate`, `super` or
    /// `self`.
    fn resolve(&self, segments: &[String]) -> Option<Vec<String>> {
        let first = segments.first()?;
        let mut base = match first.as_str() {
            "crate" => Vec::new(),
            "self" | "super" => self.module.clone(),
            _ => return None,
        };
        let mut rest = &segments[1..];
        if first == "super" {
            base.pop()?;
        }
        while rest.first().is_some_and(|s| s == "super") {
            base.pop()?;
            rest = &rest[1..];
        }
        base.extend(rest.iter().cloned());
        Some(base)
    }

    fn add(&mut self, segments: &[String]) {
        if let Some(path) = self.resolve(segments) {
            self.named.push(path);
        }
    }

    /// Every full path of a `use` tree under `prefix`.
    fn use_tree(&mut self, tree: &syn::UseTree, prefix: &mut Vec<String>) {
        match tree {
            syn::UseTree::Path(p) => {
                prefix.push(p.ident.to_string());
                self.use_tree(&p.tree, prefix);
                prefix.pop();
            }
            syn::UseTree::Name(n) => {
                prefix.push(n.ident.to_string());
                self.add(prefix);
                prefix.pop();
            }
            syn::UseTree::Rename(r) => {
                prefix.push(r.ident.to_string());
                self.add(prefix);
                prefix.pop();
            }
            syn::UseTree::Glob(_) => self.add(prefix),
            syn::UseTree::Group(g) => {
                for item in &g.items {
                    self.use_tree(item, prefix);
                }
            }
        }
    }
}

/// The tokens of `stream`, groups opened, in order.
fn flatten(stream: proc_macro2::TokenStream, out: &mut Vec<proc_macro2::TokenTree>) {
    for token in stream {
        match token {
            proc_macro2::TokenTree::Group(g) => flatten(g.stream(), out),
            other => out.push(other),
        }
    }
}

/// True for `#[cfg(test)]`.
fn is_test_only(attrs: &[syn::Attribute]) -> bool {
    attrs.iter().any(|a| a.path().is_ident("cfg") && a.parse_args::<syn::Ident>().is_ok_and(|i| i == "test"))
}

impl<'ast> Visit<'ast> for Imports {
    fn visit_item_use(&mut self, item: &'ast syn::ItemUse) {
        if !is_test_only(&item.attrs) {
            self.use_tree(&item.tree, &mut Vec::new());
        }
    }

    fn visit_item_mod(&mut self, item: &'ast syn::ItemMod) {
        if is_test_only(&item.attrs) {
            return;
        }
        if let Some((_, items)) = &item.content {
            self.module.push(item.ident.to_string());
            for i in items {
                self.visit_item(i);
            }
            self.module.pop();
        }
    }

    fn visit_item_fn(&mut self, item: &'ast syn::ItemFn) {
        if !is_test_only(&item.attrs) {
            syn::visit::visit_item_fn(self, item);
        }
    }

    fn visit_macro(&mut self, mac: &'ast syn::Macro) {
        syn::visit::visit_macro(self, mac);
        // A macro's arguments are tokens, not syntax: read the paths among them.
        let mut tokens = Vec::new();
        flatten(mac.tokens.clone(), &mut tokens);
        for (i, token) in tokens.iter().enumerate() {
            let proc_macro2::TokenTree::Ident(first) = token else { continue };
            let mut segments = vec![first.to_string()];
            let mut at = i + 1;
            while let (
                Some(proc_macro2::TokenTree::Punct(a)),
                Some(proc_macro2::TokenTree::Punct(b)),
                Some(proc_macro2::TokenTree::Ident(next)),
            ) = (tokens.get(at), tokens.get(at + 1), tokens.get(at + 2))
            {
                if a.as_char() != ':' || b.as_char() != ':' {
                    break;
                }
                segments.push(next.to_string());
                at += 3;
            }
            if segments.len() > 1 {
                self.add(&segments);
            }
        }
    }

    fn visit_path(&mut self, path: &'ast syn::Path) {
        let segments: Vec<String> = path.segments.iter().map(|s| s.ident.to_string()).collect();
        self.add(&segments);
        syn::visit::visit_path(self, path);
    }
}

/// The graph of one crate's top-level modules: each to the top-level modules it imports.
fn crate_graph(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let tops: BTreeSet<String> = files.iter().filter_map(|f| module_path(src, f).first().cloned()).collect();
    let mut graph: BTreeMap<String, BTreeSet<String>> =
        tops.iter().map(|t| (t.clone(), BTreeSet::new())).collect();
    for file in &files {
        let module = module_path(src, file);
        let Some(top) = module.first().cloned() else { continue };
        let text = std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        let syntax = syn::parse_file(&text).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        let mut imports = Imports { module, named: Vec::new() };
        imports.visit_file(&syntax);
        for path in imports.named {
            if let Some(other) = path.first().filter(|o| **o != top && tops.contains(*o)) {
                graph.get_mut(&top).expect("a node").insert(other.clone());
            }
        }
    }
    graph
}

/// A circle through `start` in `graph`, as the modules on it, if there is one.
fn circle_through(graph: &BTreeMap<String, BTreeSet<String>>, start: &str) -> Option<Vec<String>> {
    // Depth-first from `start`, keeping the path, until an edge returns to `start`.
    let mut path = vec![start.to_string()];
    let mut seen = BTreeSet::new();
    let mut stack: Vec<std::collections::btree_set::Iter<'_, String>> = vec![graph[start].iter()];
    while let Some(edges) = stack.last_mut() {
        match edges.next() {
            Some(next) if next == start => {
                path.push(start.to_string());
                return Some(path);
            }
            Some(next) if seen.insert(next.clone()) => {
                path.push(next.clone());
                // Edges lead only to the graph's own nodes.
                stack.push(graph[next].iter());
            }
            Some(_) => {}
            None => {
                stack.pop();
                path.pop();
            }
        }
    }
    None
}

#[test]
fn no_crate_has_an_import_circle() {
    let mut circles = Vec::new();
    let mut modules = 0;
    for src in source_folders() {
        let graph = crate_graph(&src);
        modules += graph.len();
        for start in graph.keys() {
            if let Some(circle) = circle_through(&graph, start) {
                circles.push(format!("{}: {}", src.parent().unwrap_or(&src).display(), circle.join(" → ")));
            }
        }
    }
    assert!(modules > 60, "read only {modules} modules");
    assert!(circles.is_empty(), "import circles:\n{}", circles.join("\n"));
}

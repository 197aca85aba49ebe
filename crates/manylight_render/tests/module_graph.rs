//! The render crate's toolkit has no circles: reading the sources (no GPU), no module imports
//! one that imports it back, directly or through others, and no pass module imports another
//! pass module (what passes share lives in `passes/common.rs`, `passes/scene_draw.rs`,
//! `passes/gbuffer_layout.rs` and the crate's shared modules).

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// Shared pass modules: any pass may import them; they import no pass.
const SHARED: [&str; 3] = ["common", "scene_draw", "gbuffer_layout"];

/// The code of a file without its comments (doc links are not imports).
fn code(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    text.lines().filter(|l| !l.trim_start().starts_with("//")).collect::<Vec<_>>().join("\n")
}

/// The names `prefix` is followed by in `code` (`crate::name`, `super::name`).
fn uses(code: &str, prefix: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for (i, _) in code.match_indices(prefix) {
        let rest = &code[i + prefix.len()..];
        let name: String = rest.chars().take_while(|c| c.is_ascii_lowercase() || *c == '_').collect();
        if !name.is_empty() {
            out.insert(name);
        }
    }
    out
}

#[test]
fn modules_form_no_circle_and_passes_import_no_pass() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    let mut pass_files = Vec::new();
    for entry in std::fs::read_dir(&src).expect("src").flatten() {
        let path = entry.path();
        let Some(name) = path.file_stem().and_then(|s| s.to_str()).map(str::to_string) else { continue };
        if path.extension().is_some_and(|e| e == "rs") && name != "lib" {
            let deps = uses(&code(&path), "crate::").into_iter().filter(|d| *d != name).collect();
            graph.insert(name, deps);
        } else if path.is_dir() && name != "passes" {
            // A module with submodules: what any of its files imports.
            let mut deps = BTreeSet::new();
            for file in std::fs::read_dir(&path).expect("module folder").flatten() {
                deps.extend(uses(&code(&file.path()), "crate::").into_iter().filter(|d| *d != name));
            }
            graph.insert(name, deps);
        }
    }
    let mut passes_deps = BTreeSet::new();
    for entry in std::fs::read_dir(src.join("passes")).expect("src/passes").flatten() {
        let path = entry.path();
        let name = path.file_stem().and_then(|s| s.to_str()).unwrap_or_default().to_string();
        let text = code(&path);
        passes_deps.extend(uses(&text, "crate::").into_iter().filter(|d| d != "passes"));
        if name != "mod" {
            pass_files.push((name, text));
        }
    }
    graph.insert("passes".into(), passes_deps);
    assert!(graph.len() > 15, "read only {} modules", graph.len());

    // No circle: no module reaches itself.
    for start in graph.keys() {
        let mut seen = BTreeSet::new();
        let mut stack: Vec<&String> = graph[start].iter().collect();
        while let Some(m) = stack.pop() {
            assert!(m != start, "`{start}` imports itself through others: {:?}", graph);
            if seen.insert(m.clone()) {
                stack.extend(graph.get(m).into_iter().flatten());
            }
        }
    }

    // No pass module imports another pass module; shared ones import only shared ones, in no
    // circle.
    let names: BTreeSet<String> = pass_files.iter().map(|(n, _)| n.clone()).collect();
    let mut shared_graph: BTreeMap<&str, BTreeSet<String>> = BTreeMap::new();
    for (name, text) in &pass_files {
        let imported: BTreeSet<String> =
            uses(text, "super::").into_iter().chain(uses(text, "crate::passes::")).collect();
        for other in imported.intersection(&names) {
            assert!(SHARED.contains(&other.as_str()), "pass module `{name}` imports pass module `{other}`");
            if SHARED.contains(&name.as_str()) {
                shared_graph.entry(name.as_str()).or_default().insert(other.clone());
            }
        }
    }
    for start in SHARED {
        let mut stack: Vec<&String> = shared_graph.get(start).into_iter().flatten().collect();
        let mut seen = BTreeSet::new();
        while let Some(m) = stack.pop() {
            assert!(m != start, "shared pass module `{start}` imports itself through others");
            if seen.insert(m.clone()) {
                stack.extend(shared_graph.get(m.as_str()).into_iter().flatten());
            }
        }
    }
}

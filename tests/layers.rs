//! The code has no import circle (docs/architecture.md). Across folders: the top-level modules
//! of both crates form layers, each referring only to the layers below it, in code and in doc
//! links; `wraptree-core` (crates/core) holds the lower layers and the `wraptree` crate (src/)
//! the upper ones. Inside folders: no file refers, through its siblings, back to itself.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The layers of crates/core/src then src/, bottom first; modules on one line may not refer to
/// each other.
const LAYERS: &[&[&str]] = &[
    &["geom", "output", "stop", "par"],
    &["scene"],
    &["events"],
    &["grouping"],
    &["refine"],
    &["wrap"],
    &["query"],
    &["spherize"],
    &["peers"],
    &["record"],
    &["replay"],
    &["render"],
    &["metrics"],
    &["cli"],
];

/// The modules crates/core holds; the rest are the `wraptree` crate's.
const CORE: &[&str] = &[
    "geom", "output", "stop", "par", "scene", "events", "grouping", "refine", "wrap", "query",
    "spherize",
];

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The source folders: the core crate's, then this crate's.
fn sources() -> [PathBuf; 2] {
    [root().join("crates/core/src"), root().join("src")]
}

fn layer_of(module: &str) -> Option<usize> {
    LAYERS.iter().position(|l| l.contains(&module))
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// Every path that `text` names after `prefix` (`crate::` or `super::`), braced lists expanded
/// to their items' first segments: `crate::a::{b::C, d}` gives `a::b` and `a::d`.
fn paths_after(text: &str, prefix: &str) -> BTreeSet<Vec<String>> {
    let mut found = BTreeSet::new();
    let mut rest = text;
    while let Some(i) = rest.find(prefix) {
        let before = rest[..i].chars().next_back();
        rest = &rest[i + prefix.len()..];
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
            continue;
        }
        let mut path = Vec::new();
        let mut tail = rest;
        loop {
            let end = tail
                .find(|c: char| !(c.is_alphanumeric() || c == '_'))
                .unwrap_or(tail.len());
            if end == 0 {
                break;
            }
            path.push(tail[..end].to_string());
            tail = &tail[end..];
            match tail.strip_prefix("::") {
                Some(t) => tail = t,
                None => break,
            }
        }
        if let Some(list) = tail.strip_prefix('{') {
            for item in top_level_items(list) {
                let mut p = path.clone();
                p.push(item);
                found.insert(p);
            }
        } else if !path.is_empty() {
            found.insert(path);
        }
    }
    found
}

/// Every top-level module that `text` names after `crate::`, braced lists included.
fn referenced(text: &str) -> BTreeSet<String> {
    paths_after(text, "crate::")
        .into_iter()
        .map(|p| p[0].clone())
        .collect()
}

/// The first path segment of each item of a braced `use` list (`list` starts after its `{`).
fn top_level_items(list: &str) -> Vec<String> {
    let mut items = vec![String::new()];
    let mut depth = 1;
    for c in list.chars() {
        match c {
            '{' => depth += 1,
            '}' if depth == 1 => break,
            '}' => depth -= 1,
            ',' if depth == 1 => items.push(String::new()),
            _ if depth == 1 => items.last_mut().unwrap().push(c),
            _ => {}
        }
    }
    items
        .iter()
        .filter_map(|item| item.trim().split("::").next())
        .map(str::to_string)
        .filter(|s| !s.is_empty())
        .collect()
}

/// A file's module path under its source folder: `grouping/partitioned/plan.rs` gives
/// `grouping::partitioned::plan`, a `mod.rs` its folder's.
fn module_path(src: &Path, file: &Path) -> Vec<String> {
    let rel = file.strip_prefix(src).unwrap().with_extension("");
    let mut path: Vec<String> = rel
        .components()
        .map(|c| c.as_os_str().to_str().unwrap().to_string())
        .collect();
    if matches!(
        path.last().map(String::as_str),
        Some("mod" | "lib" | "main")
    ) {
        path.pop();
    }
    path
}

#[test]
fn every_folder_refers_only_to_the_layers_below_it() {
    let mut upward = Vec::new();
    let mut seen = 0;
    for src in sources() {
        let mut files = Vec::new();
        rust_files(&src, &mut files);
        files.sort();
        for file in &files {
            let Some(module) = module_path(&src, file).first().cloned() else {
                continue;
            };
            let own = layer_of(&module)
                .unwrap_or_else(|| panic!("{} is in no layer of this test", file.display()));
            seen += 1;
            let text = std::fs::read_to_string(file).unwrap();
            for other in referenced(&text) {
                if other == module {
                    continue;
                }
                if let Some(theirs) = layer_of(&other)
                    && theirs >= own
                {
                    upward.push(format!("{} refers to crate::{other}", file.display()));
                }
            }
        }
    }
    assert!(seen > 50, "only {seen} source files were read");
    assert!(
        upward.is_empty(),
        "references that are not downward:\n{}",
        upward.join("\n")
    );
}

#[test]
fn the_core_crate_holds_the_lower_layers_and_every_module_has_a_layer() {
    for (src, lib) in sources().iter().zip(["lib.rs", "lib.rs"]) {
        let text = std::fs::read_to_string(src.join(lib)).unwrap();
        let core = src.ends_with("crates/core/src");
        let modules: Vec<&str> = text
            .lines()
            .filter_map(|l| l.strip_prefix("pub mod "))
            .map(|l| l.trim_end_matches(';'))
            .collect();
        assert!(!modules.is_empty(), "{}", src.display());
        for m in modules {
            assert!(layer_of(m).is_some(), "{m} is in no layer of this test");
            assert_eq!(CORE.contains(&m), core, "{m} is in the wrong crate");
        }
    }
    let core_top = CORE.iter().filter_map(|m| layer_of(m)).max().unwrap();
    for (l, layer) in LAYERS.iter().enumerate() {
        for m in *layer {
            assert_eq!(
                CORE.contains(m),
                l <= core_top,
                "{m}: core layers come first"
            );
        }
    }
}

/// The sibling files each file of a folder refers to (`super::x`, `crate::…::x`).
fn sibling_edges(src: &Path) -> BTreeMap<Vec<String>, BTreeSet<Vec<String>>> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let modules: BTreeMap<Vec<String>, PathBuf> = files
        .iter()
        .map(|f| (module_path(src, f), f.clone()))
        .collect();
    let mut edges: BTreeMap<Vec<String>, BTreeSet<Vec<String>>> = BTreeMap::new();
    for (module, file) in &modules {
        if module.is_empty() || file.ends_with("mod.rs") {
            continue;
        }
        let text = std::fs::read_to_string(file).unwrap();
        let parent = &module[..module.len() - 1];
        let named = paths_after(&text, "super::").into_iter().map(|p| {
            let mut full = parent.to_vec();
            full.extend(p);
            full
        });
        for path in named.chain(paths_after(&text, "crate::")) {
            if path.len() > parent.len() && path[..parent.len()] == *parent {
                let sibling = path[..module.len()].to_vec();
                if sibling != *module && modules.contains_key(&sibling) {
                    edges.entry(module.clone()).or_default().insert(sibling);
                }
            }
        }
    }
    edges
}

/// A circle through `edges` as a list of modules, if there is one.
fn circle(edges: &BTreeMap<Vec<String>, BTreeSet<Vec<String>>>) -> Option<Vec<Vec<String>>> {
    fn visit(
        v: &Vec<String>,
        edges: &BTreeMap<Vec<String>, BTreeSet<Vec<String>>>,
        state: &mut BTreeMap<Vec<String>, u8>,
        stack: &mut Vec<Vec<String>>,
    ) -> Option<Vec<Vec<String>>> {
        state.insert(v.clone(), 1);
        stack.push(v.clone());
        for w in edges.get(v).into_iter().flatten() {
            match state.get(w).copied().unwrap_or(0) {
                0 => {
                    if let Some(c) = visit(w, edges, state, stack) {
                        return Some(c);
                    }
                }
                1 => {
                    let from = stack.iter().position(|x| x == w).unwrap();
                    return Some(stack[from..].to_vec());
                }
                _ => {}
            }
        }
        stack.pop();
        state.insert(v.clone(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for v in edges.keys() {
        if state.get(v).copied().unwrap_or(0) == 0
            && let Some(c) = visit(v, edges, &mut state, &mut Vec::new())
        {
            return Some(c);
        }
    }
    None
}

#[test]
fn no_folder_has_a_circle_among_its_files() {
    for src in sources() {
        let edges = sibling_edges(&src);
        assert!(edges.len() > 10, "{}: {} files", src.display(), edges.len());
        if let Some(c) = circle(&edges) {
            let names: Vec<String> = c.iter().map(|m| m.join("::")).collect();
            panic!("{}: a circle: {}", src.display(), names.join(" → "));
        }
    }
}

#[test]
fn the_reference_scanner_reads_braced_lists() {
    let found =
        referenced("use crate::{geom::Aabb, grouping::{Merge, cluster::X}};\n[`crate::wrap`]");
    assert_eq!(
        found.into_iter().collect::<Vec<_>>(),
        ["geom", "grouping", "wrap"]
    );
    let mut edges = BTreeMap::new();
    let m = |s: &str| vec!["f".to_string(), s.to_string()];
    edges.insert(m("a"), BTreeSet::from([m("b")]));
    edges.insert(m("b"), BTreeSet::from([m("c")]));
    assert_eq!(circle(&edges), None);
    edges.insert(m("c"), BTreeSet::from([m("a")]));
    assert_eq!(circle(&edges).map(|c| c.len()), Some(3));
}

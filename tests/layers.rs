//! The library's folders form layers (docs/architecture.md): each refers only to the layers
//! below it, in code and in doc links, so there is no import circle.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// The layers of `src/`, bottom first; modules on one line may not refer to each other.
const LAYERS: &[&[&str]] = &[
    &["geom", "output", "stop"],
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
];

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

/// Every top-level module that `text` names after `crate::`, braced lists included.
fn referenced(text: &str) -> BTreeSet<String> {
    let mut found = BTreeSet::new();
    let mut rest = text;
    while let Some(i) = rest.find("crate::") {
        rest = &rest[i + "crate::".len()..];
        let names: Vec<String> = if let Some(list) = rest.strip_prefix('{') {
            top_level_items(list)
        } else {
            let end = rest
                .find(|c: char| !(c.is_alphanumeric() || c == '_'))
                .unwrap_or(rest.len());
            vec![rest[..end].to_string()]
        };
        found.extend(names);
    }
    found
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

#[test]
fn every_folder_refers_only_to_the_layers_below_it() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.sort();
    let mut upward = Vec::new();
    let mut seen = 0;
    for file in &files {
        let rel = file.strip_prefix(&src).unwrap();
        let first = rel
            .components()
            .next()
            .unwrap()
            .as_os_str()
            .to_str()
            .unwrap();
        let module = first.trim_end_matches(".rs");
        let Some(own) = layer_of(module) else {
            continue;
        };
        seen += 1;
        let text = std::fs::read_to_string(file).unwrap();
        for other in referenced(&text) {
            if other == module {
                continue;
            }
            if let Some(theirs) = layer_of(&other)
                && theirs >= own
            {
                upward.push(format!("{} refers to crate::{other}", rel.display()));
            }
        }
    }
    assert!(seen > 50, "only {seen} files of src/ were read");
    assert!(
        upward.is_empty(),
        "references that are not downward:\n{}",
        upward.join("\n")
    );
}

#[test]
fn every_top_level_module_has_a_layer() {
    let lib =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("src/lib.rs")).unwrap();
    let modules: Vec<&str> = lib
        .lines()
        .filter_map(|l| l.strip_prefix("pub mod "))
        .map(|l| l.trim_end_matches(';'))
        .collect();
    assert!(modules.len() >= 10, "{modules:?}");
    for m in modules {
        assert!(layer_of(m).is_some(), "src/{m} is in no layer of this test");
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
}

/// The module path of a file of `src/` (`scene/obj/polygon.rs` → `scene::obj::polygon`,
/// `scene/mod.rs` → `scene`).
fn module_path(rel: &Path) -> Vec<String> {
    let mut parts: Vec<String> = rel
        .iter()
        .map(|p| p.to_string_lossy().trim_end_matches(".rs").to_string())
        .collect();
    if parts.last().is_some_and(|p| p == "mod") {
        parts.pop();
    }
    parts
}

/// The identifier segments at the start of `s` (`a::b::C, …` → `[a, b, C]`), and for a braced
/// list the segments of each of its items.
fn segments(s: &str) -> Vec<Vec<String>> {
    if let Some(list) = s.strip_prefix('{') {
        let mut items = vec![String::new()];
        let mut depth = 1;
        for c in list.chars() {
            match c {
                '}' if depth == 1 => break,
                ',' if depth == 1 => items.push(String::new()),
                _ => {
                    depth += usize::from(c == '{');
                    depth -= usize::from(c == '}');
                    items.last_mut().unwrap().push(c);
                }
            }
        }
        return items.iter().flat_map(|i| segments(i.trim())).collect();
    }
    let mut out = Vec::new();
    let mut rest = s;
    loop {
        let end = rest
            .find(|c: char| !(c.is_alphanumeric() || c == '_'))
            .unwrap_or(rest.len());
        if end == 0 {
            break;
        }
        out.push(rest[..end].to_string());
        match rest[end..].strip_prefix("::") {
            Some(r) if !r.starts_with('{') => rest = r,
            _ => break,
        }
    }
    vec![out]
}

/// The module paths `text` (of the file of module `own`) refers to through `crate::`,
/// `super::` and `self::`, as written (not yet resolved to files).
fn module_references(text: &str, own: &[String]) -> Vec<Vec<String>> {
    let mut found = Vec::new();
    for (prefix, base) in [("crate::", 0usize), ("super::", 1), ("self::", 2)] {
        let mut rest = text;
        while let Some(i) = rest.find(prefix) {
            // `super::super::`, `crate::…` inside a longer word: skip what is not a path start.
            let before = rest[..i].chars().last();
            rest = &rest[i + prefix.len()..];
            if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
                continue;
            }
            let mut start: Vec<String> = match base {
                0 => Vec::new(),
                1 => own[..own.len().saturating_sub(1)].to_vec(),
                _ => own.to_vec(),
            };
            while let Some(r) = rest.strip_prefix("super::") {
                start.pop();
                rest = r;
            }
            for seg in segments(rest) {
                let mut path = start.clone();
                path.extend(seg);
                found.push(path);
            }
        }
    }
    found
}

/// No file of `src/` refers, through other files, back to itself: inside each folder the files
/// form layers too. A module referring to its own ancestors (a submodule using its parent's
/// items, anything using a folder's `mod.rs`) is not counted; test modules are not read.
#[test]
fn no_files_refer_to_each_other_in_a_circle() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.sort();
    let modules: Vec<Vec<String>> = files
        .iter()
        .map(|f| module_path(f.strip_prefix(&src).unwrap()))
        .collect();
    let index: std::collections::HashMap<&[String], usize> = modules
        .iter()
        .enumerate()
        .map(|(i, m)| (m.as_slice(), i))
        .collect();
    let mut edges: Vec<BTreeSet<usize>> = vec![BTreeSet::new(); files.len()];
    for (i, file) in files.iter().enumerate() {
        let own = &modules[i];
        if own.len() < 2 {
            continue; // lib.rs, main.rs, a top-level mod.rs or file: the layer test's
        }
        let text = std::fs::read_to_string(file).unwrap();
        let text = text.split("#[cfg(test)]").next().unwrap();
        for path in module_references(text, own) {
            // The longest prefix of `path` that is a file of its own.
            let Some(t) = (1..=path.len())
                .rev()
                .find_map(|n| index.get(&path[..n]).copied())
            else {
                continue;
            };
            let target = &modules[t];
            if t != i && !own.starts_with(target) {
                edges[i].insert(t);
            }
        }
    }
    let edge_count: usize = edges.iter().map(BTreeSet::len).sum();
    assert!(
        edge_count > 50,
        "only {edge_count} references between files were found"
    );
    let circles: Vec<String> = strongly_connected(&edges)
        .into_iter()
        .filter(|c| c.len() > 1)
        .map(|c| {
            let mut names: Vec<String> = c.iter().map(|&k| modules[k].join("::")).collect();
            names.sort();
            names.join(" ↔ ")
        })
        .collect();
    // Circles older than this check, each to be undone by the folder's owner; a new one fails.
    let known = [
        "grouping::partitioned::brute_force ↔ grouping::partitioned::subproblem",
        "grouping::partitioned::keep ↔ grouping::partitioned::plan",
        "grouping::partitioned::all_pairs ↔ grouping::partitioned::executor",
        "refine::renumber ↔ refine::work",
    ];
    let new: Vec<&String> = circles
        .iter()
        .filter(|c| !known.contains(&c.as_str()))
        .collect();
    assert!(
        new.is_empty(),
        "files refer to each other in a circle: {new:#?}"
    );
    let gone: Vec<&&str> = known
        .iter()
        .filter(|k| !circles.iter().any(|c| c == *k))
        .collect();
    assert!(gone.is_empty(), "undone, remove from `known`: {gone:?}");
}

/// The strongly connected components of the graph `edges` (Tarjan's algorithm), each sorted.
fn strongly_connected(edges: &[BTreeSet<usize>]) -> Vec<Vec<usize>> {
    struct State<'a> {
        edges: &'a [BTreeSet<usize>],
        index: Vec<Option<usize>>,
        low: Vec<usize>,
        on_stack: Vec<bool>,
        stack: Vec<usize>,
        next: usize,
        out: Vec<Vec<usize>>,
    }
    fn visit(s: &mut State, v: usize) {
        s.index[v] = Some(s.next);
        s.low[v] = s.next;
        s.next += 1;
        s.stack.push(v);
        s.on_stack[v] = true;
        for &w in s.edges[v].iter() {
            match s.index[w] {
                None => {
                    visit(s, w);
                    s.low[v] = s.low[v].min(s.low[w]);
                }
                Some(iw) if s.on_stack[w] => s.low[v] = s.low[v].min(iw),
                _ => {}
            }
        }
        if Some(s.low[v]) == s.index[v] {
            let mut c = Vec::new();
            while let Some(w) = s.stack.pop() {
                s.on_stack[w] = false;
                c.push(w);
                if w == v {
                    break;
                }
            }
            c.sort();
            s.out.push(c);
        }
    }
    let n = edges.len();
    let mut s = State {
        edges,
        index: vec![None; n],
        low: vec![0; n],
        on_stack: vec![false; n],
        stack: Vec::new(),
        next: 0,
        out: Vec::new(),
    };
    for v in 0..n {
        if s.index[v].is_none() {
            visit(&mut s, v);
        }
    }
    s.out
}

#[test]
fn the_module_reference_scanner_resolves_super_and_braces() {
    let own: Vec<String> = ["scene", "obj", "groups"].map(String::from).to_vec();
    let found = module_references(
        "use super::super::{faces::Faces, input::{A, B}};\nuse self::x::Y; crate::geom::P3",
        &own,
    );
    let joined: Vec<String> = found.iter().map(|p| p.join("::")).collect();
    assert_eq!(
        joined,
        [
            "geom::P3",
            "scene::faces::Faces",
            "scene::input",
            "scene::obj::groups::x::Y"
        ]
    );
}

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

//! The architecture as tests: the module graph has no arrow running back up (docs/architecture.md). The
//! other rules (no printing in the library, no process started, no function longer than a screen) are
//! clippy's: `[workspace.lints.clippy]` in Cargo.toml and clippy.toml.
//!
//! The checks read the source text: every `crate::<module>` path (in `use` lines and inline) in a file of
//! `src/<module>/` is an arrow from that module to `<module>`. `#[cfg(test)]` blocks are left out (unit
//! tests may print their evidence).
// Helpers outside #[test] functions read the repository's own files: a failure to read is a failed test.
#![allow(clippy::unwrap_used)]

use std::collections::BTreeMap;
use std::fs;
use std::path::{Path, PathBuf};

/// The library's modules, lowest first. A module may use modules of lower layers only; modules of one
/// layer do not use each other.
const LAYERS: &[&[&str]] = &[
    &["model", "mcap_io"],
    &["integrate"],
    &["simulation"],
    &["format"],
    &["scene"],
    &["record", "verify", "analyse", "inspect"],
    &["live"],
    &["bench"],
];

fn layer_of(module: &str) -> Option<usize> {
    LAYERS.iter().position(|l| l.contains(&module))
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The library's source files with the module each belongs to (`src/model/x.rs` → model,
/// `src/simulation.rs` → simulation); `lib.rs`, `main.rs` and `cli/` are not library modules.
fn library_files() -> Vec<(String, PathBuf)> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.sort();
    files
        .into_iter()
        .filter_map(|p| {
            let rel = p.strip_prefix(&src).unwrap().to_path_buf();
            let first = rel.components().next()?.as_os_str().to_str()?.to_string();
            let module = first.trim_end_matches(".rs").to_string();
            (!matches!(module.as_str(), "lib" | "main" | "cli")).then_some((module, p))
        })
        .collect()
}

/// The file's text without its `#[cfg(test)]` items (from the attribute to the end of the item's block).
fn without_tests(text: &str) -> String {
    let mut out = String::new();
    let mut lines = text.lines();
    while let Some(line) = lines.next() {
        if line.trim_start().starts_with("#[cfg(test)]") {
            let mut depth = 0i32;
            let mut opened = false;
            for l in lines.by_ref() {
                depth += l.matches('{').count() as i32 - l.matches('}').count() as i32;
                opened |= l.contains('{');
                if (opened && depth <= 0) || (!opened && l.trim_end().ends_with(';')) {
                    break;
                }
            }
            continue;
        }
        out.push_str(line);
        out.push('\n');
    }
    out
}

/// Every module named after `crate::` in the text, including grouped imports `use crate::{a, b::c}`.
fn crate_references(text: &str) -> Vec<String> {
    let mut found = Vec::new();
    for (i, _) in text.match_indices("crate::") {
        let rest = &text[i + "crate::".len()..];
        if let Some(group) = rest.strip_prefix('{') {
            let end = group.find('}').unwrap_or(group.len());
            for item in group[..end].split(',') {
                let name: String = item
                    .trim()
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                found.push(name);
            }
        } else {
            found.push(
                rest.chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect(),
            );
        }
    }
    found.retain(|m| !m.is_empty());
    found
}

#[test]
fn every_module_is_in_a_layer() {
    for (module, path) in library_files() {
        assert!(
            layer_of(&module).is_some(),
            "{}: module `{module}` is in no layer of tests/it/architecture.rs (and docs/architecture.md)",
            path.display()
        );
    }
}

#[test]
fn no_arrow_runs_back_up_the_module_graph() {
    let mut arrows: BTreeMap<(String, String), Vec<String>> = BTreeMap::new();
    for (module, path) in library_files() {
        let text = without_tests(&fs::read_to_string(&path).unwrap());
        for target in crate_references(&text) {
            if target != module && layer_of(&target).is_some() {
                arrows
                    .entry((module.clone(), target))
                    .or_default()
                    .push(path.display().to_string());
            }
        }
    }
    let mut wrong = Vec::new();
    for ((from, to), files) in &arrows {
        let (lf, lt) = (layer_of(from).unwrap(), layer_of(to).unwrap());
        println!("{from} (layer {lf}) -> {to} (layer {lt})");
        if lt >= lf {
            wrong.push(format!("{from} -> {to} in {}", files.join(", ")));
        }
    }
    assert!(
        wrong.is_empty(),
        "arrows that do not point down the layers:\n  {}",
        wrong.join("\n  ")
    );
}

#[test]
fn the_negative_control_catches_an_upward_arrow() {
    let text = "use crate::model::State;\nuse crate::{record::x, format};\nlet y = crate::scene::defaults::RATE;\n#[cfg(test)]\nmod tests {\n    use crate::cli::x;\n}\n";
    let refs = crate_references(&without_tests(text));
    assert_eq!(refs, ["model", "record", "format", "scene"]);
    // A file of `model` naming `record` would be an arrow from layer 0 to layer 5.
    assert!(layer_of("record").unwrap() > layer_of("model").unwrap());
}

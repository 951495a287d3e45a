//! The architecture as tests: docs/architecture.md draws exactly the workspace's crate graph and the module
//! graph inside crates/coin-log, and no module arrow runs back up the layers the document lists. The other
//! rules (no printing in the libraries, no process started, no function longer than a screen) are
//! clippy's: `[workspace.lints.clippy]` in Cargo.toml and clippy.toml.
//!
//! The crate graph is `cargo metadata`'s: the normal dependencies of each workspace crate on the others.
//! The module graph is read from the source text: every `crate::<module>` path (in `use` trees and inline)
//! in a file of `crates/coin-log/src/<module>` is an arrow from that module to `<module>`; comments and
//! `#[cfg(test)]` items are left out (unit tests may reach anywhere).
// Helpers outside #[test] functions read the repository's own files: a failure to read is a failed test.
#![allow(clippy::unwrap_used)]

use crate::support::repo;
use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;

/// An arrow of a graph: (from, to).
type Arrow = (String, String);

const DOC: &str = "docs/architecture.md";

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

/// The library's modules: the entries of `crates/coin-log/src` but `lib.rs`.
fn modules() -> BTreeSet<String> {
    fs::read_dir(repo().join("crates/coin-log/src"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| name != "lib.rs")
        .map(|name| name.trim_end_matches(".rs").to_string())
        .collect()
}

/// The file's code without comments and without its `#[cfg(test)]` items (from the attribute to the end
/// of the item's block, or to the `;` of a one-line item).
fn without_tests(text: &str) -> String {
    let mut out = String::new();
    let mut lines = text.lines().map(|l| l.split("//").next().unwrap_or(""));
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

fn identifier(text: &str) -> String {
    text.trim_start()
        .chars()
        .take_while(|c| c.is_alphanumeric() || *c == '_')
        .collect()
}

/// Every name after `crate::` in the text; in a use tree `crate::{a, b::{c, d}}`, its top-level items.
fn crate_references(text: &str) -> Vec<String> {
    let mut found = Vec::new();
    for (i, _) in text.match_indices("crate::") {
        let rest = &text[i + "crate::".len()..];
        let Some(group) = rest.strip_prefix('{') else {
            found.push(identifier(rest));
            continue;
        };
        let (mut depth, mut start) = (0, 0);
        for (j, c) in group.char_indices() {
            match c {
                '{' => depth += 1,
                '}' if depth == 0 => {
                    found.push(identifier(&group[start..j]));
                    break;
                }
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    found.push(identifier(&group[start..j]));
                    start = j + 1;
                }
                _ => {}
            }
        }
    }
    found.retain(|m| !m.is_empty());
    found
}

/// The arrows between the library's modules, each with the files that make it.
fn module_arrows() -> BTreeMap<Arrow, Vec<String>> {
    let modules = modules();
    let src = repo().join("crates/coin-log/src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut arrows: BTreeMap<Arrow, Vec<String>> = BTreeMap::new();
    for path in files {
        let rel = path.strip_prefix(&src).unwrap();
        let first = rel
            .components()
            .next()
            .unwrap()
            .as_os_str()
            .to_string_lossy();
        let module = first.trim_end_matches(".rs").to_string();
        if module == "lib" {
            continue;
        }
        let text = without_tests(&fs::read_to_string(&path).unwrap());
        for target in crate_references(&text) {
            if target != module && modules.contains(&target) {
                let files = arrows.entry((module.clone(), target)).or_default();
                files.push(rel.display().to_string());
                files.dedup();
            }
        }
    }
    arrows
}

/// A crate's node in the document: its package name with `_` for `-` (mermaid ids).
fn node(package: &str) -> String {
    package.replace('-', "_")
}

/// The dependencies between the workspace's crates (`[dependencies]`, not dev or build), by
/// `cargo metadata`.
fn crate_arrows() -> BTreeSet<Arrow> {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let out = Command::new(cargo)
        .args([
            "metadata",
            "--format-version",
            "1",
            "--no-deps",
            "--offline",
        ])
        .current_dir(repo())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "cargo metadata: {err}");
    let metadata: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let packages = metadata["packages"].as_array().unwrap();
    let names: BTreeSet<&str> = packages
        .iter()
        .map(|p| p["name"].as_str().unwrap())
        .collect();
    let mut arrows = BTreeSet::new();
    for package in packages {
        for dependency in package["dependencies"].as_array().unwrap() {
            let name = dependency["name"].as_str().unwrap();
            if dependency["kind"].is_null() && names.contains(name) {
                arrows.insert((node(package["name"].as_str().unwrap()), node(name)));
            }
        }
    }
    arrows
}

/// The arrows the ```mermaid blocks of a Markdown text draw: `a --> b` and `a --> b & c`.
fn drawn_arrows(text: &str) -> BTreeSet<Arrow> {
    let mut arrows = BTreeSet::new();
    let mut in_graph = false;
    for line in text.lines() {
        match line.trim() {
            "```mermaid" => in_graph = true,
            "```" => in_graph = false,
            l if in_graph && l.contains("-->") => {
                let (from, to) = l.split_once("-->").unwrap();
                let ids = |side: &str| -> Vec<String> {
                    side.split('&')
                        .map(|id| {
                            let id = id.trim();
                            assert!(
                                !id.is_empty() && identifier(id) == id,
                                "{DOC}: `{l}`: draw arrows as `a --> b & c`, nodes declared apart"
                            );
                            id.to_string()
                        })
                        .collect()
                };
                for f in ids(from) {
                    arrows.extend(ids(to).into_iter().map(|t| (f.clone(), t)));
                }
            }
            _ => {}
        }
    }
    arrows
}

/// What `drawn` gets wrong against `real`: arrows it lacks and arrows it has that do not exist.
fn differences(real: &BTreeSet<Arrow>, drawn: &BTreeSet<Arrow>) -> Vec<String> {
    let missing = real
        .difference(drawn)
        .map(|(f, t)| format!("missing: {f} --> {t}"));
    let extra = drawn
        .difference(real)
        .map(|(f, t)| format!("does not exist: {f} --> {t}"));
    missing.chain(extra).collect()
}

/// The layers of the document's table (`| 0 | `model` | … |`), lowest first, each a list of modules.
fn layers(text: &str) -> Vec<Vec<String>> {
    let mut layers = Vec::new();
    for line in text.lines() {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        if cells.len() < 4 || cells[1].parse::<usize>() != Ok(layers.len()) {
            continue;
        }
        let names = cells[2].split(',').map(|m| {
            let name = m.trim().trim_matches('`');
            assert_eq!(format!("`{name}`"), m.trim(), "{DOC}: `{line}`");
            name.to_string()
        });
        layers.push(names.collect());
    }
    layers
}

/// Arrows that do not point to a lower layer (or whose ends are in no layer).
fn upward(arrows: &BTreeSet<Arrow>, layers: &[Vec<String>]) -> Vec<String> {
    let layer = |m: &str| layers.iter().position(|l| l.iter().any(|x| x == m));
    let name =
        |m: &str| layer(m).map_or(format!("{m} (in no layer)"), |l| format!("{m} (layer {l})"));
    arrows
        .iter()
        .filter(|(from, to)| !matches!((layer(from), layer(to)), (Some(f), Some(t)) if t < f))
        .map(|(from, to)| format!("{} -> {}", name(from), name(to)))
        .collect()
}

#[test]
fn the_document_draws_exactly_the_crate_and_module_graphs() {
    let doc = fs::read_to_string(repo().join(DOC)).unwrap();
    let crates = crate_arrows();
    let modules = module_arrows();
    for ((from, to), files) in &modules {
        println!("{from} -> {to}: {}", files.join(", "));
    }
    let real: BTreeSet<Arrow> = crates.iter().cloned().chain(modules.into_keys()).collect();
    println!("{} crate arrows, {} in all", crates.len(), real.len());
    let wrong = differences(&real, &drawn_arrows(&doc));
    assert!(
        wrong.is_empty(),
        "{DOC}'s graphs are not the code's (crate arrows from `cargo metadata`, module arrows from \
         the `crate::` paths of crates/coin-log):\n  {}",
        wrong.join("\n  ")
    );
}

#[test]
fn every_module_is_in_one_layer_and_no_arrow_runs_back_up() {
    let layers = layers(&fs::read_to_string(repo().join(DOC)).unwrap());
    let listed: Vec<&String> = layers.iter().flatten().collect();
    let unique: BTreeSet<String> = listed.iter().map(|m| m.to_string()).collect();
    println!("layers: {layers:?}");
    assert_eq!(listed.len(), unique.len(), "a module in two layers");
    assert_eq!(unique, modules(), "{DOC}'s layers list exactly the modules");
    let arrows = module_arrows();
    let wrong = upward(&arrows.keys().cloned().collect(), &layers);
    assert!(
        wrong.is_empty(),
        "arrows that do not point down the layers of {DOC}:\n  {}",
        wrong.join("\n  ")
    );
}

/// Negative controls of the readers above: grouped, nested and inline paths found, comments and tests
/// left out; a missing, an extra and an upward arrow caught.
#[test]
fn the_checks_catch_a_hidden_a_missing_an_extra_and_an_upward_arrow() {
    let text = "use crate::model::State; // crate::live\nuse crate::{\n    format::{A, B},\n    record::x,\n};\nlet y = crate::scene::defaults::RATE;\n#[cfg(test)]\nmod tests {\n    use crate::cli::x;\n}\n#[cfg(test)]\nuse crate::verify;\n";
    let refs = crate_references(&without_tests(text));
    assert_eq!(refs, ["model", "format", "record", "scene"]);
    let arrow = |f: &str, t: &str| (f.to_string(), t.to_string());
    let real = BTreeSet::from([arrow("record", "format"), arrow("format", "model")]);
    let drawn = drawn_arrows("```mermaid\nflowchart TD\n    record[\"record: scene → MCAP\"]\n    record --> format & scene\n```\n");
    assert_eq!(
        differences(&real, &drawn),
        [
            "missing: format --> model",
            "does not exist: record --> scene"
        ]
    );
    let text =
        "| layer | modules |\n| --- | --- |\n| 0 | `model` | x |\n| 1 | `format`, `record` | y |\n";
    let layers = layers(text);
    assert_eq!(layers, [vec!["model"], vec!["format", "record"]]);
    assert!(upward(&BTreeSet::from([arrow("format", "model")]), &layers).is_empty());
    let sideways = BTreeSet::from([arrow("record", "format"), arrow("model", "live")]);
    assert_eq!(
        upward(&sideways, &layers),
        [
            "model (layer 0) -> live (in no layer)",
            "record (layer 1) -> format (layer 1)"
        ]
    );
}

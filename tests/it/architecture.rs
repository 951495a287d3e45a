//! The architecture as tests: the module graph has no arrow running back up (docs/architecture.md), the
//! library never prints and never starts a process, and no function is longer than a screen
//! ([`LONGEST_FUNCTION`] lines, tables of data excepted).
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
    &["live", "sweep"],
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

#[test]
fn the_library_never_prints_nor_starts_a_process() {
    let forbidden = [
        "println!",
        "eprintln!",
        "print!(",
        "eprint!(",
        "dbg!(",
        "std::process::Command",
        "process::exit",
    ];
    let mut found = Vec::new();
    for (_, path) in library_files() {
        let text = without_tests(&fs::read_to_string(&path).unwrap());
        for (n, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            for f in forbidden {
                if code.contains(f) {
                    found.push(format!("{}:{}: `{f}`", path.display(), n + 1));
                }
            }
        }
    }
    assert!(found.is_empty(), "{}", found.join("\n"));
}

/// `println!` panics when stdout is a closed pipe or a full disk; the command line prints only through
/// `src/cli/output.rs`, whose macros handle both (format.md: Exit codes).
#[test]
fn the_command_line_prints_only_through_its_output_module() {
    let cli = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/cli");
    let mut files = Vec::new();
    rust_files(&cli, &mut files);
    files.push(Path::new(env!("CARGO_MANIFEST_DIR")).join("src/main.rs"));
    let mut found = Vec::new();
    for path in files.iter().filter(|p| !p.ends_with("cli/output.rs")) {
        let text = without_tests(&fs::read_to_string(path).unwrap());
        for (n, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            for f in ["println!", "eprintln!", "print!(", "eprint!("] {
                // `outln!`/`errln!` do not contain these; `out!(` does not either.
                if code.contains(f) {
                    found.push(format!("{}:{}: `{f}`", path.display(), n + 1));
                }
            }
        }
    }
    println!("{} files of src/cli checked", files.len());
    assert!(
        found.is_empty(),
        "use out!/outln!/errln! of src/cli/output.rs:\n{}",
        found.join("\n")
    );
}

/// Longest function body allowed, in lines (about a screen): longer functions mix stages.
const LONGEST_FUNCTION: usize = 80;

/// Functions that are tables of data, not logic, and may be longer (file suffix, function name, why).
const DATA_TABLES: &[(&str, &str, &str)] = &[(
    "scene/presets.rs",
    "preset",
    "one match arm per built-in scene, each a literal scene",
)];

/// (name, first line, length in lines) of every `fn` with a body in `text`, by brace matching outside
/// strings, chars and comments.
fn functions(text: &str) -> Vec<(String, usize, usize)> {
    let lines: Vec<&str> = text.lines().collect();
    let code: Vec<String> = lines.iter().map(|l| strip_literals(l)).collect();
    let mut found = Vec::new();
    let mut i = 0;
    while i < code.len() {
        let Some(name) = fn_name(&code[i]) else {
            i += 1;
            continue;
        };
        let (mut depth, mut opened, mut j) = (0i64, false, i);
        while j < code.len() {
            depth += code[j].matches('{').count() as i64 - code[j].matches('}').count() as i64;
            opened |= code[j].contains('{');
            if (opened && depth <= 0) || (!opened && code[j].trim_end().ends_with(';')) {
                break;
            }
            j += 1;
        }
        if opened {
            found.push((name, i + 1, j - i + 1));
            i = j + 1;
        } else {
            i += 1;
        }
    }
    found
}

/// The line without string and char literals and `//` comments (so braces inside them do not count).
fn strip_literals(line: &str) -> String {
    let mut out = String::new();
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' => {
                while let Some(d) = chars.next() {
                    match d {
                        '\\' => {
                            chars.next();
                        }
                        '"' => break,
                        _ => {}
                    }
                }
            }
            '\'' if chars.peek() == Some(&'{') || chars.peek() == Some(&'}') => {
                chars.next();
            }
            '/' if chars.peek() == Some(&'/') => break,
            _ => out.push(c),
        }
    }
    out
}

/// The name of the function a line declares, if it does.
fn fn_name(line: &str) -> Option<String> {
    let t = line.trim_start();
    let t = t
        .strip_prefix("pub(crate) ")
        .or_else(|| t.strip_prefix("pub(super) "))
        .or_else(|| t.strip_prefix("pub "))
        .unwrap_or(t);
    let t = t.strip_prefix("const ").unwrap_or(t);
    let t = t.strip_prefix("unsafe ").unwrap_or(t);
    let rest = t.strip_prefix("fn ")?;
    Some(
        rest.chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect(),
    )
}

#[test]
fn no_function_is_longer_than_a_screen() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut long = Vec::new();
    for path in files {
        let text = without_tests(&fs::read_to_string(&path).unwrap());
        for (name, line, len) in functions(&text) {
            let table = DATA_TABLES
                .iter()
                .any(|(file, f, _)| path.ends_with(file) && *f == name);
            if len > LONGEST_FUNCTION && !table {
                long.push(format!(
                    "{}:{line} `{name}` has {len} lines",
                    path.display()
                ));
            }
        }
    }
    assert!(
        long.is_empty(),
        "functions over {LONGEST_FUNCTION} lines (split them by stage):\n  {}",
        long.join("\n  ")
    );
}

#[test]
fn the_function_measure_counts_a_long_function_and_ignores_braces_in_strings() {
    let body: String = (0..90)
        .map(|i| format!("    let x{i} = \"{{\";\n"))
        .collect();
    let text =
        format!("fn short() {{\n}}\n\npub fn long() {{\n{body}}}\nconst fn c() -> u8 {{ 1 }}\n");
    let found = functions(&text);
    let names: Vec<(&str, usize)> = found.iter().map(|(n, _, l)| (n.as_str(), *l)).collect();
    assert_eq!(names, [("short", 2), ("long", 92), ("c", 1)]);
}

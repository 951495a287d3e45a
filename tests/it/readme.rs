//! The documentation's example sessions are real: every ```console block of README.md and docs/*.md is run
//! and its output compared with what the block shows, so the examples cannot drift from the tool.
//!
//! In a block, a line `$ coin-log ARGS` is a command (run in a fresh folder holding links to `datasets/` and
//! `schemas/`, one folder per block so later commands see earlier commands' files); the lines up to the next
//! command are its expected standard output, line for line. In an expected line, `…` stands for any text
//! (an elision, or a value that depends on the machine such as the wall time); a line that is only `…`
//! stands for any number of lines.
// Helpers outside #[test] functions read the repository's own files: a failure to read is a failed test.
#![allow(clippy::unwrap_used)]

use crate::support::record::exe;
use crate::support::repo;
use std::fs;
use std::path::Path;
use std::process::Command;

/// One command of a block and the output it should print.
#[derive(Debug)]
struct Example {
    source: String,
    args: Vec<String>,
    expected: Vec<String>,
}

/// The ```console blocks of a Markdown text, each as its list of examples.
fn console_blocks(source: &str, text: &str) -> Vec<Vec<Example>> {
    let mut blocks = Vec::new();
    let mut current: Option<Vec<Example>> = None;
    for (n, line) in text.lines().enumerate() {
        let fence = line.trim_start();
        match &mut current {
            None if fence == "```console" => current = Some(Vec::new()),
            None => {}
            Some(block) if fence == "```" => {
                blocks.push(std::mem::take(block));
                current = None;
            }
            Some(block) => match line.strip_prefix("$ ") {
                Some(command) => {
                    let mut words = command.split_whitespace().map(str::to_string);
                    assert_eq!(
                        words.next().as_deref(),
                        Some("coin-log"),
                        "{source}:{}: example commands start with `coin-log`",
                        n + 1
                    );
                    block.push(Example {
                        source: format!("{source}:{}", n + 1),
                        args: words.collect(),
                        expected: Vec::new(),
                    });
                }
                None => match block.last_mut() {
                    Some(example) => example.expected.push(line.to_string()),
                    None => panic!("{source}:{}: output before any `$ coin-log` line", n + 1),
                },
            },
        }
    }
    blocks
}

/// Whether `actual` matches `expected`, where `…` in `expected` stands for any text.
fn line_matches(expected: &str, actual: &str) -> bool {
    let parts: Vec<&str> = expected.trim_end().split('…').collect();
    let actual = actual.trim_end();
    let (first, rest) = (parts[0], &parts[1..]);
    let Some(mut tail) = actual.strip_prefix(first) else {
        return false;
    };
    for (i, part) in rest.iter().enumerate() {
        let last = i + 1 == rest.len();
        if last {
            return tail.ends_with(part);
        }
        match tail.find(part) {
            Some(at) => tail = &tail[at + part.len()..],
            None => return false,
        }
    }
    tail.is_empty()
}

/// Whether the lines match, a lone `…` line standing for any number of lines.
fn lines_match(expected: &[String], actual: &[&str]) -> bool {
    match expected.split_first() {
        None => actual.is_empty(),
        Some((e, rest)) if e.trim() == "…" => {
            (0..=actual.len()).any(|skip| lines_match(rest, &actual[skip..]))
        }
        Some((e, rest)) => {
            !actual.is_empty() && line_matches(e, actual[0]) && lines_match(rest, &actual[1..])
        }
    }
}

fn documents() -> Vec<(String, String)> {
    let root = repo();
    let mut docs = vec![("README.md".to_string(), root.join("README.md"))];
    let mut extra: Vec<_> = fs::read_dir(root.join("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    extra.sort();
    for p in extra {
        let name = format!("docs/{}", p.file_name().unwrap().to_string_lossy());
        docs.push((name, p));
    }
    docs.into_iter()
        .map(|(name, p)| (name, fs::read_to_string(p).unwrap()))
        .collect()
}

fn link(from: &Path, to: &Path) {
    #[cfg(unix)]
    std::os::unix::fs::symlink(from, to).unwrap();
    #[cfg(not(unix))]
    let _ = (from, to);
}

#[test]
fn every_console_example_in_the_docs_prints_what_it_shows() {
    let mut run = 0;
    for (name, text) in documents() {
        for block in console_blocks(&name, &text) {
            let dir = tempfile::tempdir().unwrap();
            link(&repo().join("datasets"), &dir.path().join("datasets"));
            link(&repo().join("schemas"), &dir.path().join("schemas"));
            for example in block {
                let out = Command::new(exe())
                    .args(&example.args)
                    .current_dir(dir.path())
                    .output()
                    .unwrap();
                let stdout = String::from_utf8_lossy(&out.stdout);
                let actual: Vec<&str> = stdout.lines().collect();
                assert!(
                    lines_match(&example.expected, &actual),
                    "{}: `coin-log {}` printed (exit {:?}):\n{stdout}\nstderr:\n{}\nbut the document shows:\n{}",
                    example.source,
                    example.args.join(" "),
                    out.status.code(),
                    String::from_utf8_lossy(&out.stderr),
                    example.expected.join("\n")
                );
                run += 1;
            }
        }
    }
    println!("{run} documented commands run");
    assert!(
        run >= 2,
        "the README's record and verify examples are console blocks"
    );
}

#[test]
fn the_matcher_rejects_a_changed_value_and_a_missing_line() {
    assert!(line_matches(
        "file  x.mcap (1.1 MiB)",
        "file  x.mcap (1.1 MiB)"
    ));
    assert!(line_matches(
        "wall time  … s (… messages/s)",
        "wall time  0.03 s (99 messages/s)"
    ));
    assert!(line_matches(
        "energy  pass  1e-16  …",
        "energy  pass  1e-16  drift is ..."
    ));
    // Negative controls: a value the tool does not print, a missing line, an extra line.
    assert!(!line_matches(
        "file  x.mcap (1.2 MiB)",
        "file  x.mcap (1.1 MiB)"
    ));
    let expected = vec!["a".to_string(), "b".to_string()];
    assert!(lines_match(&expected, &["a", "b"]));
    assert!(!lines_match(&expected, &["a"]));
    assert!(!lines_match(&expected, &["a", "b", "c"]));
    let with_gap = vec!["a".to_string(), "…".to_string(), "c".to_string()];
    assert!(lines_match(&with_gap, &["a", "x", "y", "c"]));
    assert!(!lines_match(&with_gap, &["a", "x"]));
}

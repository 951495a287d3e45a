//! The documentation's example sessions are real: every ```console block of README.md and docs/*.md is run
//! by trycmd, and what each command prints is compared with what the block shows, so the examples cannot
//! drift from the tool.
//!
//! In a block, a line `$ coin-log ARGS` is a command, run in a fresh folder per block (holding links to
//! `datasets/` and `schemas/`; later commands of a block see earlier commands' files). The lines up to the
//! next command are its standard output and error, line for line, and it must exit 0 (unless a line
//! `? CODE` follows the command); they end with an empty line, trycmd's mark of the last line's newline.
//! In an expected line `[..]` stands for any text (an elision, or a value that depends on the machine
//! such as the wall time); a line `...` stands for any number of lines.
// Helpers outside #[test] functions read the repository's own files: a failure to read is a failed test.
#![allow(clippy::unwrap_used)]

use crate::support::record::exe;
use crate::support::repo;
use std::fs;
use std::path::Path;
use std::time::Duration;

/// README.md, then docs/*.md sorted: (name, text).
fn documents() -> Vec<(String, String)> {
    let mut names = vec!["README.md".to_string()];
    let mut docs: Vec<String> = fs::read_dir(repo().join("docs"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| name.ends_with(".md"))
        .map(|name| format!("docs/{name}"))
        .collect();
    docs.sort();
    names.extend(docs);
    names
        .into_iter()
        .map(|name| (name.clone(), fs::read_to_string(repo().join(name)).unwrap()))
        .collect()
}

/// Writes each ```console block of the document `name` to `dir` as `<name>-<line>.md` (`/` and `.` of the
/// name as `-`), every other line of the document left blank (so trycmd's line numbers are the
/// document's), with its working folder `<name>-<line>.in/`. Returns how many commands the blocks hold.
fn write_blocks(name: &str, text: &str, dir: &Path) -> usize {
    let lines: Vec<&str> = text.lines().collect();
    let (mut commands, mut open) = (0, None);
    for (n, line) in lines.iter().enumerate() {
        match (open, line.trim()) {
            (None, "```console") => open = Some(n),
            (Some(_), l) if l.starts_with("$ ") => {
                // trycmd would skip a program it does not know.
                assert!(
                    l.starts_with("$ coin-log "),
                    "{name}:{}: example commands start with `coin-log`",
                    n + 1
                );
                commands += 1;
            }
            (Some(first), "```") => {
                let indent = lines[first].len() - lines[first].trim_start().len();
                let block: String = (0..lines.len())
                    .map(|i| match lines[i].get(indent..) {
                        Some(l) if (first..=n).contains(&i) => format!("{l}\n"),
                        _ => "\n".to_string(),
                    })
                    .collect();
                let stem = format!("{}-{}", name.replace(['/', '.'], "-"), first + 1);
                fs::write(dir.join(format!("{stem}.md")), block).unwrap();
                let folder = dir.join(format!("{stem}.in"));
                fs::create_dir(&folder).unwrap();
                for shared in ["datasets", "schemas"] {
                    std::os::unix::fs::symlink(repo().join(shared), folder.join(shared)).unwrap();
                }
                open = None;
            }
            _ => {}
        }
    }
    commands
}

/// Runs the blocks written in `dir` with trycmd: each wrong output is shown on stderr, and the run panics
/// if there was one.
fn run_blocks(dir: &Path) {
    trycmd::TestCases::new()
        .register_bin("coin-log", exe())
        // A hang detector for each command, never a speed test.
        .timeout(Duration::from_secs(60))
        .case(dir.join("*.md"))
        .run();
}

#[test]
fn every_console_example_in_the_docs_prints_what_it_shows() {
    let dir = tempfile::tempdir().unwrap();
    let mut commands = 0;
    for (name, text) in documents() {
        commands += write_blocks(&name, &text, dir.path());
    }
    println!("{commands} documented commands");
    assert!(
        commands >= 2,
        "the README's record and verify examples are console blocks"
    );
    run_blocks(dir.path());
}

/// The negative control: the README's first example with a value changed (the last digit of its first
/// line with a digit), with its last line missing, and with a line added each fail.
#[test]
fn an_example_with_a_changed_missing_or_extra_line_fails() {
    let (_, readme) = &documents()[0];
    let start = readme.find("```console\n").unwrap();
    let end = start + readme[start..].find("\n\n```\n").unwrap();
    let block: Vec<String> = readme[start..end].lines().map(str::to_string).collect();
    let (command, output) = (&block[1], &block[2..]);
    assert!(output.iter().all(|l| !l.starts_with("$ ")), "one command");
    let mut changed = output.to_vec();
    let line = changed
        .iter_mut()
        .find(|l| !l.contains("[..]") && l.contains(|c: char| c.is_ascii_digit()))
        .unwrap();
    let at = line.rfind(|c: char| c.is_ascii_digit()).unwrap();
    let digit = (line.as_bytes()[at] - b'0' + 1) % 10;
    line.replace_range(at..=at, &digit.to_string());
    let missing = output[..output.len() - 1].to_vec();
    let extra = [output, &["extra".to_string()]].concat();
    let dir = tempfile::tempdir().unwrap();
    for (i, lines) in [changed, missing, extra].iter().enumerate() {
        let text = format!("```console\n{command}\n{}\n\n```\n", lines.join("\n"));
        write_blocks(&format!("wrong-{i}"), &text, dir.path());
    }
    let failed = std::panic::catch_unwind(|| run_blocks(dir.path())).unwrap_err();
    assert_eq!(*failed.downcast::<String>().unwrap(), "3 of 3 tests failed");
}

//! The committed datasets: each `coin-log record` line of `datasets/README.md` re-run into a
//! temporary folder gives the committed file byte for byte; the five required scenes are there; every
//! `.mcap` in `datasets/` is listed; the whole set stays small.
//!
//! On a mismatch after an intended change of the output, run `scripts/regenerate-datasets`.

// Helpers outside #[test] functions panic on any failure by design.
#![allow(clippy::unwrap_used)]

use crate::support::record::coin_log;
use crate::support::repo;
use std::collections::BTreeSet;
use std::path::PathBuf;

/// (output path as written, arguments after `coin-log`) of each `coin-log record` line of the README.
fn commands() -> Vec<(String, Vec<String>)> {
    let readme = std::fs::read_to_string(repo().join("datasets/README.md")).unwrap();
    readme
        .lines()
        .filter(|l| l.starts_with("coin-log record "))
        .map(|l| {
            let args: Vec<String> = l.split_whitespace().skip(1).map(String::from).collect();
            let out = args
                .iter()
                .position(|a| a == "-o")
                .and_then(|i| args.get(i + 1))
                .unwrap_or_else(|| panic!("`{l}` has no `-o FILE`"))
                .clone();
            (out, args)
        })
        .collect()
}

#[test]
fn the_readme_lists_the_five_required_datasets_and_every_file_in_the_folder() {
    let listed: BTreeSet<String> = commands().into_iter().map(|(out, _)| out).collect();
    for name in [
        "circle-plus",
        "centre-fixed",
        "wobble",
        "high-spin",
        "five-hundred-yen",
    ] {
        assert!(
            listed.contains(&format!("datasets/{name}.mcap")),
            "datasets/README.md has no command for {name}"
        );
    }
    let mut total = 0;
    for entry in std::fs::read_dir(repo().join("datasets")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "mcap") {
            let name = format!("datasets/{}", path.file_name().unwrap().to_string_lossy());
            assert!(
                listed.contains(&name),
                "{name} is not listed in datasets/README.md"
            );
            total += std::fs::metadata(&path).unwrap().len();
        }
    }
    for out in &listed {
        assert!(
            repo().join(out).exists(),
            "{out} is listed but not committed: run scripts/regenerate-datasets"
        );
    }
    println!(
        "{} datasets, {total} bytes in all (limit 8 MB)",
        listed.len()
    );
    assert!(
        total < 8_000_000,
        "datasets should stay a few MB in all: {total} bytes"
    );
}

#[test]
fn re_recording_each_dataset_gives_the_committed_bytes() {
    let dir = tempfile::tempdir().unwrap();
    for (out, args) in commands() {
        let fresh = dir.path().join(PathBuf::from(&out).file_name().unwrap());
        let args: Vec<String> = args
            .iter()
            .map(|a| {
                if *a == out {
                    fresh.display().to_string()
                } else {
                    a.clone()
                }
            })
            .collect();
        let run = coin_log(&repo(), &args);
        assert!(
            run.status.success(),
            "coin-log {} failed:\n{}",
            args.join(" "),
            String::from_utf8_lossy(&run.stderr)
        );
        let committed = std::fs::read(repo().join(&out)).unwrap();
        let again = std::fs::read(&fresh).unwrap();
        println!(
            "{out}: committed {} bytes, re-recorded {} bytes",
            committed.len(),
            again.len()
        );
        assert!(
            committed == again,
            "{out}: re-recording gives different bytes; if the change is intended run scripts/regenerate-datasets"
        );
    }
}

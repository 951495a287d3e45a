//! What the command line says agrees with what it does (the help's bounds and Protobuf sizes: adversary.rs):
//! `verify --help` names every check; a description is one line of bounded length; tiny numbers print
//! short; control characters in paths are escaped in messages; `--help` into a full disk is an error.
// Helpers outside #[test] functions panic on failure too: a failed step is a failed test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use crate::support::record::{coin_log, coin_log_text};
use coin_log::verify::CheckId;

#[test]
fn verify_help_names_every_check() {
    let (_, help, _) = coin_log_text(&["verify", "--help"]);
    for id in CheckId::ALL {
        assert!(help.contains(id.name()), "`{}` in verify --help", id.name());
    }
}

/// A description is one line (no control characters) of at most 1000 characters: a newline or a longer
/// one is refused naming the key; the longest allowed is accepted.
#[test]
fn a_description_is_one_line_of_bounded_length() {
    let dir = tempfile::tempdir().unwrap();
    let max = coin_log::scene::DESCRIPTION_MAX_CHARS;
    for (description, ok, needle) in [
        ("two\nlines".to_string(), false, "a description is one line"),
        ("tab\there".to_string(), false, "control character"),
        ("é".repeat(max), true, ""),
        (
            "x".repeat(max + 1),
            false,
            "characters long, more than the 1000",
        ),
    ] {
        let set = format!("description={}", toml::Value::String(description.clone()));
        let out = coin_log(
            dir.path(),
            &["record", "wobble", "--dry-run", "--set", &set],
        );
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.success(), ok, "{description:?}: {err}");
        assert!(
            ok || (err.contains("`description`") && err.contains(needle)),
            "{err}"
        );
    }
}

/// Tiny values print in exponent form, never as hundreds of digits.
#[test]
fn tiny_values_print_short() {
    let (code, out, err) = coin_log_text(&["analyse", "wobble", "--set", "initial.theta=1e-300"]);
    assert_eq!(code, 0, "{err}");
    println!("{out}");
    assert!(out.contains("θ = 1e-300"), "{out}");
    assert!(
        out.lines().all(|l| l.len() < 200),
        "no line of hundreds of digits: {out}"
    );
}

/// A path with a newline and an escape sequence is printed escaped in every message.
#[test]
fn control_characters_in_paths_are_escaped_in_messages() {
    let dir = tempfile::tempdir().unwrap();
    let name = "evil\n\u{1b}[31mred.mcap";
    for args in [
        vec!["verify", name],
        vec!["info", name],
        vec!["plot", name],
        vec!["export", name],
        vec![
            "record",
            "wobble",
            "--duration",
            "1",
            "-o",
            "no\nfolder/x.mcap",
        ],
    ] {
        let out = coin_log(dir.path(), &args);
        let err = String::from_utf8_lossy(&out.stderr);
        println!("{args:?}: {err}");
        assert!(!out.status.success());
        assert!(
            !err.contains('\u{1b}'),
            "{args:?}: the escape character is escaped: {err}"
        );
        assert_eq!(
            err.trim_end().lines().count(),
            1,
            "{args:?}: one line: {err}"
        );
        assert!(err.contains("\\n"), "{args:?}: {err}");
    }
}

/// `--help` and `--version` into a full disk: an error and exit 1, like any other output.
#[test]
fn help_into_a_full_disk_exits_non_zero() {
    for args in [&["--help"][..], &["--version"], &["record", "--help"]] {
        let out = std::process::Command::new(crate::support::record::exe())
            .args(args)
            .stdout(std::fs::File::create("/dev/full").unwrap())
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains("No space left on device"), "{err}");
    }
    let (code, out, _) = coin_log_text(&["--help"]);
    assert_eq!(code, 0, "negative control: --help into a pipe");
    assert!(out.contains("Usage"));
}

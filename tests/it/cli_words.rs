//! What the command line says agrees with what it does: each numeric bound `record --help` states is
//! accepted and the next value beyond it refused; `verify --help` names every check; a description is
//! one line of bounded length; tiny numbers print short; control characters in paths are escaped in
//! messages; `--help` into a full disk is an error.
// Helpers outside #[test] functions panic on failure too: a failed step is a failed test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use crate::support::record::{coin_log, coin_log_text};
use coin_log::scene::limits::max_rate;
use coin_log::verify::CheckId;

/// A coin upright at rest (M = a = g = 1): W = max(|ω|, |φ̇|, |ψ̇|, 1/τ) = 1 exactly, so the bounds
/// stated in terms of W are plain numbers.
const AT_REST: &str = "[body]\nmass = 1.0\nradius = 1.0\ngravity = 1.0\nshape = \"thin-disk\"\n\
[initial]\ntheta = 0.0\nomega = [0.0, 0.0, 0.0]\n[run]\nduration = 1.0\n";

/// `record --dry-run` of the scene at rest with `flags`: the exit code and stderr.
fn dry_run(dir: &std::path::Path, flags: &[String]) -> (i32, String) {
    let mut args = vec!["record".to_string(), "rest.toml".into(), "--dry-run".into()];
    args.extend_from_slice(flags);
    let out = coin_log(dir, &args);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    (out.status.code().unwrap(), err)
}

fn flags(pairs: &[(&str, String)]) -> Vec<String> {
    pairs
        .iter()
        .flat_map(|(flag, value)| [(*flag).to_string(), value.clone()])
        .collect()
}

/// Each bound `record --help` states, as (what the help says, the flags at the bound, the flags just
/// beyond it, the key the refusal names). "Just beyond" is the next double for exact bounds and the next
/// value at the stated precision for a rounded one (2.221e-15 stands for 10·2⁻⁵² = 2.2204e-15).
#[allow(clippy::type_complexity)]
fn stated_bounds() -> Vec<(
    &'static str,
    Vec<(&'static str, String)>,
    Vec<(&'static str, String)>,
    &'static str,
)> {
    let up = |x: f64| f64::from_bits(x.to_bits() + 1);
    let down = |x: f64| f64::from_bits(x.to_bits() - 1);
    let rk4 = || ("--integrator", "rk4".to_string());
    // A step equal to the sampling interval is used as given (no rounding).
    let step = |h: f64| {
        vec![
            rk4(),
            ("--step", h.to_string()),
            ("--rate", (1.0 / h).to_string()),
        ]
    };
    let rate = max_rate(1.0);
    vec![
        (
            "2.221e-15",
            vec![("--rtol", "2.221e-15".into())],
            vec![("--rtol", "2.220e-15".into())],
            "run.rtol",
        ),
        (
            "to 1e-3",
            vec![("--rtol", "1e-3".into())],
            vec![("--rtol", up(1e-3).to_string())],
            "run.rtol",
        ),
        (
            "at most 1e-3·min(1, a, 1/τ)",
            vec![("--atol", "1e-3".into())],
            vec![("--atol", up(1e-3).to_string())],
            "run.atol",
        ),
        ("step·W ≤ 0.1778", step(0.1778), step(0.1779), "run.step"),
        (
            "T·W ≤ 1e10",
            vec![("--duration", "1e10".into()), ("--rate", "1e-3".into())],
            vec![
                ("--duration", up(1e10).to_string()),
                ("--rate", "1e-3".into()),
            ],
            "run.duration",
        ),
        (
            "at most 1/(1e-9 + 3·2⁻⁵²·T)",
            vec![("--rate", rate.to_string())],
            vec![("--rate", up(rate).to_string())],
            "run.rate",
        ),
        (
            "Duration in the scene's time unit, ≥ 1e-9",
            vec![("--duration", "1e-9".into())],
            vec![("--duration", down(1e-9).to_string())],
            "run.duration",
        ),
        (
            "Most integrator steps, ≥ 1",
            vec![("--max-steps", "1".into())],
            vec![("--max-steps", "0".into())],
            "run.max_steps",
        ),
        (
            "duration/step ≤ --max-steps",
            vec![rk4(), ("--max-steps", "1000".into())],
            vec![rk4(), ("--max-steps", "999".into())],
            "run.step",
        ),
    ]
}

#[test]
fn every_bound_record_help_states_is_accepted_and_the_next_value_refused() {
    let (_, help, _) = coin_log_text(&["record", "--help"]);
    let help = help.split_whitespace().collect::<Vec<_>>().join(" ");
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("rest.toml"), AT_REST).unwrap();
    for (said, at, beyond, key) in stated_bounds() {
        assert!(
            help.contains(said),
            "`record --help` states {said:?}: {help}"
        );
        let (code, err) = dry_run(dir.path(), &flags(&at));
        assert_eq!(code, 0, "{said}: {at:?} is inside the bound: {err}");
        let (code, err) = dry_run(dir.path(), &flags(&beyond));
        println!("{said}: {beyond:?} → {err}");
        assert_eq!(code, 1, "{said}: {beyond:?} is beyond the bound");
        assert!(err.contains(key), "{said}: the refusal names {key}: {err}");
    }
    // The measured size of Protobuf files, not "half".
    assert!(!help.contains("half the size"), "{help}");
    assert!(help.contains("0.9× JSON's size with zstd"), "{help}");
}

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

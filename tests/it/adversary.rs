//! Issue 25 as an adversary would try it, one test per class: reproduction that reproduces (`info --scene`
//! names every flag of the bytes), help texts whose numeric bounds are exactly the bounds enforced, scene
//! text without hundreds of digits, and writers that refuse what an output may not be before any work.
// Helpers outside #[test] functions panic on failure too: a failed step is a failed test.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::cast_precision_loss)]

use crate::support::mkfifo;
use crate::support::record::{coin_log, coin_log_text};
use std::path::Path;

/// The command line `info --scene` prints, with its placeholders for the scene and the output filled in.
fn reproduction(text: &str, scene: &Path, out: &Path) -> Vec<String> {
    let line = text
        .lines()
        .find_map(|l| l.strip_prefix("#     coin-log record "))
        .unwrap_or_else(|| panic!("no command line in:\n{text}"));
    line.split_whitespace()
        .map(|w| match w {
            "SCENE.toml" => scene.display().to_string(),
            "OUT.mcap" => out.display().to_string(),
            w => w.to_string(),
        })
        .collect()
}

/// For every encoding × compression, the command `info --scene` prints, run on the text it prints, writes
/// the same bytes; the bare `record` of that text (what the old comment offered for Protobuf) does not,
/// except for the defaults (the negative control).
#[test]
fn info_scene_prints_the_command_that_writes_the_same_bytes_for_every_encoding_and_compression() {
    let dir = tempfile::tempdir().unwrap();
    for encoding in coin_log::format::Encoding::NAMES {
        for compression in coin_log_mcap::Compression::NAMES {
            let original = dir.path().join(format!("{encoding}-{compression}.mcap"));
            let out = coin_log(
                dir.path(),
                &[
                    "record",
                    "wobble",
                    "--duration",
                    "2",
                    "--channels",
                    "omega,angles,energy,tf",
                    "--set",
                    "initial.theta=1e-300",
                    "--encoding",
                    encoding,
                    "--compression",
                    compression,
                    "-o",
                    original.to_str().unwrap(),
                ],
            );
            assert!(
                out.status.success(),
                "{}",
                String::from_utf8_lossy(&out.stderr)
            );
            let (code, text, err) = coin_log_text(&["info", original.to_str().unwrap(), "--scene"]);
            assert_eq!(code, 0, "{err}");
            let scene = dir.path().join(format!("{encoding}-{compression}.toml"));
            std::fs::write(&scene, &text).unwrap();
            let again = dir
                .path()
                .join(format!("again-{encoding}-{compression}.mcap"));
            let mut args = vec!["record".to_string()];
            args.extend(reproduction(&text, &scene, &again));
            let out = coin_log(dir.path(), &args);
            assert!(
                out.status.success(),
                "{args:?}: {}",
                String::from_utf8_lossy(&out.stderr)
            );
            let same = std::fs::read(&original).unwrap() == std::fs::read(&again).unwrap();
            println!(
                "{encoding:>8} × {compression:<4}: {args:?} → {}",
                if same { "identical" } else { "DIFFERENT" }
            );
            assert!(
                same,
                "{encoding} × {compression}: the printed command line reproduces\n{text}"
            );
            let bare = dir
                .path()
                .join(format!("bare-{encoding}-{compression}.mcap"));
            let out = coin_log(
                dir.path(),
                &[
                    "record",
                    scene.to_str().unwrap(),
                    "-o",
                    bare.to_str().unwrap(),
                ],
            );
            assert!(out.status.success());
            let defaults = *encoding == "json" && *compression == "zstd";
            assert_eq!(
                std::fs::read(&original).unwrap() == std::fs::read(&bare).unwrap(),
                defaults,
                "{encoding} × {compression}: without the printed flags the bytes differ unless both are defaults"
            );
        }
    }
}

/// A coin upright at rest (M = a = g = 1): W = max(|ω|, |φ̇|, |ψ̇|, 1/τ) = 1 exactly, so the bounds
/// stated in terms of W are plain numbers.
const AT_REST: &str = "[body]\nmass = 1.0\nradius = 1.0\ngravity = 1.0\nshape = \"thin-disk\"\n\
[initial]\ntheta = 0.0\nomega = [0.0, 0.0, 0.0]\n[run]\nduration = 1.0\n";

/// The number the help states right after `before` (up to a space, `·` or `)`), as typed.
fn stated(help: &str, before: &str) -> f64 {
    let at = help
        .find(before)
        .unwrap_or_else(|| panic!("the help states {before:?}: {help}"))
        + before.len();
    let word: String = help[at..]
        .chars()
        .take_while(|c| !" ·)(×,".contains(*c))
        .collect();
    word.parse()
        .unwrap_or_else(|e| panic!("{before:?} is followed by a number, not {word:?}: {e}"))
}

/// Flags with their values, as `--flag value` pairs.
type Flags = Vec<(&'static str, f64)>;

/// A rate whose sample interval 1/rate is exactly `h`, so that a step `h` is used as given (it divides
/// the interval once): the step bound is then tested on the step itself.
fn rate_for_interval(h: f64) -> f64 {
    let mut rate = 1.0 / h;
    for _ in 0..64 {
        match (1.0 / rate).total_cmp(&h) {
            std::cmp::Ordering::Equal => return rate,
            std::cmp::Ordering::Less => rate = rate.next_down(),
            std::cmp::Ordering::Greater => rate = rate.next_up(),
        }
    }
    panic!("no rate has the interval {h}")
}

/// Each numeric bound that `record --help` and `live --help` state (printed there from the constants
/// scene::limits enforces) is accepted, and the next double beyond it refused naming the key; the bounds
/// are parsed from the help text itself, so a rounded or stale number fails. `live` shares the flags.
#[test]
fn every_stated_bound_is_accepted_and_the_next_double_beyond_it_refused() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("rest.toml"), AT_REST).unwrap();
    let dry_run = |flags: &[(&str, f64)], integrator: &str| {
        let mut args = vec![
            "record",
            "rest.toml",
            "--dry-run",
            "--integrator",
            integrator,
        ]
        .into_iter()
        .map(String::from)
        .collect::<Vec<_>>();
        for (flag, value) in flags {
            args.extend([(*flag).to_string(), format!("{value:e}")]);
        }
        let out = coin_log(dir.path(), &args);
        (
            out.status.code().unwrap(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    };
    // `live` is a command only with its cargo feature (plain `cargo test` builds without it).
    let commands: &[&str] = if cfg!(feature = "live") {
        &["record", "live"]
    } else {
        &["record"]
    };
    for &command in commands {
        let (_, help, _) = coin_log_text(&[command, "--help"]);
        let help = help.split_whitespace().collect::<Vec<_>>().join(" ");
        let rtol_min = stated(&help, "Relative tolerance of adaptive methods, ");
        let rtol_max = stated(&help, "(ten units of rounding, 10·2⁻⁵²) to ");
        let atol_max = stated(&help, "Absolute tolerance of adaptive methods, at most ");
        let step_max = stated(&help, "then step·W ≤ ");
        let radians = stated(&help, "with T·W ≤ ");
        let duration_min = stated(&help, "Duration in the scene's time unit, ≥ ");
        assert!(help.contains("at most 1/(1e-9 + 3·2⁻⁵²·T)"), "{help}");
        let rate_max = coin_log::scene::limits::max_rate(1.0);
        // (what, integrator, flags at the bound, flags just beyond it, the key the refusal names)
        let cases: [(&str, &str, Flags, Flags, &str); 7] = [
            (
                "rtol min",
                "dop853",
                vec![("--rtol", rtol_min)],
                vec![("--rtol", rtol_min.next_down())],
                "run.rtol",
            ),
            (
                "rtol max",
                "dop853",
                vec![("--rtol", rtol_max)],
                vec![("--rtol", rtol_max.next_up())],
                "run.rtol",
            ),
            (
                "atol max",
                "dop853",
                vec![("--atol", atol_max)],
                vec![("--atol", atol_max.next_up())],
                "run.atol",
            ),
            (
                "step max",
                "rk4",
                vec![
                    ("--step", step_max),
                    ("--rate", rate_for_interval(step_max)),
                ],
                vec![
                    ("--step", step_max.next_up()),
                    ("--rate", rate_for_interval(step_max.next_up())),
                ],
                "run.step",
            ),
            (
                "duration max",
                "dop853",
                vec![("--duration", radians), ("--rate", 1e-3)],
                vec![("--duration", radians.next_up()), ("--rate", 1e-3)],
                "run.duration",
            ),
            (
                "duration min",
                "dop853",
                vec![("--duration", duration_min)],
                vec![("--duration", duration_min.next_down())],
                "run.duration",
            ),
            (
                "rate max",
                "dop853",
                vec![("--rate", rate_max)],
                vec![("--rate", rate_max.next_up())],
                "run.rate",
            ),
        ];
        for (what, integrator, at, beyond, key) in cases {
            let (code, err) = dry_run(&at, integrator);
            assert_eq!(
                code, 0,
                "{command} --help, {what}: {at:?} is at the bound: {err}"
            );
            let (code, err) = dry_run(&beyond, integrator);
            println!(
                "{command} --help, {what}: {at:?} accepted, {beyond:?} → {}",
                err.trim()
            );
            assert_eq!(
                code, 1,
                "{command} --help, {what}: {beyond:?} is beyond the bound"
            );
            assert!(err.contains(key), "{what}: the refusal names {key}: {err}");
        }
    }
}

/// Every `bench` refuses a link, a named pipe or a folder where one of its result files goes before it
/// measures anything (it used to find out after minutes of work), and leaves what is there untouched.
#[test]
fn bench_refuses_what_is_in_the_way_of_its_results_before_any_work() {
    use crate::support::record::coin_log_within;
    use std::time::Duration;
    let dir = tempfile::tempdir().unwrap();
    let victim = dir.path().join("victim");
    std::fs::write(&victim, "precious").unwrap();
    for (bench, file) in [
        ("precision", "precision.csv"),
        ("stability", "stability.csv"),
        ("throughput", "throughput.csv"),
        ("euler", "euler.svg"),
        ("sweep", "sweep.csv"),
    ] {
        for (what, needle) in [
            ("link", "is a symbolic link"),
            ("pipe", "is a named pipe"),
            ("folder", "is a folder"),
        ] {
            let out = dir.path().join(format!("{bench}-{what}"));
            std::fs::create_dir(&out).unwrap();
            let at = out.join(file);
            match what {
                "link" => std::os::unix::fs::symlink(&victim, &at).unwrap(),
                "pipe" => mkfifo(&at),
                _ => std::fs::create_dir(&at).unwrap(),
            }
            let (code, _, err) = coin_log_within(
                Duration::from_secs(20),
                &["bench", bench, "--out", out.to_str().unwrap()],
            );
            println!(
                "bench {bench}, {what} at {file}: exit {code}: {}",
                err.trim()
            );
            assert_eq!(code, 1, "bench {bench}: {err}");
            assert!(err.contains(needle), "bench {bench}, {what}: {err}");
            assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious");
        }
    }
}

/// The Protobuf-to-JSON size ratios `record --help` states are those of `wobble` (the built-in scene,
/// every default) recorded both ways, to ±0.05, for each compression; the old "half the size" and "0.6×
/// uncompressed" fail this.
#[test]
fn record_help_states_the_measured_protobuf_size_for_each_compression() {
    let (_, help, _) = coin_log_text(&["record", "--help"]);
    let help = help.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(!help.contains("half the size"), "{help}");
    let dir = tempfile::tempdir().unwrap();
    for (compression, said) in [
        ("zstd", "the file is about "),
        ("lz4", "JSON's size with zstd, "),
        ("none", "× with lz4, "),
    ] {
        let claim = stated(&help, said);
        let size = |encoding: &str| {
            let file = dir.path().join(format!("{encoding}-{compression}.mcap"));
            let out = coin_log(
                dir.path(),
                &[
                    "record",
                    "wobble",
                    "--encoding",
                    encoding,
                    "--compression",
                    compression,
                    "-o",
                    file.to_str().unwrap(),
                ],
            );
            assert!(out.status.success());
            std::fs::metadata(&file).unwrap().len() as f64
        };
        let ratio = size("protobuf") / size("json");
        println!("{compression}: Protobuf/JSON = {ratio:.3}, help says {claim}");
        assert!(
            (ratio - claim).abs() <= 0.05,
            "{compression}: measured {ratio:.3}, help says {claim}×"
        );
    }
}

/// The scene text printed for people (`record --dry-run`, `info --scene`) writes tiny and huge values in
/// exponent form, never as hundreds of digits (the `toml` crate's positional form, which stays in the
/// file's metadata), and reads back to the same scene: the dry-run's text re-recorded equals the file.
#[test]
fn printed_scenes_write_tiny_values_short() {
    let dir = tempfile::tempdir().unwrap();
    let set = [
        "--set",
        "initial.theta=1e-300",
        "--set",
        "body.thickness=1e-200",
        "--duration",
        "1",
    ];
    let run = |extra: &[&str]| {
        let mut args = vec!["record", "wobble"];
        args.extend_from_slice(&set);
        args.extend_from_slice(extra);
        let out = coin_log(dir.path(), &args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8(out.stdout).unwrap()
    };
    let dry = run(&["--dry-run"]);
    run(&["-o", "f.mcap"]);
    let (code, info, err) = coin_log_text(&[
        "info",
        dir.path().join("f.mcap").to_str().unwrap(),
        "--scene",
    ]);
    assert_eq!(code, 0, "{err}");
    for (what, text) in [("dry-run", &dry), ("info --scene", &info)] {
        println!("{what}:\n{text}");
        assert!(
            text.contains("theta = 1e-300") && text.contains("thickness = 1e-200"),
            "{what}: {text}"
        );
        assert!(
            text.lines().all(|l| l.len() < 200),
            "{what}: no line of hundreds of digits"
        );
    }
    std::fs::write(dir.path().join("dry.toml"), &dry).unwrap();
    let out = coin_log(dir.path(), &["record", "dry.toml", "-o", "g.mcap"]);
    assert!(out.status.success());
    assert!(
        std::fs::read(dir.path().join("f.mcap")).unwrap()
            == std::fs::read(dir.path().join("g.mcap")).unwrap()
    );
}

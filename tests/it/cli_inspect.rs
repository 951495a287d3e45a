//! The commands around recording: `record --dry-run` (the resolved scene and an estimate that real
//! recordings keep within its stated factor), the warning before a large recording, `scenes --json` and
//! `--show` with every default, shell completions and man pages that name every command, and `verify`'s
//! total line over several files.
// Helpers outside #[test] functions panic on failure too: a failed step is a failed test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use crate::support::record::{coin_log, coin_log_text, exe, listing, read_back, record_scene};
use coin_log::format::Channel;
use coin_log::record::estimate::ACCURACY;
use coin_log::scene::{self, presets, FlagOverrides, Scene};
use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};

/// The subcommands, as `coin-log --help` lists them.
const COMMANDS: [&str; 9] = [
    "record",
    "verify",
    "scenes",
    "bench",
    "info",
    "export",
    "plot",
    "completions",
    "man",
];

#[test]
fn dry_run_prints_the_resolved_scene_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = coin_log(
        dir.path(),
        &[
            "record",
            "wobble",
            "--dry-run",
            "--rate",
            "250",
            "--set",
            "initial.theta=0.4",
        ],
    );
    let text = String::from_utf8(out.stdout).unwrap();
    print!("{text}");
    assert_eq!(out.status.code(), Some(0));
    assert!(
        listing(dir.path()).is_empty(),
        "nothing written: {:?}",
        listing(dir.path())
    );
    // The output is a scene file: it resolves to the scene the flags make.
    let printed = Scene::from_file(&scene::parse_with_sets(&text, &[]).unwrap()).unwrap();
    let flags = FlagOverrides {
        rate: Some(250.0),
        ..FlagOverrides::default()
    };
    let sets = vec!["initial.theta=0.4".to_string()];
    let expected = scene::resolve(
        &scene::file_with_sets(&presets::preset("wobble").unwrap(), &sets).unwrap(),
        &flags,
    )
    .unwrap();
    assert_eq!(printed, expected);
    for key in [
        "rate = 250.0",
        "integrator = \"dop853\"",
        "rtol =",
        "atol =",
        "flat_margin =",
        "channels =",
    ] {
        assert!(text.contains(key), "`{key}` in the dry run");
    }
    // Every setting the integrator uses, none it ignores: dop853 has no fixed step.
    assert!(
        !text.contains("step ="),
        "no `step =` for dop853 in the dry run"
    );
    assert!(text.contains("7501 samples"), "30 × 250 + 1 samples");
    // A bad scene: the same errors as a real recording, exit 1, nothing written.
    let out = coin_log(
        dir.path(),
        &["record", "wobble", "--dry-run", "--rate", "0"],
    );
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--rate"));
    assert!(listing(dir.path()).is_empty());
}

/// The estimate against real recordings: messages exact for runs that complete, never fewer for runs
/// ended by an event; bytes within the stated factor for every compression.
#[test]
fn the_estimate_holds_within_its_factor_on_real_recordings() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&str, &[&str]); 6] = [
        ("wobble", &[]),
        ("circle-plus", &[]),
        ("high-spin", &[]),
        // Before its flat landing (t = 1.907): the run completes and the estimate is exact in messages.
        ("topple", &["--duration", "1.9"]),
        ("five-hundred-yen", &[]),
        ("long-horizon", &["--duration", "200"]),
    ];
    let mut worst: f64 = 1.0;
    for (name, extra) in cases {
        for (compression, encoding) in ["zstd", "lz4", "none"]
            .into_iter()
            .flat_map(|c| [(c, "json"), (c, "protobuf")])
        {
            let mut args = vec!["record", name, "--compression", compression];
            args.extend_from_slice(&["--encoding", encoding]);
            args.extend_from_slice(extra);
            let mut dry = args.clone();
            dry.extend(["--dry-run", "--json"]);
            let (code, out, err) = coin_log_text(&dry);
            assert_eq!(code, 0, "{err}");
            let estimate: serde_json::Value = serde_json::from_str(&out).unwrap();
            let path = record_scene(
                dir.path(),
                name,
                &[
                    &["--compression", compression, "--encoding", encoding][..],
                    extra,
                ]
                .concat(),
            );
            let bytes = std::fs::metadata(&path).unwrap().len() as f64;
            let file = read_back(&std::fs::read(&path).unwrap());
            let messages = file.messages.len() as u64;
            let ratio = estimate["estimated_bytes"].as_f64().unwrap() / bytes;
            println!(
                "{name:<17} {compression:<4} {encoding:<8} estimate {:>9} B, file {bytes:>9} B, ratio {ratio:.2}; messages {} vs {messages}",
                estimate["estimated_bytes"], estimate["messages"]
            );
            worst = worst.max(ratio).max(1.0 / ratio);
            assert!(
                (1.0 / ACCURACY..=ACCURACY).contains(&ratio),
                "{name} {compression} {encoding}: estimate/file = {ratio:.3}, outside the factor {ACCURACY}"
            );
            // The coin_log channels' counts are exact for a completed run; the Foxglove display topics
            // (track levels, table moves) are estimated, so the total is held to the size's factor.
            for (channel, count) in estimate["channels"].as_object().unwrap() {
                let c: Channel = channel.parse().unwrap();
                if c.message_type().is_some() {
                    let stored = file.on_topic(c.topic()).len() as u64;
                    assert_eq!(count.as_u64(), Some(stored), "{name}: {channel} messages");
                }
            }
            let estimated = estimate["messages"].as_u64().unwrap() as f64;
            let ratio = estimated / messages as f64;
            assert!(
                (1.0 / ACCURACY..=ACCURACY).contains(&ratio),
                "{name}: estimated {estimated} messages, file {messages}"
            );
        }
    }
    // A run ended by an event writes less than the estimate of its full duration.
    let (_, out, _) = coin_log_text(&["record", "topple", "--dry-run", "--json"]);
    let estimate: serde_json::Value = serde_json::from_str(&out).unwrap();
    let path = record_scene(dir.path(), "topple", &[]);
    let file = read_back(&std::fs::read(&path).unwrap());
    assert!(estimate["messages"].as_u64().unwrap() > file.messages.len() as u64);
    println!("worst factor {worst:.2} (allowed {ACCURACY})");
}

/// The dry run's samples are the recording's where the end falls off the grid: a rate slower than one
/// sample per duration (t = 0 and the end, 2 samples, was 1), an end within 2 ns of a grid point (which
/// gives way to the end, was counted apart) and one 100 ns past a grid point on a long grid (was taken
/// for the grid point).
#[test]
fn the_dry_run_counts_the_samples_of_ends_off_the_grid() {
    let dir = tempfile::tempdir().unwrap();
    for (duration, rate) in [
        ("1", "1e-10"),
        ("1.0000000015", "1"),
        ("100.0000001", "100"),
    ] {
        let args = [
            "record",
            "wobble",
            "--channels",
            "omega",
            "--duration",
            duration,
            "--rate",
            rate,
        ];
        let (code, out, err) = coin_log_text(&[&args[..], &["--dry-run", "--json"]].concat());
        assert_eq!(code, 0, "{err}");
        let estimate: serde_json::Value = serde_json::from_str(&out).unwrap();
        let path = record_scene(dir.path(), "wobble", &args[2..]);
        let file = read_back(&std::fs::read(&path).unwrap());
        let stored = file.on_topic("/coin/omega").len() as u64;
        assert_eq!(
            estimate["samples"].as_u64(),
            Some(stored),
            "--duration {duration} --rate {rate}"
        );
        assert_eq!(estimate["messages"].as_u64(), Some(stored));
    }
}

/// A recording estimated above 1 GiB warns on stderr before it starts (stopped right after the warning).
#[test]
fn a_recording_above_a_gibibyte_is_warned_about() {
    let dir = tempfile::tempdir().unwrap();
    let mut child = Command::new(exe())
        .args([
            "record",
            "long-horizon",
            "--rate",
            "1000",
            "--duration",
            "100000",
            "-o",
            "big.mcap",
        ])
        .current_dir(dir.path())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(child.stderr.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let _ = child.kill();
    let _ = child.wait();
    println!("{line}");
    assert!(
        line.starts_with("warning: this recording is estimated at"),
        "{line}"
    );
    assert!(line.contains("GiB"), "{line}");
    // A small recording does not warn.
    let (code, _, err) = coin_log_text(&["record", "circle-plus", "--dry-run"]);
    assert_eq!(code, 0);
    assert!(err.is_empty(), "{err}");
}

#[test]
fn scenes_json_lists_every_built_in_resolved() {
    let (code, out, err) = coin_log_text(&["scenes", "--json"]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let all = v.as_array().unwrap();
    assert_eq!(all.len(), presets::NAMES.len());
    for (entry, name) in all.iter().zip(presets::NAMES) {
        assert_eq!(entry["name"], name);
        let preset = presets::preset(name).unwrap();
        assert_eq!(entry["description"], preset.description.clone().unwrap());
        let file: scene::SceneFile = serde_json::from_value(entry["scene"].clone()).unwrap();
        assert_eq!(
            Scene::from_file(&file).unwrap(),
            Scene::from_file(&preset).unwrap(),
            "{name}"
        );
        let run = &entry["scene"]["run"];
        for key in ["duration", "rate", "integrator", "flat_margin"] {
            assert!(!run[key].is_null(), "{name}: run.{key} filled in");
        }
        // The settings the integrator uses are filled in, the others left out.
        let adaptive = matches!(run["integrator"].as_str(), Some("dop853" | "dopri5"));
        for (key, used) in [("rtol", adaptive), ("atol", adaptive), ("step", !adaptive)] {
            assert_eq!(
                !run[key].is_null(),
                used,
                "{name}: run.{key} filled in iff used"
            );
        }
        assert!(entry["scene"]["record"]["channels"].is_array());
        assert!(!entry["scene"]["body"]["thickness"].is_null());
    }
}

#[test]
fn scenes_show_prints_every_default() {
    for name in presets::NAMES {
        let (code, out, _) = coin_log_text(&["scenes", "--show", name]);
        assert_eq!(code, 0);
        for key in [
            "rate =",
            "integrator =",
            "flat_margin =",
            "thickness =",
            "channels =",
        ] {
            assert!(out.contains(key), "{name}: `{key}` in\n{out}");
        }
        crate::support::assert_uses_its_settings(name, &out);
        let file = scene::parse_with_sets(&out, &[]).unwrap();
        let resolved = Scene::from_file(&presets::preset(name).unwrap()).unwrap();
        assert_eq!(
            file,
            resolved.to_file(),
            "{name}: the resolved scene, written out"
        );
    }
}

/// The bash script completes past the command: a subcommand's flags and their values (clap_complete's
/// script for a hyphenated binary name labelled its `case` arms so that none matched: clap issue #6421),
/// run in bash as bash-completion runs it.
#[test]
fn bash_completion_completes_the_flags_and_values_of_subcommands() {
    let dir = tempfile::tempdir().unwrap();
    let (code, script, err) = coin_log_text(&["completions", "bash"]);
    assert_eq!(code, 0, "{err}");
    let file = dir.path().join("coin-log.bash");
    std::fs::write(&file, script).unwrap();
    for (words, prev, expected) in [
        ("coin-log rec", "coin-log", "record"),
        (
            "coin-log bench ''",
            "bench",
            "precision stability throughput euler sweep",
        ),
        ("coin-log record --enc", "record", "--encoding"),
        (
            "coin-log record --encoding ''",
            "--encoding",
            "json protobuf",
        ),
        ("coin-log sweep collect --j", "collect", "--jobs --json"),
        // Names the scene or the command checks itself (exit 1, its own message) are still offered,
        // not the file names the shell falls back to.
        (
            "coin-log record wobble --integrator ''",
            "--integrator",
            "rk4 dopri5 dop853 gauss4",
        ),
        ("coin-log analyse map --branch ''", "--branch", "+ - both"),
    ] {
        let cur = words.rsplit(' ').next().unwrap();
        let line = format!(
            "source \"$1\"; COMP_WORDS=({words}); COMP_CWORD=$((${{#COMP_WORDS[@]}} - 1)); \
             _coin__log coin-log {cur} {prev}; echo \"${{COMPREPLY[*]}}\""
        );
        let out = Command::new("bash")
            .args(["-c", &line, "bash"])
            .arg(&file)
            .output()
            .unwrap();
        let got = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success(),
            "{words}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(
            got.contains(expected),
            "`{words}<TAB>`: expected `{expected}`, got `{got}`"
        );
    }
}

#[test]
fn completions_and_man_pages_name_every_command() {
    let (code, help, _) = coin_log_text(&["--help"]);
    assert_eq!(code, 0);
    for c in COMMANDS {
        assert!(help.contains(c), "`{c}` in --help");
    }
    for shell in ["bash", "zsh", "fish", "elvish", "powershell"] {
        let (code, out, err) = coin_log_text(&["completions", shell]);
        assert_eq!(code, 0, "{shell}: {err}");
        for c in COMMANDS {
            assert!(out.contains(c), "{shell}: `{c}` completed");
        }
        for flag in ["dry-run", "overwrite", "wide"] {
            assert!(out.contains(flag), "{shell}: `--{flag}` completed");
        }
    }
    let (code, out, _) = coin_log_text(&["completions", "tcsh"]);
    assert_eq!(code, 2, "an unknown shell is a usage error: {out}");
    let (code, man, _) = coin_log_text(&["man"]);
    assert_eq!(code, 0);
    assert!(
        man.starts_with(".ie") || man.contains(".TH coin-log"),
        "roff: {}",
        &man[..200.min(man.len())]
    );
    for c in COMMANDS {
        assert!(man.contains(c), "`{c}` in the man page");
    }
    let dir = tempfile::tempdir().unwrap();
    let out = coin_log(dir.path(), &["man", "--out", "man1"]);
    assert_eq!(out.status.code(), Some(0));
    let pages = listing(&dir.path().join("man1"));
    println!("{pages:?}");
    for c in COMMANDS {
        assert!(
            pages.contains(&format!("coin-log-{c}.1")),
            "coin-log-{c}.1 written"
        );
    }
    assert!(pages.contains(&"coin-log.1".to_string()));
    assert!(pages.contains(&"coin-log-bench-precision.1".to_string()));
}

/// With several files verify ends with a one-line total; with one it does not; no progress bar when
/// stderr is not a terminal.
#[test]
fn verify_totals_several_files_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    record_scene(dir.path(), "circle-plus", &["--duration", "2"]);
    std::fs::write(dir.path().join("junk.mcap"), b"junk").unwrap();
    let out = coin_log(
        dir.path(),
        &[
            "verify",
            "circle-plus.mcap",
            "junk.mcap",
            "circle-plus.mcap",
        ],
    );
    let text = String::from_utf8_lossy(&out.stdout);
    print!("{text}");
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        text.lines().last(),
        Some("3 files: 2 ok, 0 failed, 0 cannot verify, 1 unusable")
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        err.lines().count(),
        1,
        "only junk.mcap's error, no bar: {err}"
    );
    let out = coin_log(dir.path(), &["verify", "circle-plus.mcap"]);
    assert!(!String::from_utf8_lossy(&out.stdout).contains("files:"));
    assert!(out.stderr.is_empty());
}

/// `plot` draws SVG only: `-o plot.png` wrote SVG under a PNG name without a word. It is refused before any
/// work with exit 2 (a usage error), naming the SVG name to give, and writes nothing; an SVG name in any case,
/// and a name whose extension is no picture format, are drawn.
#[test]
fn plot_refuses_an_output_named_for_another_picture_format() {
    let dir = tempfile::tempdir().unwrap();
    record_scene(dir.path(), "wobble", &["--duration", "0.1"]);
    for name in ["plot.png", "plot.PDF", "plot.jpeg"] {
        let out = coin_log(dir.path(), &["plot", "wobble.mcap", "-o", name]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{name}: {err}");
        assert!(err.contains("plot draws SVG only"), "{name}: {err}");
        assert!(err.contains("give --out plot.svg"), "{name}: {err}");
        assert!(!dir.path().join(name).exists(), "{name}");
    }
    assert_eq!(listing(dir.path()), ["wobble.mcap"]);
    for name in ["plot.SVG", "plot.v2"] {
        let out = coin_log(dir.path(), &["plot", "wobble.mcap", "-o", name]);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(std::fs::read_to_string(dir.path().join(name))
            .unwrap()
            .starts_with("<svg"));
    }
}

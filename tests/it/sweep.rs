//! `coin-log sweep` (docs/format.md: Sweeps): the sweep file's keys and every error, the run files byte
//! for byte `record`'s, the catalogue's columns and values, the dry run and the exit codes. Resume and
//! interruption are in `sweep_resume`, shards and collect in `sweep_shards`; the helpers here serve all.
// Helpers outside #[test] functions: a failed unwrap there is a failed test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use crate::support::record::{exe, listing};
use coin_log::sweep::{linspace, logspace, sha256_hex, Sweep};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A small sweep with every kind of ending: lift-off, flat landing, completed; 2 × 3 grid points with a
/// zipped pair, 2 draws each (12 runs of at most 3 time units at 50 samples per unit).
pub const SMALL: &str = r#"
description = "test sweep"
base = "wobble"
set = { "run.duration" = 3.0, "run.rate" = 50.0 }

[[axis]]
key = "initial.omega"
values = [[0.0, 0.0, 0.0], [0.3, 0.2, 1.5]]

[[axis]]
key = "initial.theta"
values = [0.2, 0.6, 1.0]
zip = "lean"

[[axis]]
key = "initial.phi"
linspace = [0.0, 1.0, 3]
zip = "lean"

[random]
seed = 11
count = 2

[[random.draw]]
key = "body.thickness"
choice = [0.04, 0.06]
"#;

/// Runs of [`SMALL`].
pub const SMALL_RUNS: usize = 12;

/// Writes a sweep file `name` into `dir`.
pub fn write_sweep(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// The schedulers' variables, which would make a sweep take one shard: kept from every child but the
/// ones that set them on purpose.
pub const SCHEDULER_VARIABLES: [&str; 5] = [
    "SLURM_ARRAY_TASK_ID",
    "SLURM_ARRAY_TASK_COUNT",
    "SLURM_ARRAY_TASK_MIN",
    "SLURM_ARRAY_TASK_MAX",
    "JOB_COMPLETION_INDEX",
];

/// Runs `coin-log ARGS` in `dir` with `env` set (and no other scheduler variable): exit code, stdout,
/// stderr.
pub fn run_with_env(dir: &Path, args: &[&str], env: &[(&str, &str)]) -> (i32, String, String) {
    let mut command = std::process::Command::new(exe());
    command.args(args).current_dir(dir);
    for v in SCHEDULER_VARIABLES {
        command.env_remove(v);
    }
    command.envs(env.iter().copied());
    let out = command.output().expect("coin-log runs");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Runs `coin-log ARGS` in `dir`: exit code, stdout, stderr.
pub fn run_in(dir: &Path, args: &[&str]) -> (i32, String, String) {
    run_with_env(dir, args, &[])
}

/// Runs the sweep `sweep` into `out` (both relative to `dir`) with `extra` flags and `--json`; returns
/// the exit code and the summary object.
pub fn sweep_json(dir: &Path, sweep: &str, out: &str, extra: &[&str]) -> (i32, serde_json::Value) {
    let mut args = vec!["sweep", sweep, "-o", out, "--json"];
    args.extend_from_slice(extra);
    let (code, stdout, stderr) = run_in(dir, &args);
    let json = serde_json::from_str(stdout.trim())
        .unwrap_or_else(|e| panic!("sweep --json printed no JSON ({e}): {stdout}{stderr}"));
    (code, json)
}

/// A CSV file read by RFC 4180, independently of the library's writer: header and rows.
pub struct Csv {
    pub header: Vec<String>,
    pub rows: Vec<Vec<String>>,
}

impl Csv {
    pub fn read(path: &Path) -> Self {
        let text =
            std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert!(
            text.ends_with('\n'),
            "{}: the last row ends with a line break",
            path.display()
        );
        let mut lines = text.lines().map(parse_csv_line);
        let header = lines.next().expect("a header");
        let rows: Vec<Vec<String>> = lines.collect();
        for (n, r) in rows.iter().enumerate() {
            assert_eq!(r.len(), header.len(), "{} row {n}: {r:?}", path.display());
        }
        Self { header, rows }
    }

    pub fn column(&self, name: &str) -> usize {
        self.header
            .iter()
            .position(|c| c == name)
            .unwrap_or_else(|| panic!("no column `{name}` in {:?}", self.header))
    }

    /// Each row as column → value.
    pub fn records(&self) -> Vec<BTreeMap<String, String>> {
        let zip = |r: &Vec<String>| self.header.iter().cloned().zip(r.iter().cloned()).collect();
        self.rows.iter().map(zip).collect()
    }

    /// The rows without the one host-dependent column, `wall_time_s`.
    pub fn without_wall_time(&self) -> Vec<Vec<String>> {
        let wall = self.column("wall_time_s");
        let keep = |r: &Vec<String>| {
            let mut r = r.clone();
            r.remove(wall);
            r
        };
        self.rows.iter().map(keep).collect()
    }
}

fn parse_csv_line(line: &str) -> Vec<String> {
    let (mut fields, mut field, mut quoted, mut chars) =
        (Vec::new(), String::new(), false, line.chars().peekable());
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', false) if field.is_empty() => quoted = true,
            ('"', true) if chars.peek() == Some(&'"') => {
                chars.next();
                field.push('"');
            }
            ('"', true) => quoted = false,
            (',', false) => fields.push(std::mem::take(&mut field)),
            (c, _) => field.push(c),
        }
    }
    assert!(!quoted, "unclosed quote in {line}");
    fields.push(field);
    fields
}

/// SHA-256 of a file, by the system's `sha256sum` (independent of the library's hash).
pub fn sha256sum(path: &Path) -> String {
    let out = std::process::Command::new("sha256sum")
        .arg(path)
        .output()
        .expect("sha256sum runs");
    String::from_utf8_lossy(&out.stdout)
        .split_whitespace()
        .next()
        .unwrap_or_default()
        .to_string()
}

/// The run files of a folder (`run-*.mcap`), sorted.
pub fn run_files(dir: &Path) -> Vec<String> {
    listing(dir)
        .into_iter()
        .filter(|n| n.starts_with("run-") && n.ends_with(".mcap"))
        .collect()
}

#[test]
fn a_sweep_runs_every_combination_and_its_catalogue_has_the_contracts_columns() {
    let dir = tempfile::tempdir().unwrap();
    write_sweep(dir.path(), "s.toml", SMALL);
    let (code, json) = sweep_json(dir.path(), "s.toml", "out", &["--jobs", "2"]);
    assert_eq!(code, 0, "{json}");
    assert_eq!(
        (
            json["runs"].as_u64(),
            json["finished"].as_u64(),
            json["failed"].as_u64()
        ),
        (Some(12), Some(12), Some(0))
    );
    let out = dir.path().join("out");
    let c = Csv::read(&out.join("catalogue.csv"));
    let expected: Vec<&str> = "index,initial.omega,initial.theta,initial.phi,body.thickness,status,termination,t_end,verify,failure,reason,file,bytes,sha256,samples,messages,steps,energy_drift,invariant_drift,steady_residual,event_trusted,predicted_motion,predicted_stability,predicted_termination,wall_time_s".split(',').collect();
    assert_eq!(c.header, expected);
    assert_eq!(c.rows.len(), SMALL_RUNS);
    let phis = linspace(0.0, 1.0, 3);
    for (i, r) in c.records().iter().enumerate() {
        // Grid point i / 2 (two draws each): omega slowest, then the zipped (theta, phi) pair.
        let point = i / 2;
        assert_eq!(r["index"], i.to_string());
        assert_eq!(
            r["initial.omega"],
            ["[0.0, 0.0, 0.0]", "[0.3, 0.2, 1.5]"][point / 3]
        );
        assert_eq!(r["initial.theta"], ["0.2", "0.6", "1.0"][point % 3]);
        assert_eq!(
            r["initial.phi"].parse::<f64>().unwrap().to_bits(),
            phis[point % 3].to_bits()
        );
        assert!(
            ["0.04", "0.06"].contains(&r["body.thickness"].as_str()),
            "{r:?}"
        );
        assert_eq!(
            (
                r["status"].as_str(),
                r["verify"].as_str(),
                r["failure"].as_str(),
                r["reason"].as_str()
            ),
            ("finished", "ok", "", "")
        );
        let file = out.join(&r["file"]);
        assert_eq!(r["file"], format!("run-{i:02}.mcap"));
        assert_eq!(
            r["bytes"],
            std::fs::metadata(&file).unwrap().len().to_string()
        );
        assert_eq!(r["sha256"], sha256sum(&file));
        assert_eq!(
            r["termination"], r["predicted_termination"],
            "run {i}: simulation and quadrature agree on these"
        );
        assert!(r["wall_time_s"].parse::<f64>().unwrap() > 0.0);
        let no_spin = point < 3;
        let ending = if !no_spin {
            "completed"
        } else if point == 0 {
            "lift-off"
        } else {
            "flat-landing"
        };
        assert_eq!(r["termination"], ending, "run {i}");
        assert_eq!(
            r["predicted_motion"],
            if no_spin { "flat-landing" } else { "nutation" }
        );
        assert_eq!(r["event_trusted"], if no_spin { "true" } else { "" });
        assert!(r["energy_drift"].parse::<f64>().unwrap() < 1e-9, "{r:?}");
        assert!(r["invariant_drift"].parse::<f64>().is_ok() && r["steady_residual"].is_empty());
        if !no_spin {
            assert_eq!(
                r["samples"], "151",
                "3 time units at 50 samples per unit, both ends included"
            );
        }
    }
    // The draws are the documented generator's, whatever the jobs: a second folder with --jobs 1 agrees.
    let (code, _) = sweep_json(dir.path(), "s.toml", "one", &["--jobs", "1"]);
    assert_eq!(code, 0);
    assert_eq!(
        Csv::read(&dir.path().join("one/catalogue.csv")).without_wall_time(),
        c.without_wall_time()
    );
    assert_eq!(run_files(&out).len(), SMALL_RUNS);
    assert!(
        !listing(&out).iter().any(|n| n.ends_with(".tmp")),
        "no temporary file left: {:?}",
        listing(&out)
    );
}

#[test]
fn sweep_json_holds_the_resolved_sweep_and_the_counts() {
    let dir = tempfile::tempdir().unwrap();
    write_sweep(dir.path(), "s.toml", SMALL);
    assert_eq!(sweep_json(dir.path(), "s.toml", "out", &[]).0, 0);
    let text = std::fs::read_to_string(dir.path().join("out/sweep.json")).unwrap();
    let j: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(j["format"], "coin-log sweep");
    assert_eq!(j["format_version"], "1");
    assert_eq!(j["tool_version"], env!("CARGO_PKG_VERSION"));
    assert_eq!(j["runs"], 12);
    assert_eq!(j["index_width"], 2);
    assert_eq!(
        j["keys"],
        serde_json::json!([
            "initial.omega",
            "initial.theta",
            "initial.phi",
            "body.thickness"
        ])
    );
    assert_eq!(
        j["counts"],
        serde_json::json!({"finished": 12, "failed": 0, "pending": 0})
    );
    let s = &j["sweep"];
    assert_eq!(s["base"], "wobble");
    assert!(s["base_scene"].as_str().unwrap().contains("[body]"));
    assert_eq!(
        s["set"],
        serde_json::json!({"run.duration": 3.0, "run.rate": 50.0})
    );
    assert_eq!(
        s["axes"][2],
        serde_json::json!({"key": "initial.phi", "values": [0.0, 0.5, 1.0], "zip": "lean"})
    );
    assert_eq!(
        s["random"],
        serde_json::json!({"generator": 2, "seed": 11, "count": 2, "draws": [{"key": "body.thickness", "choice": [0.04, 0.06]}]})
    );
    assert_eq!(
        s["output"],
        serde_json::json!({"channels": null, "encoding": "json", "compression": "zstd", "verify": true, "predict": true})
    );
    // The identity is the SHA-256 of the compact `sweep` object (format.md: sweep.json).
    let identity = coin_log::sweep::sha256_hex(s.to_string().as_bytes());
    assert_eq!(j["identity"], identity.as_str());
    let plan = std::fs::read_to_string(dir.path().join("out/.coin-log-sweep/plan.json")).unwrap();
    let mut without_counts = j.clone();
    without_counts.as_object_mut().unwrap().remove("counts");
    assert_eq!(
        serde_json::from_str::<serde_json::Value>(&plan).unwrap(),
        without_counts
    );
}

/// The resolved scene of run `index` of `sweep_text` (through the library, as the sweep resolves it).
fn scene_of(sweep_text: &str, index: u64) -> coin_log::scene::Scene {
    let sweep = Sweep::parse(sweep_text, Path::new("."), "s.toml").unwrap();
    sweep.scene(&sweep.values(index).unwrap()).unwrap()
}

#[test]
fn a_run_file_is_byte_for_byte_what_record_writes_for_the_same_scene() {
    let dir = tempfile::tempdir().unwrap();
    let text = SMALL.replace(
        "[random]",
        "[output]\nencoding = \"protobuf\"\ncompression = \"lz4\"\n\n[random]",
    );
    write_sweep(dir.path(), "s.toml", &text);
    assert_eq!(
        sweep_json(dir.path(), "s.toml", "out", &["--jobs", "2"]).0,
        0
    );
    let c = Csv::read(&dir.path().join("out/catalogue.csv"));
    for (i, r) in c.records().iter().enumerate().step_by(3) {
        // 1. The stored scene recorded again, as `coin-log info --scene` documents.
        let run = dir.path().join("out").join(&r["file"]);
        let (code, scene, err) = run_in(dir.path(), &["info", run.to_str().unwrap(), "--scene"]);
        assert_eq!(code, 0, "{err}");
        std::fs::write(dir.path().join("stored.toml"), scene).unwrap();
        let again = dir.path().join(format!("again-{i}.mcap"));
        let (code, _, err) = run_in(
            dir.path(),
            &[
                "record",
                "stored.toml",
                "-o",
                again.to_str().unwrap(),
                "--encoding",
                "protobuf",
                "--compression",
                "lz4",
            ],
        );
        assert_eq!(code, 0, "{err}");
        assert!(
            std::fs::read(&again).unwrap() == std::fs::read(&run).unwrap(),
            "run {i}: `record` of its stored scene differs"
        );
        // 2. The base scene with the run's values as --set edits.
        let mut args: Vec<String> = [
            "record",
            "wobble",
            "--encoding",
            "protobuf",
            "--compression",
            "lz4",
        ]
        .map(String::from)
        .into();
        for (key, value) in [("run.duration", "3.0"), ("run.rate", "50.0")] {
            args.push("--set".into());
            args.push(format!("{key}={value}"));
        }
        for key in [
            "initial.omega",
            "initial.theta",
            "initial.phi",
            "body.thickness",
        ] {
            args.push("--set".into());
            args.push(format!("{key}={}", r[key]));
        }
        let by_set = dir.path().join(format!("set-{i}.mcap"));
        args.extend(["-o".into(), by_set.to_str().unwrap().into()]);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let (code, _, err) = run_in(dir.path(), &args);
        assert_eq!(code, 0, "{err}");
        assert!(
            std::fs::read(&by_set).unwrap() == std::fs::read(&run).unwrap(),
            "run {i}: `record --set` differs"
        );
        // 3. And the library resolves the same scene the file stores (`info --scene` prints it readably).
        let stored = std::fs::read_to_string(dir.path().join("stored.toml")).unwrap();
        let stored: Vec<&str> = stored.lines().filter(|l| !l.starts_with('#')).collect();
        assert_eq!(
            coin_log::scene::readable_toml(&scene_of(&text, i as u64).to_toml())
                .lines()
                .collect::<Vec<_>>(),
            stored,
            "run {i}"
        );
    }
}

/// The problems of a bad sweep file: exit 2, nothing written, every problem named with its key.
fn refused(text: &str) -> String {
    let dir = tempfile::tempdir().unwrap();
    write_sweep(dir.path(), "bad.toml", text);
    let (code, out, err) = run_in(dir.path(), &["sweep", "bad.toml", "-o", "out"]);
    assert_eq!(code, 2, "a bad sweep file exits 2: {out}{err}");
    assert!(
        !dir.path().join("out").exists(),
        "nothing written for a bad sweep file"
    );
    assert!(err.starts_with("error: sweep file `bad.toml`: "), "{err}");
    err
}

#[test]
fn a_bad_sweep_file_gets_every_problem_at_once_with_key_value_and_fix() {
    let err = refused(
        r#"
base = "wobbel"
set = { "run..rate" = 1.0, run = { duration = 2.0 } }
[[axis]]
key = "initial.theta"
linspace = [0.1, 0.5, 0]
[[axis]]
key = "initial.phi"
[[axis]]
key = "body.mass"
values = []
[[axis]]
key = "initial.psi"
values = [1.0]
logspace = [0, 1, 2]
[[axis]]
key = "x"
values = [1.0, 2.0]
zip = "a"
[[axis]]
key = "y"
values = [1.0]
zip = "a"
[random]
seed = -1
count = 0
[[random.draw]]
key = "body.friction"
uniform = [0.9, 0.1]
[[random.draw]]
key = "body.radius"
log_uniform = [0.0, 1.0]
[[random.draw]]
key = "initial.theta"
normal = { mean = 0.3, std = 0.0 }
[[random.draw]]
key = "run.rate"
[output]
encoding = "yaml"
compression = "brotli"
channels = ["omega", "velocity"]
"#,
    );
    let expected = [
        "`base` = \"wobbel\" is no built-in scene (",
        "and not a path: a scene file is given by its path relative to the sweep file, such as \"./wobbel.toml\"",
        "`set.\"run..rate\"` = 1.0 is not a dotted scene key",
        "`set.run` = { duration = 2.0 } is a table: TOML reads an unquoted dotted key as nested tables, which would replace the whole `run` table; quote the key so that it names one scene key: set = { \"run.duration\" = 2.0 }",
        "`axis[0].linspace` = [0.1, 0.5, 0] must end with a whole number of values n, 1 ≤ n ≤ 1000000 (more samples of a key: draw it, [[random.draw]])",
        "`axis[1]` has no values: give one of `values = [...]`, `linspace = [first, last, n]` or `logspace = [first_exp, last_exp, n]`",
        "`axis[2].values` = [] is empty: give at least one value",
        "`axis[3]` gives values and logspace: give exactly one of them",
        "`axis[5].zip` = \"a\" zips axes of different lengths (axis[4] has 2, axis[5] has 1 values)",
        "`random.seed` = -1 must be a whole number from 0 to 9223372036854775807",
        "`random.count` = 0 must be a whole number of runs per grid point",
        "`random.draw[0].uniform` = [0.9, 0.1] must be [lo, hi], two finite numbers with lo < hi",
        "`random.draw[1].log_uniform` = [0.0, 1.0] must be [lo, hi], two finite numbers with 0 < lo < hi",
        "`random.draw[2].normal.std` = 0.0 must be a finite number > 0",
        "`random.draw[3]` has no distribution: give one of `uniform = [lo, hi]`",
        "`output.encoding` = \"yaml\" unknown encoding `yaml`; valid: json, protobuf",
        "`output.compression` = \"brotli\" unknown compression `brotli`; valid: zstd, lz4, none",
        "`output.channels` = \"velocity\" unknown channel `velocity`",
        "`random.draw[2].key` = \"initial.theta\" is also given by axis[0]: each key is set or swept in one place only",
    ];
    for e in expected {
        assert!(err.contains(e), "missing `{e}` in:\n{err}");
    }
    assert!(
        err.contains(&format!("{} problems:", expected.len() - 1)),
        "{err}"
    );
}

#[test]
fn an_infinite_normal_mean_is_a_problem_not_a_silently_dropped_random_table() {
    // It was turned into "no value" without a problem: the [random] table vanished and the sweep ran
    // its one grid point (`--dry-run`: "1 run", exit 0).
    let err = refused(
        r#"
base = "wobble"
[random]
seed = 1
count = 2
[[random.draw]]
key = "initial.theta"
normal = { mean = inf, std = 0.1 }
[[random.draw]]
key = "initial.psi"
normal = { mean = -inf, std = inf }
[[random.draw]]
key = "initial.phi"
normal = { mean = 0.0, std = 0.0, min = "x" }
"#,
    );
    for e in [
        "`random.draw[0].normal.mean` = inf must be a finite number",
        "`random.draw[1].normal.mean` = -inf must be a finite number",
        "`random.draw[1].normal.std` = inf must be a finite number > 0",
        // Each value is judged on its own: a bad bound does not hide a bad std.
        "`random.draw[2].normal.std` = 0.0 must be a finite number > 0",
        "`random.draw[2].normal.min` = \"x\" must be a number",
    ] {
        assert!(err.contains(e), "missing `{e}` in:\n{err}");
    }
    assert!(err.contains("5 problems:"), "{err}");
}

#[test]
fn a_swept_string_with_a_line_break_is_a_problem_not_a_run_redone_forever() {
    // Its cell split the row over two lines of the journal and the part: resume redid the run every
    // time, and collect refused the part ("not a row of this sweep: run its shard again", which did not
    // help).
    let err = refused(
        "base = \"wobble\"\n[[axis]]\nkey = \"run.integrator\"\nvalues = [\"rk4\", \"dop\\n853\"]\n\
         [random]\nseed = 1\ncount = 1\n[[random.draw]]\nkey = \"body.shape\"\nchoice = [\"x\\r\"]\n",
    );
    for (key, value) in [
        ("axis[0].values", r#""dop\n853""#),
        ("random.draw[0].choice", r#""x\r""#),
    ] {
        let problem = format!(
            "`{key}` = {value} holds a line break, which no scene key takes and a catalogue row (one line) cannot hold: remove it"
        );
        assert!(err.contains(&problem), "{err}");
    }
}

#[test]
fn a_long_swept_key_is_shown_cut_in_its_problem() {
    // A key of 100 000 characters was quoted whole (a 100 kB message); `record --set` cuts it.
    let key = format!("initial.{}", "x".repeat(100_000));
    let err = refused(&format!(
        "base = \"wobble\"\n[[axis]]\nkey = \"{key}\"\nvalues = [1]\n"
    ));
    assert!(err.len() < 2000, "{} bytes", err.len());
    assert!(
        err.contains("does not fit the scene key `initial.xxx"),
        "{err}"
    );
}

#[test]
fn an_output_channel_list_that_every_run_would_refuse_is_a_problem() {
    // `output.channels` is fixed for all runs: an empty list or a channel listed twice passed, and every
    // run was then a failed row with the scene's complaint.
    for (list, says) in [
        ("[]", "`output.channels` = [] is empty: list at least one channel, or leave the key out for the scenes' lists"),
        (r#"["omega", "energy", "omega"]"#, "`output.channels` = \"omega\" is listed twice: list each channel once"),
    ] {
        let err = refused(&format!("base = \"wobble\"\n[output]\nchannels = {list}\n"));
        assert!(err.contains(says), "{err}");
    }
}

#[test]
fn a_uniform_draw_wider_than_the_largest_double_is_a_problem_not_a_sweep_of_inf() {
    // Both bounds finite and lo < hi, but hi − lo overflows: lo + (hi − lo)·u was inf for every run
    // (each a failed row, `--dry-run` showing inf in every row).
    let err = refused(
        r#"
base = "wobble"
[random]
seed = 1
count = 3
[[random.draw]]
key = "body.mass"
uniform = [-1e308, 1.7e308]
[[random.draw]]
key = "body.radius"
uniform = [-8e307, 8e307]
"#,
    );
    assert!(
        err.contains("`random.draw[0].uniform` = [-1e308, 1.7e308] is wider")
            && err.contains("is wider than the largest double (hi − lo overflows, so every draw would be inf): narrow it, or draw log_uniform"),
        "{err}"
    );
    assert!(!err.contains("draw[1]"), "a width that fits is fine: {err}");
}

#[test]
fn a_sweep_of_the_most_runs_starts_at_once_in_little_memory() {
    // 10⁹ runs is allowed; resume listed every one to do in a Vec<u64> (8 GB) before the first started,
    // deaf to signals. Under a 2 GB address-space limit that aborted ("memory allocation … failed").
    let dir = tempfile::tempdir().unwrap();
    write_sweep(
        dir.path(),
        "s.toml",
        r#"
base = "wobble"
set = { "run.duration" = 0.1, "run.rate" = 20.0 }
[random]
seed = 1
count = 1000000000
[[random.draw]]
key = "body.mass"
uniform = [1, 2]
[output]
verify = false
"#,
    );
    let script = format!(
        "ulimit -v 2000000; exec '{}' sweep s.toml -o out --jobs 1 --json",
        exe().display()
    );
    let mut command = std::process::Command::new("sh");
    for v in SCHEDULER_VARIABLES {
        command.env_remove(v);
    }
    let mut child = command
        .args(["-c", &script])
        .current_dir(dir.path())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let out = dir.path().join("out");
    let started = std::time::Instant::now();
    let made = |out: &Path| {
        std::fs::read_dir(out).is_ok_and(|mut d| {
            d.any(|e| e.is_ok_and(|e| e.file_name().to_string_lossy().starts_with("run-")))
        })
    };
    while !made(&out) {
        if started.elapsed() > std::time::Duration::from_secs(20) {
            let _ = child.kill();
            panic!("no run made within 20 s");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let _ = std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status();
    let output = child.wait_with_output().unwrap();
    let (out_text, err) = (
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr),
    );
    assert_eq!(output.status.code(), Some(130), "{out_text}{err}");
    let json: serde_json::Value = serde_json::from_str(&out_text).unwrap();
    assert_eq!(json["runs"].as_u64(), Some(1_000_000_000));
    assert!(json["finished"].as_u64().unwrap() >= 1, "{json}");
    if let Some(rss) = json["peak_rss_bytes"].as_u64() {
        assert!(rss < 200 << 20, "peak RSS {rss} B: {json}");
    }
}

#[test]
fn a_system_that_refuses_threads_still_finishes_every_run() {
    // Under a limit on processes (a cluster's pids limit, `ulimit -u`), spawning the sweep's workers and
    // a verification's reading thread panicked ("failed to spawn thread"), killing the sweep with
    // nothing catalogued. The limit binds root only through another user: setpriv, where there is one.
    let dir = tempfile::tempdir().unwrap();
    let text = SMALL.replace("count = 2", "count = 10");
    write_sweep(dir.path(), "s.toml", &text);
    let mode = std::os::unix::fs::PermissionsExt::from_mode(0o777);
    std::fs::set_permissions(dir.path(), mode).unwrap();
    // prlimit is util-linux's; as root the limit binds only another user.
    let nobody = crate::support::unprivileged(&exe());
    let mut command = std::process::Command::new("prlimit");
    command
        .args(["--nproc=40:40", "--"])
        .arg(nobody.get_program())
        .args(nobody.get_args())
        .args(["sweep", "s.toml", "-o", "out", "--jobs", "200"]);
    for v in SCHEDULER_VARIABLES {
        command.env_remove(v);
    }
    let output = command.current_dir(dir.path()).output().unwrap();
    let err = String::from_utf8_lossy(&output.stderr);
    assert!(!err.contains("panicked"), "{err}");
    let catalogue = Csv::read(&dir.path().join("out/catalogue.csv"));
    assert_eq!(catalogue.rows.len(), SMALL_RUNS * 5, "{err}");
    // And every run is done: a run also needs a thread of its own (verify's reading thread), so the
    // sweep leaves half of what the system gave it idle, and a writer refused a compression thread
    // compresses on its own (35 of 40 runs failed "Resource temporarily unavailable" before).
    for r in catalogue.records() {
        assert_eq!(
            (r["status"].as_str(), r["verify"].as_str()),
            ("finished", "ok"),
            "{r:?}\n{err}"
        );
    }
    assert_eq!(output.status.code(), Some(0), "{err}");
}

#[test]
fn axes_of_more_values_than_memory_and_sweep_json_take_are_refused_before_any_is_made() {
    // A linspace of 10⁹ values (as many as a sweep's runs) once asked for 32 GB and aborted.
    let err = refused(
        r#"
base = "wobble"
[[axis]]
key = "initial.theta"
linspace = [0.2, 1.0, 1000000000]
"#,
    );
    assert!(
        err.contains("`axis[0].linspace` = [0.2, 1.0, 1000000000] must end with a whole number of values n, 1 ≤ n ≤ 1000000"),
        "{err}"
    );
    // Zipped axes make one dimension, so only the values' total stops these (6·10⁵ runs).
    let err = refused(
        r#"
base = "wobble"
[[axis]]
key = "initial.theta"
linspace = [0.2, 1.0, 600000]
zip = "z"
[[axis]]
key = "initial.phi"
linspace = [0.0, 1.0, 600000]
zip = "z"
"#,
    );
    assert!(
        err.contains("`axis` gives 1200000 values in all, more than the 1000000 the axes may"),
        "{err}"
    );
}

/// Too many runs name what makes them too many: `random.count` at each grid point (the axes, 1000 values,
/// were once blamed for 10¹² runs), or the grid itself.
#[test]
fn too_many_runs_name_the_count_or_the_grid_that_makes_them() {
    let err = refused(
        r#"
base = "wobble"
[[axis]]
key = "initial.theta"
linspace = [0.1, 1.0, 1000]
[random]
seed = 1
count = 1000000000
[[random.draw]]
key = "body.thickness"
uniform = [0.01, 0.02]
"#,
    );
    assert!(
        err.contains("`random.count` = 1000000000 runs at each of the axes' 1000 grid points give 1000000000000 runs, more than the 1000000000 a sweep may have: draw fewer runs per point"),
        "{err}"
    );
    assert!(!err.contains("`axis` gives"), "{err}");
    let err = refused(
        r#"
base = "wobble"
[[axis]]
key = "initial.theta"
linspace = [0.1, 1.0, 100000]
[[axis]]
key = "initial.phi"
linspace = [0.0, 1.0, 100000]
"#,
    );
    assert!(
        err.contains("`axis` gives 10000000000 grid points, each a run at least, more than the 1000000000 runs a sweep may have"),
        "{err}"
    );
}

/// A linspace whose ends are finite but whose formula overflows between them is refused with its own
/// advice, not logspace's ("keep the exponents within ±300"), and its value as written, not 1e308 in
/// 309 digits cut short.
#[test]
fn a_linspace_that_overflows_says_so_and_shows_its_value_short() {
    let err = refused(
        r#"
base = "wobble"
[[axis]]
key = "initial.theta"
linspace = [-1e308, 1e308, 4]
"#,
    );
    assert!(
        err.contains("`axis[0].linspace` = [-1e308, 1e308, 4] gives -inf: first·(n − 1 − k) + last·k overflows: keep |first|·(n − 1) and |last|·(n − 1) below about 1.8e308"),
        "{err}"
    );
    assert!(
        !err.contains("exponents") && !err.contains("00000000"),
        "{err}"
    );
    // Every value a problem shows is in that form: a set value, a listed value, a normal's bounds.
    let err = refused(
        r#"
base = "wobble"
[random]
seed = 1
count = 1
[[random.draw]]
key = "body.friction"
normal = { mean = 0.5, std = 1.0, min = 1e300, max = -1e300 }
"#,
    );
    assert!(
        err.contains("{ min = 1e300, max = -1e300 } has min ≥ max"),
        "{err}"
    );
    assert!(!err.contains("00000000"), "{err}");
    let err = refused("base = \"wobble\"\nset = { \"run.integrator\" = 1e300 }\n");
    assert!(
        err.contains("`set.\"run.integrator\"` = 1e300 does not fit the scene"),
        "{err}"
    );
    let err = refused("base = \"wobble\"\n[[axis]]\nkey = \"run.integrator\"\nvalues = [1e300]\n");
    assert!(
        err.contains("`axis[0].values` = 1e300 does not fit the scene key `run.integrator`"),
        "{err}"
    );
    let err = refused(
        r#"
base = "wobble"
[[axis]]
key = "initial.theta"
logspace = [-400, 400, 3]
"#,
    );
    assert!(
        err.contains(
            "`axis[0].logspace` = [-400, 400, 3] gives inf: keep the exponents within ±300"
        ),
        "{err}"
    );
}

/// The dry run's file count leaves out the runs it found without a valid scene, which make no file
/// (every run invalid was "about 0 B in 4 files"); a sweep of valid runs keeps its exact count.
#[test]
fn a_dry_run_counts_no_file_for_runs_without_a_valid_scene() {
    let dir = tempfile::tempdir().unwrap();
    let sweep =
        "base = \"wobble\"\n[[axis]]\nkey = \"body.mass\"\nvalues = [-1.0, 0.0, -2.0, -3.0]\n";
    write_sweep(dir.path(), "bad.toml", sweep);
    let (code, out, err) = run_in(dir.path(), &["sweep", "bad.toml", "--dry-run"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("about 0 B in about 0 files (runs with a valid scene)"),
        "{out}"
    );
    assert!(
        out.contains("invalid scenes: 4 of the 4 runs checked"),
        "{out}"
    );
    let half = sweep.replace("-1.0, 0.0", "1.0, 2.0");
    write_sweep(dir.path(), "half.toml", &half);
    let (_, out, _) = run_in(dir.path(), &["sweep", "half.toml", "--dry-run"]);
    assert!(
        out.contains(" in about 2 files (runs with a valid scene)"),
        "{out}"
    );
    write_sweep(
        dir.path(),
        "good.toml",
        &sweep
            .replace("-2.0, -3.0", "2.0, 3.0")
            .replace("-1.0, 0.0", "1.0, 4.0"),
    );
    let (_, out, _) = run_in(dir.path(), &["sweep", "good.toml", "--dry-run"]);
    assert!(out.contains(" in 4 files, about"), "{out}");
}

/// A float seed within the range but not below 9e15 is refused saying why (it was refused with the
/// range alone, which 9e15 is in); a whole float below it is taken as the integer.
#[test]
fn a_float_seed_is_refused_saying_to_write_it_as_an_integer() {
    let sweep = |seed: &str| {
        format!("base = \"wobble\"\n[random]\nseed = {seed}\ncount = 1\n[[random.draw]]\nkey = \"initial.theta\"\nuniform = [0.1, 0.2]\n")
    };
    let err = refused(&sweep("9e15"));
    assert!(err.contains("`random.seed` = 9000000000000000.0 must be a whole number from 0 to 9223372036854775807, written as an integer (a float is taken only below 9e15"), "{err}");
    let dir = tempfile::tempdir().unwrap();
    write_sweep(dir.path(), "s.toml", &sweep("7.0"));
    let (code, _, err) = run_in(dir.path(), &["sweep", "s.toml", "--dry-run"]);
    assert_eq!(code, 0, "{err}");
}

#[test]
fn keys_that_are_no_scene_keys_or_collide_are_refused_naming_them() {
    let err = refused(
        r#"
base = "wobble"
set = { "initial.theta" = 0.3, "run.duration" = 1.0, "record.channels" = ["omega"] }
[[axis]]
key = "initial.thetta"
values = [0.1]
[[axis]]
key = "initial.theta"
values = [0.2]
[[axis]]
key = "initial"
values = [{ theta = 0.3, omega = [0.0, 0.0, 1.0] }]
[[axis]]
key = "run.rate"
values = [100.0, "fast"]
[output]
channels = ["angles"]
"#,
    );
    for e in [
        "`axis[1].key` = \"initial.theta\" is also given by set.\"initial.theta\": each key is set or swept in one place only",
        "`axis[2].key` = \"initial\" replaces the whole table holding `initial.theta` (given by set.\"initial.theta\", which applies first)",
        // output.channels has no key of its own to quote: it says which key it sets.
        "`output.channels` sets `record.channels`, which is also given by set.\"record.channels\"",
    ] {
        assert!(err.contains(e), "missing `{e}` in:\n{err}");
    }
    // Without the collisions, each key's values are checked against the scene's keys and types.
    let err = refused(
        r#"
base = "wobble"
[[axis]]
key = "initial.thetta"
values = [0.1]
[[axis]]
key = "run.rate"
values = [100.0, "fast"]
[random]
seed = 1
count = 1
[[random.draw]]
key = "body.shape"
choice = ["hoop", 3]
"#,
    );
    for e in [
        "`axis[0].values` = 0.1 does not fit the scene key `initial.thetta`: unknown field `thetta`",
        "`axis[1].values` = \"fast\" does not fit the scene key `run.rate`: invalid type: string \"fast\", expected f64",
        "`random.draw[0]` = 3 does not fit the scene key `body.shape`: invalid type: integer `3`, expected a string",
    ] {
        assert!(err.contains(e), "missing `{e}` in:\n{err}");
    }
    // A later edit that removes an earlier one as the other form of its fact (a shape stands for both
    // inertias) would drop it from every run.
    let err = refused(
        r#"
base = "wobble"
set = { "body.inertia_x" = 0.3, "body.inertia_z" = 0.5 }
[[axis]]
key = "body.shape"
values = ["hoop"]
"#,
    );
    assert!(
        err.contains("`axis[0].key` = \"body.shape\" removes `body.inertia_x` (given by set.\"body.inertia_x\", which applies first), the other form of the same fact"),
        "{err}"
    );
    let err = refused("base = \"./missing.toml\"\n");
    assert!(
        err.contains("`base` = \"./missing.toml\" cannot be read (")
            && err.contains("give the path of a scene file relative to the sweep file"),
        "{err}"
    );
    let err = refused("base = \"wobble\"\nbogus = 1\n");
    assert!(
        err.contains("unknown field `bogus`"),
        "serde names the unknown key: {err}"
    );
}

#[test]
fn a_dry_run_shows_a_value_longer_than_a_format_width() {
    // The preview padded its columns with `{:<w$}`, which panics for w > 65 535.
    let dir = tempfile::tempdir().unwrap();
    let long = "x".repeat(70_000);
    let text =
        format!("base = \"wobble\"\n[[axis]]\nkey = \"description\"\nvalues = [\"{long}\"]\n");
    write_sweep(dir.path(), "s.toml", &text);
    let (code, out, err) = run_in(dir.path(), &["sweep", "s.toml", "-o", "out", "--dry-run"]);
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains(&format!("  0      {long}")),
        "{}",
        &out[..out.len().min(300)]
    );
}

#[test]
fn an_inertia_swept_on_a_built_in_scene_replaces_its_shape() {
    // wobble gives `body.shape`; an inertia set or swept on it used to fail every run as "given together".
    let dir = tempfile::tempdir().unwrap();
    let text = r#"
base = "wobble"
set = { "run.duration" = 0.5, "body.inertia_x" = 0.25 }
[[axis]]
key = "body.inertia_z"
values = [0.3, 0.5]
"#;
    write_sweep(dir.path(), "s.toml", text);
    let (code, out, err) = run_in(dir.path(), &["sweep", "s.toml", "-o", "out"]);
    assert_eq!(code, 0, "{out}{err}");
    for (i, iz) in ["0.3", "0.5"].into_iter().enumerate() {
        let file = dir.path().join(format!("out/run-{i}.mcap"));
        let (code, json, err) = run_in(dir.path(), &["info", "--json", file.to_str().unwrap()]);
        assert_eq!(code, 0, "{err}");
        let v: serde_json::Value = serde_json::from_str(&json).unwrap();
        let body = &v["files"][0]["body"];
        assert_eq!(body["inertia_z"].to_string(), iz, "{body}");
        assert_eq!(body["inertia_x"].to_string(), "0.25", "{body}");
        assert!(!v["files"][0]["scene"].as_str().unwrap().contains("shape"));
    }
}

#[test]
fn a_base_scene_file_is_found_beside_the_sweep_file_and_an_invalid_combination_is_a_failed_row() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("sweeps")).unwrap();
    let (code, scene, _) = run_in(dir.path(), &["scenes", "--show", "topple"]);
    assert_eq!(code, 0);
    std::fs::write(dir.path().join("sweeps/topple.toml"), scene).unwrap();
    write_sweep(
        &dir.path().join("sweeps"),
        "s.toml",
        "base = \"topple.toml\"\nset = { \"run.duration\" = 1.0 }\n[[axis]]\nkey = \"initial.theta\"\nvalues = [0.3, 1.6]\n",
    );
    let (code, json) = sweep_json(dir.path(), "sweeps/s.toml", "out", &[]);
    assert_eq!(code, 1, "a failed run exits 1: {json}");
    assert_eq!(
        (json["finished"].as_u64(), json["failed"].as_u64()),
        (Some(1), Some(1))
    );
    let c = Csv::read(&dir.path().join("out/catalogue.csv"));
    let bad = &c.records()[1];
    assert_eq!(
        (
            bad["status"].as_str(),
            bad["failure"].as_str(),
            bad["file"].as_str(),
            bad["verify"].as_str()
        ),
        ("failed", "scene", "", "")
    );
    assert!(
        bad["reason"].starts_with("`initial.theta` = 1.6 is outside"),
        "{bad:?}"
    );
    assert_eq!(run_files(&dir.path().join("out")), ["run-0.mcap"]);
}

#[test]
fn a_run_that_cannot_be_verified_says_why_in_its_reason() {
    // Sampled too coarsely for the constraint check (and no steady scene): the catalogue's reason used to
    // end in "each check's reason says why and what to record", naming reasons it did not hold.
    let dir = tempfile::tempdir().unwrap();
    let sweep = "base = \"wobble\"\nset = { \"run.duration\" = 0.5, \"run.rate\" = 20.0, \"initial.omega\" = [0.0, 0.0, 0.0], \"initial.theta\" = 0.67 }\n";
    write_sweep(dir.path(), "low.toml", sweep);
    let (code, out, err) = run_in(dir.path(), &["sweep", "low.toml", "-o", "low"]);
    assert_eq!(code, 1, "{out}{err}");
    let row = &Csv::read(&dir.path().join("low/catalogue.csv")).records()[0];
    assert_eq!(row["verify"], "cannot-verify", "{row:?}");
    let reason = &row["reason"];
    assert!(
        reason.starts_with(
            "verify: cannot-verify: cannot verify: the required check constraint or steady"
        ) && reason.contains("constraint skipped: the sampling does not resolve the motion")
            && reason.contains("record at a higher --rate")
            && reason.contains("steady skipped: not a steady scene"),
        "{reason}"
    );
    // Said while the sweep runs (it used to learn it only from the catalogue at the end), once; a sweep
    // whose runs all finish says nothing of the kind.
    let warning = "warning: run 0 failed: verify: cannot-verify: cannot verify: the required check";
    assert_eq!(err.matches(warning).count(), 1, "{err}");
    assert!(
        err.contains("record at a higher --rate (at least "),
        "{err}"
    );
    assert!(
        err.contains("runs like it will fail too: Ctrl-C stops the sweep and keeps what finished"),
        "{err}"
    );
    let fine = sweep.replace("\"run.rate\" = 20.0", "\"run.rate\" = 400.0");
    write_sweep(dir.path(), "fine.toml", &fine);
    let (code, out, err) = run_in(dir.path(), &["sweep", "fine.toml", "-o", "fine"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(!err.contains("failed"), "{err}");
}

#[test]
fn a_run_that_cannot_be_verified_fails_and_verification_can_be_off() {
    let dir = tempfile::tempdir().unwrap();
    let base = "base = \"circle-plus\"\nset = { \"run.duration\" = 1.0 }\n[output]\nchannels = [\"energy\"]\n";
    write_sweep(dir.path(), "on.toml", base);
    let (code, out, err) = run_in(dir.path(), &["sweep", "on.toml", "-o", "on"]);
    assert_eq!(code, 1, "{out}{err}");
    assert!(
        err.contains("warning: verify will not be able to judge run 0's recording (it and every run like it would fail): "),
        "{err}"
    );
    let row = &Csv::read(&dir.path().join("on/catalogue.csv")).records()[0];
    assert_eq!(
        (
            row["status"].as_str(),
            row["failure"].as_str(),
            row["verify"].as_str()
        ),
        ("failed", "verify", "cannot-verify")
    );
    assert!(
        row["reason"].starts_with("verify: cannot-verify")
            && !row["reason"].contains("record expected it"),
        "a refusal record did not predict is not called expected: {row:?}"
    );
    assert_eq!(
        row["predicted_stability"], "stable",
        "circle-plus is a stable steady circle"
    );
    assert!(row["steady_residual"].parse::<f64>().is_ok());
    // A refusal record warned of: the reason says so, with the checks it named (not invariants, steady
    // or nutation, which verify does not run with dissipation; it named invariants and steady).
    write_sweep(
        dir.path(),
        "loose.toml",
        "base = \"euler-disk\"\nset = { \"run.duration\" = 3.0, \"run.rtol\" = 1e-3, \"run.integrator\" = \"dopri5\" }\n",
    );
    let (code, out, err) = run_in(dir.path(), &["sweep", "loose.toml", "-o", "loose"]);
    assert_eq!(code, 1, "{out}{err}");
    let row = &Csv::read(&dir.path().join("loose/catalogue.csv")).records()[0];
    assert!(
        row["reason"].starts_with("verify: failed: constraint ")
            && row["reason"].ends_with("; record expected it: its settings allow more error than verify accepts in energy, constraint (tighten rtol/atol, or step)"),
        "{row:?}"
    );
    write_sweep(
        dir.path(),
        "off.toml",
        &format!("{base}verify = false\npredict = false\n"),
    );
    let (code, json) = sweep_json(dir.path(), "off.toml", "off", &[]);
    assert_eq!(code, 0, "{json}");
    let row = &Csv::read(&dir.path().join("off/catalogue.csv")).records()[0];
    assert_eq!(
        (row["status"].as_str(), row["verify"].as_str()),
        ("finished", "off")
    );
    for column in [
        "predicted_motion",
        "predicted_stability",
        "predicted_termination",
    ] {
        assert_eq!(row[column], "", "no prediction asked");
    }
}

#[test]
fn a_dry_run_counts_shows_and_estimates_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    write_sweep(dir.path(), "s.toml", SMALL);
    let (code, out, err) = run_in(dir.path(), &["sweep", "s.toml", "--dry-run"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.starts_with(
            "12 runs; swept keys: initial.omega, initial.theta, initial.phi, body.thickness\n"
        ),
        "{out}"
    );
    assert!(
        out.contains("  … (2 more)")
            && out.contains("estimate: ")
            && out.ends_with("nothing written (--dry-run)\n"),
        "{out}"
    );
    let (code, out, _) = run_in(
        dir.path(),
        &[
            "sweep",
            "s.toml",
            "-o",
            "out",
            "--dry-run",
            "--json",
            "--shard",
            "1/4",
        ],
    );
    assert_eq!(code, 0);
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(
        (j["runs"].as_u64(), j["shard"].as_str()),
        (Some(3), Some("1/4"))
    );
    assert_eq!(j["first"][1]["index"], 5);
    assert_eq!(j["first"][0]["values"]["initial.theta"], "0.2");
    assert!(j["estimated_bytes"].as_u64().unwrap() > 10_000 && j["invalid"] == 0);
    assert_eq!(listing(dir.path()), ["s.toml"], "a dry run writes nothing");
}

/// A `.coin-log-sweep` folder without a plan is no sweep's unless it holds nothing else (a process stopped
/// before it published its plan): beside the user's files, or with the journal of a sweep whose plan
/// was deleted, the sweep once went ahead, moved its runs over the user's `run-0.mcap` and appended its
/// rows to the other sweep's journal.
#[test]
fn a_state_folder_without_a_plan_does_not_make_a_foreign_folder_a_sweep_s() {
    let dir = tempfile::tempdir().unwrap();
    let short = SMALL.replace("count = 2", "count = 1");
    write_sweep(dir.path(), "s.toml", &short);
    let mine = dir.path().join("mine");
    std::fs::create_dir_all(mine.join(".coin-log-sweep")).unwrap();
    std::fs::write(mine.join("run-0.mcap"), "precious").unwrap();
    let (code, _, err) = run_in(dir.path(), &["sweep", "s.toml", "-o", "mine"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("`mine`: is not empty and holds no sweep (it has `run-0.mcap`): give -o a new or empty folder"), "{err}");
    assert_eq!(
        std::fs::read_to_string(mine.join("run-0.mcap")).unwrap(),
        "precious"
    );
    assert_eq!(listing(&mine.join(".coin-log-sweep")), Vec::<String>::new());

    // A sweep's folder whose plan was deleted: its journal is not another sweep's to append to.
    assert_eq!(sweep_json(dir.path(), "s.toml", "old", &[]).0, 0);
    let state = dir.path().join("old/.coin-log-sweep");
    std::fs::remove_file(state.join("plan.json")).unwrap();
    let journal = std::fs::read(state.join("journal-0-of-1.csv")).unwrap();
    let (code, _, err) = run_in(dir.path(), &["sweep", "s.toml", "-o", "old"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("`old`: is not empty and holds no sweep (it has `"),
        "{err}"
    );
    assert_eq!(
        std::fs::read(state.join("journal-0-of-1.csv")).unwrap(),
        journal
    );
    assert!(!state.join("plan.json").exists());

    // Stopped before its plan was in place: only the plan's temporary file is there, and the sweep runs.
    let stopped = dir.path().join("stopped/.coin-log-sweep");
    std::fs::create_dir_all(&stopped).unwrap();
    std::fs::write(stopped.join(".plan.json.a1B2c3.tmp"), "{").unwrap();
    let (code, json) = sweep_json(dir.path(), "s.toml", "stopped", &[]);
    assert_eq!((code, json["finished"].as_u64()), (0, Some(6)), "{json}");
}

#[test]
fn a_folder_with_other_content_or_another_sweep_is_refused_naming_the_fix() {
    let dir = tempfile::tempdir().unwrap();
    write_sweep(dir.path(), "s.toml", SMALL);
    std::fs::create_dir(dir.path().join("busy")).unwrap();
    std::fs::write(dir.path().join("busy/notes.txt"), "mine").unwrap();
    let (code, _, err) = run_in(dir.path(), &["sweep", "s.toml", "-o", "busy"]);
    assert_eq!(code, 2);
    assert!(err.contains("`busy`: is not empty and holds no sweep (it has `notes.txt`): give -o a new or empty folder"), "{err}");
    assert_eq!(listing(&dir.path().join("busy")), ["notes.txt"]);
    let short = SMALL.replace("count = 2", "count = 1");
    write_sweep(dir.path(), "other.toml", &short);
    assert_eq!(sweep_json(dir.path(), "s.toml", "out", &[]).0, 0);
    let (code, _, err) = run_in(dir.path(), &["sweep", "other.toml", "-o", "out"]);
    assert_eq!(code, 2);
    assert!(
        err.contains("holds another sweep (identity")
            && err.contains(
                "give -o a new folder for this sweep, or delete this folder to start it over"
            ),
        "{err}"
    );
    // A comment or a reordered table is the same sweep: the identity is of the sweep as resolved.
    write_sweep(
        dir.path(),
        "same.toml",
        &format!("# the same sweep\n{SMALL}"),
    );
    let (code, json) = sweep_json(dir.path(), "same.toml", "out", &[]);
    assert_eq!((code, json["done"].as_u64()), (0, Some(0)), "{json}");
}

/// A folder whose draws came from generator 1 (its plan names no generator: made before generator 2 mixed
/// the seed first) is refused, not resumed with other values; the same plan naming generator 2 resumes.
#[test]
fn a_folder_of_another_generator_is_refused_not_resumed_with_other_draws() {
    let dir = tempfile::tempdir().unwrap();
    write_sweep(dir.path(), "s.toml", SMALL);
    assert_eq!(sweep_json(dir.path(), "s.toml", "out", &[]).0, 0);
    let plan_path = dir.path().join("out/.coin-log-sweep/plan.json");
    let plan = std::fs::read_to_string(&plan_path).unwrap();
    let old = plan.replace("\"generator\":2,", "");
    assert_ne!(old, plan, "the plan names its generator: {plan}");
    std::fs::write(&plan_path, &old).unwrap();
    let (code, _, err) = run_in(dir.path(), &["sweep", "s.toml", "-o", "out"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("holds a sweep whose random draws come from generator 1, and this coin-log draws with generator 2")
            && err.contains("finish it with the coin-log that started it, or start over in a new folder"),
        "{err}"
    );
    std::fs::write(&plan_path, plan).unwrap();
    let (code, json) = sweep_json(dir.path(), "s.toml", "out", &[]);
    assert_eq!((code, json["done"].as_u64()), (0, Some(0)), "{json}");
}

#[test]
fn the_sweep_subcommand_needs_its_arguments_and_documents_itself() {
    let (code, _, err) = run_in(Path::new("."), &["sweep"]);
    assert_eq!(code, 2, "{err}");
    let (code, _, err) = run_in(Path::new("."), &["sweep", "s.toml"]);
    assert_eq!(code, 2);
    assert!(
        err.contains("--output <DIR>"),
        "-o is required but for --dry-run: {err}"
    );
    let (code, _, err) = run_in(
        Path::new("."),
        &["sweep", "x.toml", "-o", "d", "--shard", "4/4"],
    );
    assert_eq!(code, 2);
    assert!(err.contains("K must be 0 … N − 1"), "{err}");
    let out = std::process::Command::new(exe())
        .args(["sweep", "--help"])
        .output()
        .unwrap();
    let help = String::from_utf8_lossy(&out.stdout);
    for flag in [
        "--jobs",
        "--shard",
        "--shard-count",
        "--retry-failed",
        "--dry-run",
        "--json",
        "collect",
    ] {
        assert!(help.contains(flag), "{flag} in --help:\n{help}");
    }
}

#[test]
fn linspace_is_exact_at_the_ends_and_even_between() {
    let v = linspace(0.1, 0.7, 7);
    assert_eq!(v.first().map(|x| x.to_bits()), Some(0.1f64.to_bits()));
    assert_eq!(v.last().map(|x| x.to_bits()), Some(0.7f64.to_bits()));
    for (k, x) in v.iter().enumerate() {
        let expected = 0.1 + 0.1 * k as f64;
        assert!(
            (x - expected).abs() < 1e-15,
            "v[{k}] = {x}, expected {expected}"
        );
    }
    assert_eq!(linspace(3.0, 5.0, 1), vec![3.0]);
    assert_eq!(linspace(1.0, -1.0, 3), vec![1.0, 0.0, -1.0]);
}

#[test]
fn logspace_gives_exact_decades_and_powf_between() {
    let v = logspace(-12.0, -6.0, 4);
    assert_eq!(v, vec![1e-12, 1e-10, 1e-8, 1e-6]);
    let half = logspace(0.0, 1.0, 3);
    assert_eq!(half[1].to_bits(), 10f64.powf(0.5).to_bits());
}

#[test]
fn the_hash_of_abc_is_the_fips_example() {
    assert_eq!(
        sha256_hex(b"abc"),
        "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
    );
}

#[test]
fn a_stop_request_with_no_run_left_is_not_an_interruption() {
    // A SIGINT that came after the last run ended still made the sweep "interrupted" (exit 130), so a
    // Slurm afterok skipped collect. Here the stop is set before a resume that has nothing left to do.
    let dir = tempfile::tempdir().unwrap();
    write_sweep(dir.path(), "s.toml", SMALL);
    assert_eq!(sweep_json(dir.path(), "s.toml", "out", &[]).0, 0);
    let sweep = Sweep::load(&dir.path().join("s.toml")).unwrap();
    let options = coin_log::sweep::RunOptions {
        jobs: 1,
        shard: coin_log::sweep::Shard::ALL,
        retry_failed: false,
    };
    let stop = std::sync::atomic::AtomicBool::new(true);
    let outcome = coin_log::sweep::run(
        &sweep,
        &dir.path().join("out"),
        &options,
        &stop,
        &mut |_| {},
    )
    .unwrap();
    assert_eq!(
        (outcome.pending, outcome.interrupted),
        (0, false),
        "{outcome:?}"
    );
    // Negative control: with a run left, the same request is an interruption.
    std::fs::remove_file(dir.path().join("out/run-00.mcap")).unwrap();
    let outcome = coin_log::sweep::run(
        &sweep,
        &dir.path().join("out"),
        &options,
        &stop,
        &mut |_| {},
    )
    .unwrap();
    assert!(outcome.interrupted && outcome.pending == 1, "{outcome:?}");
}

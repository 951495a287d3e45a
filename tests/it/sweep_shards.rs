//! Shards and collect (docs/format.md: Shards and collect): for N = 1 … 5 the shards K/N together make
//! every run exactly once, and the collected catalogue equals the one-process one (wall times aside);
//! the schedulers' variables pick the shard; collect names a missing part, a run in two parts and a
//! changed, cut or lost file, and then writes nothing.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use crate::support::record::{exe, listing};
use crate::sweep::{
    run_files, run_in, run_with_env, sweep_json, write_sweep, Csv, SMALL, SMALL_RUNS,
};
use coin_log::sweep::Shard;
use std::collections::HashMap;
use std::path::Path;
use std::process::Command;

fn rows(path: &Path) -> Vec<Vec<String>> {
    Csv::read(path).without_wall_time()
}

/// `collect DIR` in `dir`: exit code and stderr.
fn collect(dir: &Path, folder: &str) -> (i32, String) {
    let (code, _, err) = run_in(dir, &["sweep", "collect", folder]);
    (code, err)
}

#[test]
fn the_shards_of_every_count_make_each_run_once_and_collect_to_the_one_process_catalogue() {
    let dir = tempfile::tempdir().unwrap();
    write_sweep(dir.path(), "s.toml", SMALL);
    assert_eq!(
        sweep_json(dir.path(), "s.toml", "one", &["--jobs", "1"]).0,
        0
    );
    let reference = rows(&dir.path().join("one/catalogue.csv"));
    let summary = std::fs::read_to_string(dir.path().join("one/sweep.json")).unwrap();
    for n in 1..=5u64 {
        let folder = format!("n{n}");
        let mut made = vec![0; SMALL_RUNS];
        for k in 0..n {
            let shard = format!("{k}/{n}");
            let (code, json) = sweep_json(
                dir.path(),
                "s.toml",
                &folder,
                &["--shard", &shard, "--jobs", "2"],
            );
            assert_eq!(code, 0, "{json}");
            let part = if n == 1 {
                "catalogue.csv".to_string()
            } else {
                format!("catalogue.part-{k}-of-{n}.csv")
            };
            for row in Csv::read(&dir.path().join(&folder).join(part)).records() {
                let index: usize = row["index"].parse().unwrap();
                assert_eq!(index as u64 % n, k, "shard {shard} holds run {index}");
                made[index] += 1;
            }
        }
        assert!(
            made.iter().all(|&m| m == 1),
            "N = {n}: every run exactly once: {made:?}"
        );
        if n > 1 {
            assert!(
                !dir.path().join(&folder).join("catalogue.csv").exists(),
                "a shard writes only its part"
            );
            let (code, err) = collect(dir.path(), &folder);
            assert_eq!(code, 0, "{err}");
        }
        let collected = dir.path().join(&folder);
        assert_eq!(
            rows(&collected.join("catalogue.csv")),
            reference,
            "N = {n}: collected = one process, wall times aside"
        );
        assert_eq!(
            std::fs::read_to_string(collected.join("sweep.json")).unwrap(),
            summary,
            "N = {n}"
        );
        assert_eq!(run_files(&collected).len(), SMALL_RUNS);
    }
}

/// A task resubmitted alone (`sbatch --array=7`, which README once advised) is a one-task array: the
/// whole sweep, writing the catalogue and no part 7. It says so, naming `--shard 7/N`; a one-task array
/// numbered 0 (`--array=0`) is a plain whole sweep, without a word.
#[test]
fn a_task_resubmitted_alone_is_warned_that_it_makes_the_whole_sweep() {
    let dir = tempfile::tempdir().unwrap();
    write_sweep(dir.path(), "s.toml", SMALL);
    let alone = [
        ("SLURM_ARRAY_TASK_ID", "7"),
        ("SLURM_ARRAY_TASK_MIN", "7"),
        ("SLURM_ARRAY_TASK_MAX", "7"),
        ("SLURM_ARRAY_TASK_COUNT", "1"),
    ];
    let (code, out, err) = run_with_env(dir.path(), &["sweep", "s.toml", "--dry-run"], &alone);
    assert_eq!(code, 0, "{out}{err}");
    assert!(err.contains("warning: this job array has one task (SLURM_ARRAY_TASK_ID = 7), so it makes the whole sweep (shard 0/1) and writes catalogue.csv, not a part; to redo shard 7 of an array of N tasks, pass --shard 7/N"), "{err}");
    let zero = alone.map(|(k, v)| (k, if v == "7" { "0" } else { v }));
    let (code, _, err) = run_with_env(dir.path(), &["sweep", "s.toml", "--dry-run"], &zero);
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains("warning"), "{err}");
}

/// examples/slurm-sweep.sh's advice for a failed task, followed literally: an array of 4 tasks loses task
/// 2, the array its header says to submit again is run (its `--array=0-15` read as this array's 0-3; an
/// index alone as that task alone, which the header once advised), and then collect must pass. An array
/// of one index is the whole sweep: it wrote catalogue.csv, no part 2, and collect still missed shard 2.
#[test]
fn the_example_job_scripts_advice_for_a_failed_task_makes_collect_pass() {
    let dir = tempfile::tempdir().unwrap();
    write_sweep(dir.path(), "s.toml", SMALL);
    let script = crate::support::repo().join("examples/slurm-sweep.sh");
    let header = std::fs::read_to_string(&script).unwrap();
    let advice = &header[header
        .find("redone by")
        .expect("the header says how a failed task is redone")..];
    let array = advice
        .split("--array=")
        .nth(1)
        .expect("the advice names an array");
    let array: String = array
        .chars()
        .take_while(|c| c.is_ascii_digit() || *c == '-')
        .collect();
    // The tasks of an array numbered MIN … MAX, run in turn as Slurm would, with its variables, into
    // `folder` with sweep options `extra`.
    let task_into = |folder: &str, id: u64, min: u64, max: u64, extra: &[&str]| {
        let out = Command::new("bash")
            .arg(&script)
            .args(["s.toml", folder])
            .args(extra)
            .current_dir(dir.path())
            .env("COIN_LOG", crate::support::record::exe())
            .envs([
                ("SLURM_ARRAY_TASK_ID", id.to_string()),
                ("SLURM_ARRAY_TASK_MIN", min.to_string()),
                ("SLURM_ARRAY_TASK_MAX", max.to_string()),
                ("SLURM_ARRAY_TASK_COUNT", (max - min + 1).to_string()),
            ])
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "task {id}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    };
    let task = |id: u64, min: u64, max: u64| task_into("shared", id, min, max, &[]);
    for id in [0, 1, 3] {
        task(id, 0, 3);
    }
    match array.as_str() {
        "0-15" => (0..4).for_each(|id| task(id, 0, 3)),
        one if one.parse::<u64>().is_ok() => task(2, 2, 2),
        other => panic!(
            "the header's advice names --array={other}, neither the whole array nor one index"
        ),
    }
    let (code, err) = collect(dir.path(), "shared");
    assert_eq!(
        code, 0,
        "collect after the example's advice (--array={array}): {err}"
    );
    // The one-task array given its shard, as the header and the one-task warning say: the script takes
    // options after DIR (it took exactly two arguments, so the warning's --shard K/N could not be given).
    for id in [0, 1, 3] {
        task_into("alone", id, 0, 3, &[]);
    }
    task_into("alone", 2, 2, 2, &["--shard", "2/4"]);
    let (code, err) = collect(dir.path(), "alone");
    assert_eq!(
        code, 0,
        "collect after the one task given --shard 2/4: {err}"
    );
}

/// A shard whose runs fail for their values exits 1 every time it is submitted again (those failures
/// recur, and only I/O failures are redone), so README's `sbatch --wait ... && collect` and the example's
/// `afterok` never collected such a sweep, and README's only advice for a failed task (submit the array
/// again) looped. collect itself writes the catalogue with the failed rows: README and the example say
/// to run it then.
#[test]
fn shards_whose_runs_fail_for_their_values_fail_every_time_and_collect_is_run_by_hand() {
    let dir = tempfile::tempdir().unwrap();
    // Every draw fails (a negative thickness), so that each shard has failed runs whatever the draws.
    let bad = SMALL.replace("choice = [0.04, 0.06]", "choice = [-0.04, -0.06]");
    write_sweep(dir.path(), "s.toml", &bad);
    for _ in 0..2 {
        for k in 0..2 {
            let shard = format!("{k}/2");
            let (code, json) = sweep_json(dir.path(), "s.toml", "d", &["--shard", &shard]);
            assert_eq!(code, 1, "{json}");
            assert!(json["failed"].as_u64() > Some(0), "{json}");
        }
    }
    let (code, json) = sweep_json(dir.path(), "s.toml", "d", &["--shard", "0/2"]);
    assert_eq!(
        (code, json["done"].as_u64()),
        (1, Some(0)),
        "submitting again redoes nothing: {json}"
    );
    let (code, err) = collect(dir.path(), "d");
    assert_eq!(code, 1, "{err}");
    assert!(
        dir.path().join("d/catalogue.csv").is_file(),
        "collect wrote the catalogue"
    );
    let readme = std::fs::read_to_string(crate::support::repo().join("README.md")).unwrap();
    let readme = readme.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(
        readme.contains("A task also exits 1 when some of its runs failed for their values"),
        "README"
    );
    assert!(
        readme.contains("run `coin-log sweep collect /shared/lean-sweep` yourself then"),
        "README"
    );
    let example =
        std::fs::read_to_string(crate::support::repo().join("examples/slurm-sweep.sh")).unwrap();
    assert!(
        example.contains("so run `coin-log sweep collect DIR`\n# yourself then"),
        "examples/slurm-sweep.sh"
    );
}

#[test]
fn slurm_array_variables_and_a_kubernetes_index_pick_the_shard() {
    let dir = tempfile::tempdir().unwrap();
    write_sweep(dir.path(), "s.toml", SMALL);
    let slurm = [
        ("SLURM_ARRAY_TASK_ID", "5"),
        ("SLURM_ARRAY_TASK_MIN", "4"),
        ("SLURM_ARRAY_TASK_MAX", "6"),
        ("SLURM_ARRAY_TASK_COUNT", "3"),
    ];
    let (code, out, err) = run_with_env(
        dir.path(),
        &["sweep", "s.toml", "-o", "slurm", "--json"],
        &slurm,
    );
    assert_eq!(code, 0, "{out}{err}");
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(
        (j["shard"].as_str(), j["runs"].as_u64()),
        (Some("1/3"), Some(4)),
        "task 5 of 4–6 is shard 1/3"
    );
    let indexes: Vec<String> = Csv::read(&dir.path().join("slurm/catalogue.part-1-of-3.csv"))
        .records()
        .iter()
        .map(|r| r["index"].clone())
        .collect();
    assert_eq!(indexes, ["1", "4", "7", "10"]);
    let (code, out, err) = run_with_env(
        dir.path(),
        &[
            "sweep",
            "s.toml",
            "-o",
            "k8s",
            "--json",
            "--shard-count",
            "4",
        ],
        &[("JOB_COMPLETION_INDEX", "3")],
    );
    assert_eq!(code, 0, "{out}{err}");
    assert!(
        dir.path().join("k8s/catalogue.part-3-of-4.csv").exists(),
        "{:?}",
        listing(&dir.path().join("k8s"))
    );
    // --shard wins over the environment.
    let (code, out, _) = run_with_env(
        dir.path(),
        &["sweep", "s.toml", "-o", "flag", "--json", "--shard", "0/2"],
        &slurm,
    );
    assert_eq!(code, 0);
    assert!(out.contains("\"shard\":\"0/2\""), "{out}");
    for (env, flags, says) in [
        (
            vec![
                ("SLURM_ARRAY_TASK_ID", "2"),
                ("SLURM_ARRAY_TASK_MIN", "0"),
                ("SLURM_ARRAY_TASK_MAX", "6"),
                ("SLURM_ARRAY_TASK_COUNT", "4"),
            ],
            vec![],
            "submit --array=0-3",
        ),
        (
            vec![("JOB_COMPLETION_INDEX", "1")],
            vec![],
            "pass --shard-count N",
        ),
        (
            vec![],
            vec!["--shard-count", "2"],
            "needs JOB_COMPLETION_INDEX",
        ),
        (
            vec![
                ("SLURM_ARRAY_TASK_ID", "x"),
                ("SLURM_ARRAY_TASK_COUNT", "2"),
            ],
            vec![],
            "SLURM_ARRAY_TASK_ID=x is not a whole number",
        ),
    ] {
        let mut args = vec!["sweep", "s.toml", "-o", "bad"];
        args.extend(flags);
        let (code, _, err) = run_with_env(dir.path(), &args, &env);
        assert_eq!(code, 2, "{err}");
        assert!(err.contains(says), "`{says}` in: {err}");
        assert!(
            !dir.path().join("bad").exists(),
            "nothing written for a bad shard"
        );
    }
}

#[test]
fn collect_names_a_missing_part_a_run_in_two_parts_and_changed_files_and_then_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    write_sweep(dir.path(), "s.toml", SMALL);
    assert_eq!(
        sweep_json(dir.path(), "s.toml", "one", &["--jobs", "1"]).0,
        0
    );
    all_shards(dir.path(), "s.toml", "d", 3);
    let d = dir.path().join("d");
    let part = |k: u64| d.join(format!("catalogue.part-{k}-of-3.csv"));
    let refused = |says: &[&str]| {
        let (code, err) = collect(dir.path(), "d");
        assert_eq!(code, 1, "{err}");
        for s in says {
            assert!(err.contains(s), "`{s}` in:\n{err}");
        }
        assert!(err.trim_end().ends_with("; nothing written"), "{err}");
        assert!(
            !d.join("catalogue.csv").exists() && !d.join("sweep.json").exists(),
            "collect wrote despite problems"
        );
    };
    // A missing part.
    let saved = std::fs::read(part(1)).unwrap();
    std::fs::remove_file(part(1)).unwrap();
    refused(&[
        "error: d: 4 of 12 runs are in no part: 1, 4, 7, 10; run the shards that hold them again",
    ]);
    std::fs::write(part(1), &saved).unwrap();
    // A run in two parts (a part of an earlier sharding left behind), and a part of another sweep.
    let other_n = d.join("catalogue.part-0-of-2.csv");
    let text = std::fs::read_to_string(part(0)).unwrap();
    std::fs::write(
        &other_n,
        text.lines()
            .take(2)
            .map(|l| format!("{l}\n"))
            .collect::<String>(),
    )
    .unwrap();
    let foreign = d.join("catalogue.part-1-of-2.csv");
    std::fs::write(&foreign, "index,x\n1,2\n").unwrap();
    refused(&[
        "run 0 is in both `catalogue.part-0-of-2.csv` and `catalogue.part-0-of-3.csv`",
        "`catalogue.part-1-of-2.csv` does not start with this sweep's header",
    ]);
    std::fs::remove_file(&other_n).unwrap();
    std::fs::remove_file(&foreign).unwrap();
    // A file changed (same size), one cut, one gone.
    let mut changed = std::fs::read(d.join("run-04.mcap")).unwrap();
    changed[500] ^= 0x20;
    std::fs::write(d.join("run-04.mcap"), &changed).unwrap();
    let cut = std::fs::read(d.join("run-07.mcap")).unwrap();
    std::fs::write(d.join("run-07.mcap"), &cut[..100]).unwrap();
    std::fs::remove_file(d.join("run-10.mcap")).unwrap();
    refused(&[
        "`run-04.mcap` (run 4) does not match its row's SHA-256: it was changed; run its shard again to redo it",
        "`run-07.mcap` (run 7) has 100 bytes, its row",
        "`run-10.mcap` (run 10) cannot be read",
    ]);
    // The shards run again redo exactly those three; then collect writes the one catalogue.
    let mut redone = 0;
    for k in 0..3 {
        let (code, json) = sweep_json(dir.path(), "s.toml", "d", &["--shard", &format!("{k}/3")]);
        assert_eq!(code, 0);
        redone += json["done"].as_u64().unwrap();
    }
    assert_eq!(redone, 3);
    let (code, out, err) = run_in(dir.path(), &["sweep", "collect", "d", "--json"]);
    assert_eq!(code, 0, "{err}");
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(
        (
            j["runs"].as_u64(),
            j["finished"].as_u64(),
            j["problems"].as_array().map(Vec::len)
        ),
        (Some(12), Some(12), Some(0))
    );
    assert_eq!(
        rows(&d.join("catalogue.csv")),
        rows(&dir.path().join("one/catalogue.csv"))
    );
    // A folder with no sweep in it.
    std::fs::create_dir(dir.path().join("empty")).unwrap();
    let (code, err) = collect(dir.path(), "empty");
    assert_eq!(code, 2);
    assert!(err.contains("holds no sweep"), "{err}");
}

/// Sweeps `file` into `folder` of `dir` as all `n` shards, one after the other, each exiting 0.
fn all_shards(dir: &Path, file: &str, folder: &str, n: u64) {
    for k in 0..n {
        let shard = format!("{k}/{n}");
        assert_eq!(
            sweep_json(dir, file, folder, &["--shard", &shard]).0,
            0,
            "shard {shard}"
        );
    }
}

/// `collect` on a folder swept whole says that the sweep wrote the catalogue itself, instead of calling
/// every run missing and advising to run "the shards that hold them" again (which, one shard being the
/// whole sweep, wrote no part either, so collect refused for ever); the catalogue is left as it was.
#[test]
fn collect_on_a_folder_swept_whole_says_the_sweep_wrote_its_catalogue() {
    let dir = tempfile::tempdir().unwrap();
    write_sweep(dir.path(), "s.toml", SMALL);
    assert_eq!(sweep_json(dir.path(), "s.toml", "w", &[]).0, 0);
    let catalogue = std::fs::read(dir.path().join("w/catalogue.csv")).unwrap();
    let (code, err) = collect(dir.path(), "w");
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("it was swept whole, not in shards, so the sweep wrote its catalogue.csv and sweep.json itself"), "{err}");
    assert!(
        !err.contains("in no part") && !err.contains("run the shards"),
        "{err}"
    );
    assert_eq!(
        std::fs::read(dir.path().join("w/catalogue.csv")).unwrap(),
        catalogue
    );
}

#[test]
fn collect_refuses_a_part_whose_row_names_another_runs_file() {
    // Two rows of a part with their indexes swapped: each file still matches its row's size and
    // SHA-256, so only the file's name shows that run 0's row holds run 3's values (collect once wrote
    // that catalogue).
    let dir = tempfile::tempdir().unwrap();
    write_sweep(dir.path(), "s.toml", SMALL);
    all_shards(dir.path(), "s.toml", "d", 3);
    let part = dir.path().join("d/catalogue.part-0-of-3.csv");
    let text = std::fs::read_to_string(&part).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let (a, b) = (
        lines[1].split_once(',').unwrap(),
        lines[2].split_once(',').unwrap(),
    );
    let swapped = [format!("{},{}", b.0, a.1), format!("{},{}", a.0, b.1)];
    lines.splice(1..3, swapped);
    std::fs::write(&part, lines.join("\n") + "\n").unwrap();
    let (code, err) = collect(dir.path(), "d");
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("`catalogue.part-0-of-3.csv` line 3: run 0's row names the file `run-03.mcap`, not `run-00.mcap`"),
        "{err}"
    );
    assert!(!dir.path().join("d/catalogue.csv").exists());
}

#[test]
fn collect_names_a_damaged_parts_first_wrong_lines_and_counts_the_rest() {
    // 100 garbage lines gave 100 errors (300 000 gave 300 000), and bytes that are no UTF-8 gave the bare
    // "stream did not contain valid UTF-8", no fix.
    let dir = tempfile::tempdir().unwrap();
    write_sweep(dir.path(), "s.toml", SMALL);
    all_shards(dir.path(), "s.toml", "d", 2);
    let part = dir.path().join("d/catalogue.part-1-of-2.csv");
    let text = std::fs::read_to_string(&part).unwrap();
    std::fs::write(&part, text.clone() + &"garbage\n".repeat(100)).unwrap();
    let (code, err) = collect(dir.path(), "d");
    assert_eq!(code, 1, "{err}");
    assert_eq!(err.matches("not a row of this sweep").count(), 20, "{err}");
    assert!(err.contains("error: d: `catalogue.part-1-of-2.csv`: 80 more lines are wrong as well: run its shard again"), "{err}");
    // A row twice in one part: the other-sharding fix ("in both `p` and `p`") did not apply.
    let second = text.lines().nth(1).unwrap();
    std::fs::write(&part, format!("{text}{second}\n")).unwrap();
    let (code, err) = collect(dir.path(), "d");
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("`catalogue.part-1-of-2.csv` line 8: run 1's row is in the part twice: the part was changed; run its shard again"), "{err}");
    // A run file of another size is not read: a sparse 1 TB one took half an hour to hash.
    std::fs::write(&part, &text).unwrap();
    let run = dir.path().join("d/run-01.mcap");
    let kept = std::fs::read(&run).unwrap();
    std::fs::File::options()
        .write(true)
        .open(&run)
        .unwrap()
        .set_len(1 << 40)
        .unwrap();
    let started = std::time::Instant::now();
    let (code, err) = collect(dir.path(), "d");
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("`run-01.mcap` (run 1) has 1099511627776 bytes, its row"),
        "{err}"
    );
    assert!(
        started.elapsed().as_secs() < 20,
        "read for {:?}",
        started.elapsed()
    );
    std::fs::write(&run, kept).unwrap();
    // An index written `+01` (it parses as 1): the catalogue held `+01`.
    std::fs::write(&part, text.replacen("\n1,", "\n+01,", 1)).unwrap();
    let (code, err) = collect(dir.path(), "d");
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("`catalogue.part-1-of-2.csv` line 2: not a row of this sweep"),
        "{err}"
    );
    let mut bytes = text.into_bytes();
    bytes.extend_from_slice(b"\xff\xfe\n");
    std::fs::write(&part, bytes).unwrap();
    let (code, err) = collect(dir.path(), "d");
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("`catalogue.part-1-of-2.csv` is not UTF-8 text, so not a part as a shard writes it: delete it and run its shard again"), "{err}");
}

/// Runs of an earlier sharding beyond the first 20 of a part were counted as "more lines are wrong as
/// well: run its shard again", which mends nothing (the shard writes its part as it was, still beside the
/// earlier sharding's): they are counted as runs in another part, with the fix that works.
#[test]
fn collect_counts_the_unlisted_runs_of_an_earlier_sharding_with_their_fix() {
    let dir = tempfile::tempdir().unwrap();
    let many = SMALL.replace("count = 2", "count = 16");
    write_sweep(dir.path(), "s.toml", &many);
    all_shards(dir.path(), "s.toml", "d", 2);
    all_shards(dir.path(), "s.toml", "d", 4);
    let (code, err) = collect(dir.path(), "d");
    assert_eq!(code, 1, "{err}");
    // 96 runs: each part of 4 holds 24, every one also in a part of 2; 20 named, 4 counted.
    assert!(err.contains("error: d: run 0 is in both `catalogue.part-0-of-2.csv` and `catalogue.part-0-of-4.csv`: delete the parts of an earlier sharding"), "{err}");
    assert!(err.contains("error: d: `catalogue.part-0-of-4.csv`: 4 more of its runs are in another part as well: delete the parts of an earlier sharding (shards of one N make each run once)"), "{err}");
    assert!(!err.contains("run its shard again"), "{err}");
    for k in 0..2 {
        std::fs::remove_file(dir.path().join(format!("d/catalogue.part-{k}-of-2.csv"))).unwrap();
    }
    let (code, err) = collect(dir.path(), "d");
    assert_eq!(code, 0, "the fix given works: {err}");
}

#[test]
fn collect_refuses_a_row_no_run_writes() {
    // A finished row with its file, size and SHA-256 blanked (and the file gone) had nothing to check,
    // so collect wrote a catalogue with a finished run and no file; a verifying sweep's row saying
    // `verify` = off passed as well.
    let dir = tempfile::tempdir().unwrap();
    write_sweep(dir.path(), "s.toml", SMALL);
    all_shards(dir.path(), "s.toml", "d", 2);
    let part = dir.path().join("d/catalogue.part-1-of-2.csv");
    let text = std::fs::read_to_string(&part).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    // Run 1's file, bytes and SHA-256 (no commas in them) blanked; run 3's verify cell `off`.
    let (head, rest) = lines[1].split_once(",run-01.mcap,").unwrap();
    let rest = rest.splitn(3, ',').nth(2).unwrap();
    lines[1] = format!("{head},,,,{rest}");
    assert!(lines[2].contains(",finished,"), "{}", lines[2]);
    lines[2] = lines[2].replacen(",ok,", ",off,", 1);
    std::fs::write(&part, lines.join("\n") + "\n").unwrap();
    std::fs::remove_file(dir.path().join("d/run-01.mcap")).unwrap();
    let (code, err) = collect(dir.path(), "d");
    assert_eq!(code, 1, "{err}");
    for needle in [
        "`catalogue.part-1-of-2.csv` line 2: run 1's row is none a run writes (status `finished`, failure ``, file ``, verify `ok`): the part was changed; run its shard again",
        "`catalogue.part-1-of-2.csv` line 3: run 3's row is none a run writes (status `finished`, failure ``, file `run-03.mcap`, verify `off`)",
    ] {
        assert!(err.contains(needle), "{err}");
    }
    assert!(!dir.path().join("d/catalogue.csv").exists());
}

#[test]
fn collect_refuses_a_part_of_another_sweep_with_the_same_keys() {
    // Another sweep's part (same keys and columns, other values) and its files copied in: every row
    // named its own run's file with the right size and SHA-256, so collect wrote a catalogue holding the
    // other sweep's values under this sweep's identity. The plan gives each run's values.
    let dir = tempfile::tempdir().unwrap();
    write_sweep(dir.path(), "s.toml", SMALL);
    let other = SMALL.replace("values = [0.2, 0.6, 1.0]", "values = [0.3, 0.6, 1.0]");
    write_sweep(dir.path(), "o.toml", &other);
    for (file, folder) in [("s.toml", "d"), ("o.toml", "o")] {
        all_shards(dir.path(), file, folder, 3);
    }
    let (d, o) = (dir.path().join("d"), dir.path().join("o"));
    for name in ["catalogue.part-1-of-3.csv", "run-01.mcap", "run-07.mcap"] {
        std::fs::copy(o.join(name), d.join(name)).unwrap();
    }
    let before = listing(&d);
    let (code, err) = collect(dir.path(), "d");
    assert_eq!(code, 1, "{err}");
    for (line, run) in [(2, 1), (4, 7)] {
        let problem = format!(
            "`catalogue.part-1-of-3.csv` line {line}: run {run}'s row has initial.theta = `0.3`, but this \
             sweep's run {run} has `0.2`: the part is another sweep's; delete it and run its shard again"
        );
        assert!(err.contains(&problem), "{err}");
    }
    assert_eq!(listing(&d), before, "nothing written");
    // Shard 1 run again (its journal is this sweep's: the copied files are redone) is collected.
    assert_eq!(
        sweep_json(dir.path(), "s.toml", "d", &["--shard", "1/3"]).0,
        0
    );
    assert_eq!(collect(dir.path(), "d").0, 0);
}

#[test]
fn shards_started_at_once_on_a_new_folder_share_it_as_a_job_array_does() {
    let dir = tempfile::tempdir().unwrap();
    write_sweep(dir.path(), "s.toml", SMALL);
    assert_eq!(
        sweep_json(dir.path(), "s.toml", "one", &["--jobs", "1"]).0,
        0
    );
    let children: Vec<_> = (0..4)
        .map(|k| {
            let mut command = std::process::Command::new(crate::support::record::exe());
            for v in crate::sweep::SCHEDULER_VARIABLES {
                command.env_remove(v);
            }
            command
                .args([
                    "sweep",
                    "s.toml",
                    "-o",
                    "together",
                    "--jobs",
                    "1",
                    "--shard",
                    &format!("{k}/4"),
                ])
                .current_dir(dir.path())
                .stdout(std::process::Stdio::null())
                .stderr(std::process::Stdio::piped())
                .spawn()
                .unwrap()
        })
        .collect();
    for child in children {
        let out = child.wait_with_output().unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let (code, err) = collect(dir.path(), "together");
    assert_eq!(code, 0, "{err}");
    assert_eq!(
        rows(&dir.path().join("together/catalogue.csv")),
        rows(&dir.path().join("one/catalogue.csv"))
    );
}

/// Holds shard `shard`'s lock in `folder` as a running sweep would (an advisory lock on its own open
/// file: a second one conflicts with it even within this process).
fn hold_lock(folder: &Path, shard: &str) -> std::fs::File {
    let (k, n) = shard.split_once('/').unwrap();
    let path = folder.join(format!(".coin-log-sweep/lock-{k}-of-{n}"));
    let file = std::fs::File::create(path).unwrap();
    file.try_lock().unwrap();
    file
}

#[test]
fn a_shard_that_a_running_sweep_makes_is_refused_and_collect_waits_for_it() {
    let dir = tempfile::tempdir().unwrap();
    write_sweep(dir.path(), "s.toml", SMALL);
    let (code, json) = sweep_json(dir.path(), "s.toml", "d", &["--shard", "0/2"]);
    assert_eq!(code, 0, "{json}");
    let folder = dir.path().join("d");
    let journals = || {
        let state = folder.join(".coin-log-sweep");
        let names = listing(&state)
            .into_iter()
            .filter(|n| n.starts_with("journal-"));
        names
            .map(|n| (std::fs::read(state.join(&n)).unwrap(), n))
            .collect::<Vec<_>>()
    };
    let before = (listing(&folder), journals());
    let held = hold_lock(&folder, "1/2");
    // The same shard, and the whole sweep (which shares shard 1/2's runs): refused, nothing changed.
    for (args, says) in [
        (&["--shard", "1/2"][..], "is making shard 1/2 now ("),
        (
            &[][..],
            "is making shard 1/2 now, which shares runs with shard 0/1 (",
        ),
    ] {
        let (code, out, err) = run_in(
            dir.path(),
            &[&["sweep", "s.toml", "-o", "d"][..], args].concat(),
        );
        assert_eq!(code, 2, "{args:?}: {out}{err}");
        assert!(
            err.contains("`d`: is in use: another `coin-log sweep` ") && err.contains(says),
            "{args:?}: {err}"
        );
        assert_eq!((listing(&folder), journals()), before, "{args:?}");
    }
    // A shard that shares no run with it goes ahead (shard 0/2 again: nothing to do).
    let (code, json) = sweep_json(dir.path(), "s.toml", "d", &["--shard", "0/2"]);
    assert_eq!(code, 0, "{json}");
    let (code, err) = collect(dir.path(), "d");
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("shard 1/2 is still running in `"), "{err}");
    // Its runs are in no part yet, as expected while it runs: advising to run that shard again (which
    // is refused while it runs) was premature.
    assert!(
        !err.contains("in no part") && !err.contains("run the shards"),
        "{err}"
    );
    // Every running shard is named: two arrays on one folder, only the first was.
    let other = hold_lock(&folder, "3/4");
    let (code, err) = collect(dir.path(), "d");
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("shards 1/2, 3/4 are still running in `"),
        "{err}"
    );
    drop(other);
    // Negative control: once the lock is released, the same commands go through.
    drop(held);
    let (code, json) = sweep_json(dir.path(), "s.toml", "d", &["--shard", "1/2"]);
    assert_eq!(code, 0, "{json}");
    let (code, err) = collect(dir.path(), "d");
    assert_eq!(code, 0, "{err}");
}

#[test]
fn links_in_the_sweep_folder_are_refused_never_written_through_or_replaced() {
    let dir = tempfile::tempdir().unwrap();
    write_sweep(dir.path(), "s.toml", SMALL);
    let victim = dir.path().join("victim");
    std::fs::write(&victim, "keep me\n").unwrap();
    assert_eq!(
        sweep_json(dir.path(), "s.toml", "d", &["--shard", "0/2"]).0,
        0
    );
    let d = dir.path().join("d");
    let link = |name: &str| {
        let path = d.join(name);
        std::os::unix::fs::symlink(&victim, &path).unwrap();
        path
    };
    // A journal through a link: appending would write into the victim.
    let journal = link(".coin-log-sweep/journal-1-of-2.csv");
    let (code, out, err) = run_in(
        dir.path(),
        &["sweep", "s.toml", "-o", "d", "--shard", "1/2"],
    );
    assert_eq!(code, 1, "{out}{err}");
    assert!(
        err.contains("journal-1-of-2.csv`: is a symbolic link (to `"),
        "{err}"
    );
    std::fs::remove_file(&journal).unwrap();
    // A run's name held by a link: that run fails on I/O, the link stays.
    let run = link("run-01.mcap");
    let (code, json) = sweep_json(dir.path(), "s.toml", "d", &["--shard", "1/2"]);
    assert_eq!(code, 1, "{json}");
    assert_eq!(json["failed"], 1, "{json}");
    assert!(std::fs::symlink_metadata(&run)
        .unwrap()
        .file_type()
        .is_symlink());
    std::fs::remove_file(&run).unwrap();
    assert_eq!(
        sweep_json(dir.path(), "s.toml", "d", &["--shard", "1/2"]).0,
        0
    );
    // The catalogue's name held by a link: collect refuses rather than replacing it.
    let catalogue = link("catalogue.csv");
    let (code, err) = collect(dir.path(), "d");
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("catalogue.csv`: is a symbolic link (to `"),
        "{err}"
    );
    assert!(std::fs::symlink_metadata(&catalogue)
        .unwrap()
        .file_type()
        .is_symlink());
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "keep me\n");
    std::fs::remove_file(&catalogue).unwrap();
    // sweep.json's name held by a link: refused before anything is written (the catalogue was written,
    // then sweep.json refused: half the pair).
    let summary = link("sweep.json");
    let (code, err) = collect(dir.path(), "d");
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("sweep.json`: is a symbolic link (to `"),
        "{err}"
    );
    assert!(
        !d.join("catalogue.csv").exists(),
        "catalogue written without sweep.json"
    );
    std::fs::remove_file(&summary).unwrap();
    // A part that is a pipe is named once, not once per cause in the error's chain.
    let pipe = d.join("catalogue.part-9-of-10.csv");
    crate::support::mkfifo(&pipe);
    let (code, err) = collect(dir.path(), "d");
    assert_eq!(code, 1, "{err}");
    assert_eq!(err.matches("is a named pipe").count(), 1, "{err}");
    std::fs::remove_file(&pipe).unwrap();
    // Negative control: without the link and the pipe, collect writes the catalogue.
    assert_eq!(collect(dir.path(), "d").0, 0);
}

// The library's Shard alone: its arithmetic and the schedulers' variables.

#[test]
fn a_state_folder_that_is_a_link_or_a_file_and_a_dangling_output_link_are_refused() {
    // `.coin-log-sweep` as a link was followed (the plan, journal and lock written into the folder it
    // points to); as a file, and -o as a dangling link, gave "File exists (os error 17)", exit 1.
    use std::os::unix::fs::symlink;
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_sweep(d, "s.toml", SMALL);
    std::fs::create_dir_all(d.join("linked")).unwrap();
    std::fs::create_dir_all(d.join("elsewhere")).unwrap();
    symlink("../elsewhere", d.join("linked/.coin-log-sweep")).unwrap();
    std::fs::create_dir_all(d.join("filed")).unwrap();
    std::fs::write(d.join("filed/.coin-log-sweep"), "mine").unwrap();
    symlink("nowhere", d.join("dangling")).unwrap();
    for (out, says) in [
        ("linked", "`linked`: holds `.coin-log-sweep` as a symbolic link, not the folder a sweep keeps its state in"),
        ("filed", "`filed`: holds `.coin-log-sweep` as a file, not the folder a sweep keeps its state in"),
        ("dangling", "`dangling`: is a symbolic link to `nowhere`, which does not exist: create that folder, or give -o another"),
        // A parent on the way gave "File exists (os error 17)" and "Not a directory (os error 20)", exit 1.
        ("dangling/sub", "`dangling/sub`: cannot be created: `dangling` is a symbolic link to `nowhere`, which does not exist: create that folder, or give -o another"),
        ("s.toml/sub/deeper", "`s.toml/sub/deeper`: cannot be created: `s.toml` is not a folder; give -o a folder for the sweep's files"),
    ] {
        let (code, _, err) = run_in(d, &["sweep", "s.toml", "-o", out]);
        assert_eq!(code, 2, "{out}: {err}");
        assert!(err.contains(says), "{err}");
    }
    assert!(
        listing(&d.join("elsewhere")).is_empty(),
        "written through the link"
    );
    assert_eq!(listing(&d.join("linked")), [".coin-log-sweep"]);
    assert_eq!(
        std::fs::read_to_string(d.join("filed/.coin-log-sweep")).unwrap(),
        "mine"
    );
    assert!(!d.join("nowhere").exists());
}

#[test]
fn an_immutable_catalogue_or_append_only_folder_is_refused_before_any_run() {
    // An immutable catalogue.csv let every run be made, then "writing `catalogue.csv`: Operation not
    // permitted", exit 1; an append-only folder left what it could not remove. An immutable run file
    // is a failed (I/O) row at once, not after its recording.
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_sweep(d, "s.toml", SMALL);
    assert_eq!(sweep_json(d, "s.toml", "done", &[]).0, 0);
    std::fs::create_dir(d.join("apd")).unwrap();
    let mut attributes = crate::support::Attributes::default();
    std::fs::remove_file(d.join("done/run-02.mcap")).unwrap();
    std::fs::write(d.join("done/run-03.mcap"), "changed").unwrap();
    let set = attributes.set("+i", &d.join("done/catalogue.csv"))
        && attributes.set("+a", &d.join("apd"))
        && attributes.set("+i", &d.join("done/run-03.mcap"));
    if !set {
        // Not root, or a file system without attributes: cli_paths checks the logic of the probe.
        return;
    }
    let before = listing(&d.join("done"));
    // A file of the sweep's own that cannot be replaced is an I/O error (exit 1), as when a folder or
    // a link holds its name; it was a usage error (2), which only the folder itself is.
    let (code, _, err) = run_in(d, &["sweep", "s.toml", "-o", "done"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("writing `done/catalogue.csv`: is immutable, so the system lets no file be moved into place there: clear the attribute (chattr -i done/catalogue.csv), or give -o another folder"), "{err}");
    assert_eq!(listing(&d.join("done")), before, "no run made");
    let (code, _, err) = run_in(d, &["sweep", "collect", "done"]);
    assert_eq!(code, 1, "{err}");
    let (code, _, err) = run_in(d, &["sweep", "s.toml", "-o", "apd"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("`apd`: is append-only"), "{err}");
    assert!(listing(&d.join("apd")).is_empty(), "nothing created");
    // The catalogue writable again: run 2 is made, run 3 (immutable) fails on I/O at once.
    Command::new("chattr")
        .args(["-i"])
        .arg(d.join("done/catalogue.csv"))
        .status()
        .unwrap();
    let (code, json) = sweep_json(d, "s.toml", "done", &[]);
    assert_eq!(
        (code, json["done"].as_u64(), json["failed"].as_u64()),
        (1, Some(2), Some(1)),
        "{json}"
    );
    let catalogue = std::fs::read_to_string(d.join("done/catalogue.csv")).unwrap();
    assert!(catalogue.contains("io,\"`run-03.mcap` is immutable, so the system lets no recording replace it: clear the attribute (chattr -i run-03.mcap) and run again"), "{catalogue}");
}

#[test]
fn shards_overlap_exactly_when_they_share_a_run() {
    let all: Vec<Shard> = (1..=6)
        .flat_map(|n| (0..n).map(move |k| Shard::new(k, n).unwrap()))
        .collect();
    for &a in &all {
        for &b in &all {
            let shared = (0..60).any(|i| a.takes(i) && b.takes(i));
            assert_eq!(a.overlaps(b), shared, "{a} and {b}");
        }
    }
}

#[test]
fn the_shards_of_every_count_make_each_run_exactly_once() {
    for runs in [0, 1, 7, 23] {
        for n in 1..=5 {
            let mut made = vec![0; runs as usize];
            for k in 0..n {
                let shard = Shard::new(k, n).unwrap();
                for run in shard.runs(runs) {
                    assert!(shard.takes(run));
                    made[run as usize] += 1;
                }
                assert_eq!(shard.runs(runs).count() as u64, shard.len(runs));
                assert_eq!(
                    shard.len(runs),
                    (0..runs).filter(|r| shard.takes(*r)).count() as u64
                );
            }
            assert!(
                made.iter().all(|&m| m == 1),
                "{runs} runs in {n} shards: {made:?}"
            );
        }
    }
}

#[test]
fn a_shard_outside_its_count_is_refused() {
    let e = Shard::new(4, 4).unwrap_err().to_string();
    assert!(
        e.contains("K must be 0 … N − 1 = 3") && e.contains("--array=0-3"),
        "{e}"
    );
    let e = Shard::new(0, 0).unwrap_err().to_string();
    assert!(e.contains("N must be at least 1"), "{e}");
    assert!("3/2".parse::<Shard>().is_err());
    assert!("a/2"
        .parse::<Shard>()
        .unwrap_err()
        .to_string()
        .contains("K/N"));
    assert_eq!("1/3".parse::<Shard>(), Shard::new(1, 3));
}

fn env(vars: &[(&str, &str)]) -> impl Fn(&str) -> Option<String> {
    let map: HashMap<String, String> = vars
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    move |k| map.get(k).cloned()
}

#[test]
fn slurm_and_kubernetes_variables_give_the_shard() {
    let slurm = env(&[
        ("SLURM_ARRAY_TASK_ID", "5"),
        ("SLURM_ARRAY_TASK_MIN", "4"),
        ("SLURM_ARRAY_TASK_MAX", "7"),
        ("SLURM_ARRAY_TASK_COUNT", "4"),
    ]);
    assert_eq!(
        Shard::from_environment(slurm, None),
        Ok(Some(Shard::new(1, 4).unwrap()))
    );
    let count_only = env(&[
        ("SLURM_ARRAY_TASK_ID", "2"),
        ("SLURM_ARRAY_TASK_COUNT", "3"),
    ]);
    assert_eq!(
        Shard::from_environment(count_only, None),
        Ok(Some(Shard::new(2, 3).unwrap()))
    );
    let k8s = env(&[("JOB_COMPLETION_INDEX", "3")]);
    assert_eq!(
        Shard::from_environment(&k8s, Some(8)),
        Ok(Some(Shard::new(3, 8).unwrap()))
    );
    assert!(Shard::from_environment(&k8s, None)
        .unwrap_err()
        .to_string()
        .contains("--shard-count"));
    assert_eq!(Shard::from_environment(env(&[]), None), Ok(None));
    assert!(Shard::from_environment(env(&[]), Some(2)).is_err());
    // An index beyond the count names the Kubernetes fix (it named a Slurm array's `--array=0-2`).
    let beyond = Shard::from_environment(env(&[("JOB_COMPLETION_INDEX", "5")]), Some(3));
    assert_eq!(
        beyond.unwrap_err().to_string(),
        "JOB_COMPLETION_INDEX=5 is not below --shard-count 3: give --shard-count the Job's completions \
         (its pods are indexed 0 … completions − 1)"
    );
}

/// `--shard-count` in a Slurm job array (copied from the Kubernetes command, say) was ignored without a
/// word: an array of 2 tasks given `--shard-count 4` cut the sweep in 2 shards. A count that differs
/// from the array's size is refused before anything is written; the same count is accepted.
#[test]
fn a_shard_count_that_does_not_match_the_slurm_array_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    write_sweep(dir.path(), "s.toml", SMALL);
    let task = [
        ("SLURM_ARRAY_TASK_ID", "1"),
        ("SLURM_ARRAY_TASK_MIN", "0"),
        ("SLURM_ARRAY_TASK_MAX", "1"),
        ("SLURM_ARRAY_TASK_COUNT", "2"),
    ];
    let args = ["sweep", "s.toml", "-o", "d", "--shard-count", "4"];
    let (code, out, err) = run_with_env(dir.path(), &args, &task);
    assert_eq!(code, 2, "{out}{err}");
    assert!(err.contains("--shard-count 4 does not match this Slurm job array of 2 tasks, whose size is the number of shards: submit --array=0-3 for 4 shards, or leave --shard-count out"), "{err}");
    assert!(!dir.path().join("d").exists(), "nothing written");
    let args = ["sweep", "s.toml", "-o", "d", "--shard-count", "2", "--json"];
    let (code, out, err) = run_with_env(dir.path(), &args, &task);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("\"shard\":\"1/2\""), "{out}");
}

#[test]
fn a_slurm_array_with_a_step_is_refused_naming_the_dense_form() {
    let stepped = env(&[
        ("SLURM_ARRAY_TASK_ID", "2"),
        ("SLURM_ARRAY_TASK_MIN", "0"),
        ("SLURM_ARRAY_TASK_MAX", "6"),
        ("SLURM_ARRAY_TASK_COUNT", "4"),
    ]);
    let e = Shard::from_environment(stepped, None)
        .unwrap_err()
        .to_string();
    assert!(e.contains("--array=0-3"), "{e}");
    let bad = env(&[
        ("SLURM_ARRAY_TASK_ID", "x"),
        ("SLURM_ARRAY_TASK_COUNT", "4"),
    ]);
    assert!(Shard::from_environment(bad, None).is_err());
}

#[test]
fn collect_in_a_folder_it_may_not_write_in_is_refused_before_reading_a_run() {
    // collect read and hashed every run file, then failed writing the catalogue ("Permission denied"):
    // on a dataset of gigabytes, minutes for nothing. A run file it may not read shows which came first.
    let dir = tempfile::tempdir().unwrap();
    write_sweep(dir.path(), "s.toml", SMALL);
    for shard in ["0/2", "1/2"] {
        assert_eq!(
            sweep_json(dir.path(), "s.toml", "d", &["--shard", shard]).0,
            0
        );
    }
    let d = dir.path().join("d");
    let mode = |path: &Path, mode: u32| {
        let mode = std::os::unix::fs::PermissionsExt::from_mode(mode);
        std::fs::set_permissions(path, mode).unwrap();
    };
    mode(dir.path(), 0o755);
    mode(&d, 0o555);
    mode(&d.join("run-00.mcap"), 0o200);
    let output = crate::support::unprivileged(&exe())
        .args(["sweep", "collect", "d"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    mode(&d, 0o755);
    let err = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{err}");
    assert!(
        err.contains("writing `d/catalogue.csv`: Permission denied"),
        "{err}"
    );
    assert!(!err.contains("run-00"), "a run was read first: {err}");
}

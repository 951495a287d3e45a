//! Resuming a sweep (docs/format.md: Resume): only runs that are missing, failed on I/O or whose file does
//! not match its row are redone; and a sweep interrupted at random points by SIGINT and SIGKILL, then
//! resumed, ends with the catalogue and files of an uninterrupted one, no half file ever under a final
//! name, no temporary file left.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use crate::support::record::{exe, listing};
use crate::sweep::{
    run_files, run_in, sweep_json, write_sweep, Csv, SCHEDULER_VARIABLES, SMALL, SMALL_RUNS,
};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;

/// The catalogue of `dir` without wall times.
fn rows(dir: &Path) -> Vec<Vec<String>> {
    Csv::read(&dir.join("catalogue.csv")).without_wall_time()
}

/// Every run file of `dir` equals the file of that name in `reference`, byte for byte.
fn files_match(dir: &Path, reference: &Path) {
    for name in run_files(dir) {
        assert!(
            std::fs::read(dir.join(&name)).unwrap() == std::fs::read(reference.join(&name)).unwrap(),
            "{name} under its final name differs from the uninterrupted sweep's: a half or wrong file"
        );
    }
}

fn journal_lines(dir: &Path) -> usize {
    let text = std::fs::read_to_string(dir.join(".coin-log-sweep/journal-0-of-1.csv")).unwrap();
    text.lines().count()
}

/// `SMALL` swept into `ref` and `out` in `dir`, one job each (so that the two journals are in one
/// order); returns `out` and its journal, for a test to damage and resume.
fn swept_twice(dir: &Path) -> (PathBuf, PathBuf) {
    write_sweep(dir, "s.toml", SMALL);
    for folder in ["ref", "out"] {
        assert_eq!(sweep_json(dir, "s.toml", folder, &["--jobs", "1"]).0, 0);
    }
    let out = dir.join("out");
    let journal = out.join(".coin-log-sweep/journal-0-of-1.csv");
    (out, journal)
}

#[test]
fn resume_redoes_only_missing_cut_or_changed_files_and_keeps_what_it_can_prove_unchanged() {
    let dir = tempfile::tempdir().unwrap();
    write_sweep(dir.path(), "s.toml", SMALL);
    assert_eq!(
        sweep_json(dir.path(), "s.toml", "ref", &["--jobs", "1"]).0,
        0
    );
    assert_eq!(
        sweep_json(dir.path(), "s.toml", "out", &["--jobs", "2"]).0,
        0
    );
    let (reference, out) = (dir.path().join("ref"), dir.path().join("out"));
    // Nothing to do: every row kept, the catalogue unchanged apart from nothing at all.
    let before = std::fs::read(out.join("catalogue.csv")).unwrap();
    let (code, json) = sweep_json(dir.path(), "s.toml", "out", &[]);
    assert_eq!(
        (code, json["done"].as_u64(), json["kept"].as_u64()),
        (0, Some(0), Some(12)),
        "{json}"
    );
    assert!(
        std::fs::read(out.join("catalogue.csv")).unwrap() == before,
        "a resume with nothing to do rewrites the same catalogue"
    );
    // Damage: a file gone, one cut short, one with a byte changed (same size, new time), one touched
    // only (new time, same bytes), and a torn last journal line as a crash leaves it.
    std::fs::remove_file(out.join("run-01.mcap")).unwrap();
    let cut = std::fs::read(out.join("run-03.mcap")).unwrap();
    std::fs::write(out.join("run-03.mcap"), &cut[..cut.len() / 2]).unwrap();
    let mut changed = std::fs::read(out.join("run-05.mcap")).unwrap();
    changed[1000] ^= 1;
    std::thread::sleep(Duration::from_millis(20));
    std::fs::write(out.join("run-05.mcap"), &changed).unwrap();
    let same = std::fs::read(out.join("run-07.mcap")).unwrap();
    std::fs::write(out.join("run-07.mcap"), &same).unwrap();
    let journal = out.join(".coin-log-sweep/journal-0-of-1.csv");
    let mut text = std::fs::read_to_string(&journal).unwrap();
    text.push_str("17,9,\"[0.3, 0.2");
    std::fs::write(&journal, text).unwrap();
    let lines = journal_lines(&out);
    let (code, json) = sweep_json(dir.path(), "s.toml", "out", &[]);
    assert_eq!(
        (code, json["done"].as_u64(), json["kept"].as_u64()),
        (0, Some(3), Some(9)),
        "runs 1, 3 and 5 redone: {json}"
    );
    assert_eq!(
        rows(&out),
        rows(&reference),
        "the resumed catalogue is the uninterrupted one, wall times aside"
    );
    files_match(&out, &reference);
    assert_eq!(run_files(&out).len(), SMALL_RUNS);
    // Run 7 was re-hashed once and journalled again with its new time (beside runs 1, 3 and 5; the torn
    // line stays, ignored): the next resume proves it unchanged by size and time alone.
    assert_eq!(journal_lines(&out), lines + 4);
    let (code, json) = sweep_json(dir.path(), "s.toml", "out", &[]);
    assert_eq!((code, json["done"].as_u64()), (0, Some(0)));
    assert_eq!(journal_lines(&out), lines + 4, "nothing more to journal");
}

#[test]
fn a_journal_row_that_names_another_runs_file_is_redone_not_kept() {
    // Two journal rows with their indexes swapped: each file matched its row's size and time, so resume
    // kept them, and the catalogue gave run 0 another run's values and file.
    let dir = tempfile::tempdir().unwrap();
    let (out, journal) = swept_twice(dir.path());
    let text = std::fs::read_to_string(&journal).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let at = |i: usize| {
        lines
            .iter()
            .position(|l| l.split(',').nth(1) == Some(&i.to_string()))
            .unwrap()
    };
    let (a, b) = (at(0), at(4));
    let fields = |l: &str| l.splitn(3, ',').map(str::to_string).collect::<Vec<_>>();
    let (fa, fb) = (fields(&lines[a]), fields(&lines[b]));
    lines[a] = format!("{},{},{}", fa[0], fb[1], fa[2]);
    lines[b] = format!("{},{},{}", fb[0], fa[1], fb[2]);
    std::fs::write(&journal, lines.join("\n") + "\n").unwrap();
    let (code, json) = sweep_json(dir.path(), "s.toml", "out", &[]);
    assert_eq!(
        (code, json["done"].as_u64(), json["kept"].as_u64()),
        (0, Some(2), Some(10)),
        "runs 0 and 4 redone: {json}"
    );
    assert_eq!(rows(&out), rows(&dir.path().join("ref")));
}

#[test]
fn bytes_that_are_no_utf8_in_the_journal_spoil_their_line_not_the_resume() {
    // A byte of damage that is no UTF-8 made every resume fail ("stream did not contain valid UTF-8",
    // exit 1, no fix); the doc leaves out a line that does not parse, and redoes its run.
    let dir = tempfile::tempdir().unwrap();
    let (out, journal) = swept_twice(dir.path());
    let mut bytes = std::fs::read(&journal).unwrap();
    // Inside the third line (a row), and a line of garbage after the last.
    let third = bytes
        .iter()
        .enumerate()
        .filter(|&(_, &b)| b == b'\n')
        .nth(1)
        .unwrap()
        .0;
    bytes[third + 40] = 0xff;
    bytes.extend_from_slice(b"\x00\xfe\xff,,\n");
    std::fs::write(&journal, &bytes).unwrap();
    let (code, json) = sweep_json(dir.path(), "s.toml", "out", &[]);
    assert_eq!(
        (code, json["done"].as_u64(), json["kept"].as_u64()),
        (0, Some(1), Some(11)),
        "the damaged row's run redone: {json}"
    );
    assert_eq!(rows(&out), rows(&dir.path().join("ref")));
}

#[test]
fn a_journal_of_another_sweep_with_the_same_keys_is_redone_not_kept() {
    // Another sweep's journal (same keys, other values) and its files copied into this sweep's state:
    // every row named its own run's file with the size and SHA-256 it was journalled with, so resume kept
    // them all, and the catalogue held the other sweep's values under this sweep's identity.
    let dir = tempfile::tempdir().unwrap();
    write_sweep(dir.path(), "s.toml", SMALL);
    let other = SMALL.replace("values = [0.2, 0.6, 1.0]", "values = [0.3, 0.6, 1.0]");
    write_sweep(dir.path(), "o.toml", &other);
    for (file, folder) in [("s.toml", "ref"), ("s.toml", "out"), ("o.toml", "other")] {
        assert_eq!(sweep_json(dir.path(), file, folder, &["--jobs", "1"]).0, 0);
    }
    let (out, other) = (dir.path().join("out"), dir.path().join("other"));
    let journal = ".coin-log-sweep/journal-0-of-1.csv";
    std::fs::copy(other.join(journal), out.join(journal)).unwrap();
    for name in run_files(&other) {
        std::fs::copy(other.join(&name), out.join(&name)).unwrap();
    }
    let (code, json) = sweep_json(dir.path(), "s.toml", "out", &[]);
    // Runs 0, 1, 6 and 7 have θ = 0.2 here and 0.3 there; the others' values and files are the same.
    assert_eq!(
        (code, json["done"].as_u64(), json["kept"].as_u64()),
        (0, Some(4), Some(8)),
        "{json}"
    );
    assert_eq!(rows(&out), rows(&dir.path().join("ref")));
    files_match(&out, &dir.path().join("ref"));
}

#[test]
fn a_journal_row_no_run_writes_is_redone_not_kept() {
    // A finished row whose file cell was blanked had no file to check, so resume kept it: a finished
    // run without a file in the catalogue.
    let dir = tempfile::tempdir().unwrap();
    let (out, journal) = swept_twice(dir.path());
    let text = std::fs::read_to_string(&journal).unwrap();
    let lines: Vec<String> = text
        .lines()
        .map(|l| l.replace(",run-02.mcap,", ",,"))
        .collect();
    std::fs::write(&journal, lines.join("\n") + "\n").unwrap();
    std::fs::remove_file(out.join("run-02.mcap")).unwrap();
    let (code, json) = sweep_json(dir.path(), "s.toml", "out", &[]);
    assert_eq!(
        (code, json["done"].as_u64(), json["kept"].as_u64()),
        (0, Some(1), Some(11)),
        "{json}"
    );
    assert_eq!(rows(&out), rows(&dir.path().join("ref")));
}

#[test]
fn a_catalogue_or_sweep_json_that_cannot_be_replaced_is_refused_before_any_run() {
    // sweep.json's name held by a link: the missing run was made and the catalogue rewritten, and only
    // then was sweep.json refused, leaving a new catalogue beside the old sweep.json's place.
    let dir = tempfile::tempdir().unwrap();
    write_sweep(dir.path(), "s.toml", SMALL);
    assert_eq!(sweep_json(dir.path(), "s.toml", "out", &[]).0, 0);
    let out = dir.path().join("out");
    std::fs::remove_file(out.join("run-05.mcap")).unwrap();
    std::fs::remove_file(out.join("sweep.json")).unwrap();
    std::os::unix::fs::symlink("../victim", out.join("sweep.json")).unwrap();
    let catalogue = std::fs::read(out.join("catalogue.csv")).unwrap();
    let (code, _, err) = run_in(dir.path(), &["sweep", "s.toml", "-o", "out"]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("sweep.json`: is a symbolic link (to `../victim`)"),
        "{err}"
    );
    assert!(!out.join("run-05.mcap").exists(), "a run was made first");
    assert_eq!(std::fs::read(out.join("catalogue.csv")).unwrap(), catalogue);
}

#[test]
fn an_io_failure_is_redone_on_resume_and_other_failures_only_when_asked() {
    let dir = tempfile::tempdir().unwrap();
    let text = "base = \"wobble\"\nset = { \"run.duration\" = 0.5 }\n[[axis]]\nkey = \"initial.theta\"\nvalues = [0.3, 1.6, 0.5]\n";
    write_sweep(dir.path(), "s.toml", text);
    let (code, json) = sweep_json(dir.path(), "s.toml", "out", &[]);
    assert_eq!(
        (code, json["failed"].as_u64()),
        (1, Some(1)),
        "θ = 1.6 is no valid scene: {json}"
    );
    let out = dir.path().join("out");
    // A folder where run 2's file should go: moving the recording there fails, an I/O failure.
    std::fs::remove_file(out.join("run-2.mcap")).unwrap();
    std::fs::create_dir(out.join("run-2.mcap")).unwrap();
    let (code, json) = sweep_json(dir.path(), "s.toml", "out", &[]);
    assert_eq!(
        (code, json["done"].as_u64(), json["failed"].as_u64()),
        (1, Some(1), Some(2)),
        "{json}"
    );
    let row = &Csv::read(&out.join("catalogue.csv")).records()[2];
    assert_eq!(
        (row["failure"].as_str(), row["file"].as_str()),
        ("io", ""),
        "{row:?}"
    );
    assert!(
        row["reason"].starts_with("moving the recording to `run-2.mcap`: "),
        "{row:?}"
    );
    assert!(
        !listing(&out).iter().any(|n| n.ends_with(".tmp")),
        "the failed run's temporary file is gone"
    );
    std::fs::remove_dir(out.join("run-2.mcap")).unwrap();
    let (code, json) = sweep_json(dir.path(), "s.toml", "out", &[]);
    assert_eq!(
        (code, json["done"].as_u64(), json["failed"].as_u64()),
        (1, Some(1), Some(1)),
        "the I/O failure is redone, the scene failure kept: {json}"
    );
    let (code, json) = sweep_json(dir.path(), "s.toml", "out", &["--retry-failed"]);
    assert_eq!(
        (code, json["done"].as_u64(), json["failed"].as_u64()),
        (1, Some(1), Some(1)),
        "--retry-failed redoes the scene failure (which fails again): {json}"
    );
}

/// A fixed sequence of pseudo-random delays (splitmix64), so that a failure can be replayed.
fn delays(seed: u64, n: usize, range: std::ops::Range<u64>) -> Vec<u64> {
    (0..n as u64)
        .map(|i| {
            let w = coin_log::sweep::word(seed, i, 0, 0);
            range.start + w % (range.end - range.start)
        })
        .collect()
}

/// One round: start the sweep, wait `delay` ms, send SIGINT (`kill` false) or SIGKILL; the exit code.
fn interrupt(dir: &Path, delay: u64, kill: bool) -> Option<i32> {
    let mut command = Command::new(exe());
    for v in SCHEDULER_VARIABLES {
        command.env_remove(v);
    }
    let mut child = command
        .args(["sweep", "s.toml", "-o", "cut", "--jobs", "2"])
        .current_dir(dir)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(delay));
    if kill {
        let _ = child.kill();
    } else {
        let _ = Command::new("kill")
            .args(["-INT", &child.id().to_string()])
            .status();
    }
    child.wait().unwrap().code()
}

#[test]
fn a_sweep_interrupted_at_random_points_resumes_to_the_uninterrupted_result() {
    let dir = tempfile::tempdir().unwrap();
    let text = SMALL
        .replace("count = 2", "count = 4")
        .replace("\"run.duration\" = 3.0", "\"run.duration\" = 10.0");
    write_sweep(dir.path(), "s.toml", &text);
    let (code, json) = sweep_json(dir.path(), "s.toml", "ref", &["--jobs", "1"]);
    assert_eq!(code, 0, "{json}");
    let (reference, cut) = (dir.path().join("ref"), dir.path().join("cut"));
    // Delays from 2 % to 15 % of the uninterrupted sweep's time, so that most rounds stop it midway.
    let whole = (json["wall_time_s"].as_f64().unwrap() * 1000.0) as u64;
    let plan = delays(2024, 8, whole / 50..whole * 3 / 20 + 2);
    println!("uninterrupted: {whole} ms; delays (ms), SIGINT on even rounds, SIGKILL on odd ones: {plan:?}");
    let mut stopped = 0;
    for (round, &delay) in plan.iter().enumerate() {
        let kill = round % 2 == 1;
        let code = interrupt(dir.path(), delay, kill);
        println!(
            "round {round}: {} after {delay} ms: exit {code:?}",
            if kill { "SIGKILL" } else { "SIGINT" }
        );
        stopped += usize::from(code != Some(0));
        if !cut.exists() {
            continue;
        }
        // Never a half file under a final name, whatever the moment.
        files_match(&cut, &reference);
        if !kill {
            assert!(
                matches!(code, Some(130 | 0)),
                "SIGINT exits 130 (or 0 if the sweep had finished): {code:?}"
            );
            let all = rows(&reference);
            assert!(
                rows(&cut).iter().all(|r| all.contains(r)),
                "the interrupted catalogue holds finished rows only"
            );
            assert!(
                !listing(&cut).iter().any(|n| n.ends_with(".tmp")),
                "SIGINT discards the runs in progress"
            );
        }
    }
    assert!(
        stopped >= 4,
        "at least half the rounds stopped the sweep midway ({stopped} of 8)"
    );
    let (code, out, err) = run_in(dir.path(), &["sweep", "s.toml", "-o", "cut", "--jobs", "2"]);
    assert_eq!(code, 0, "{out}{err}");
    assert_eq!(
        rows(&cut),
        rows(&reference),
        "interrupted and resumed = uninterrupted, wall times aside"
    );
    files_match(&cut, &reference);
    assert_eq!(run_files(&cut), run_files(&reference));
    assert!(
        !listing(&cut).iter().any(|n| n.ends_with(".tmp")),
        "no temporary file left: {:?}",
        listing(&cut)
    );
    let summary = |d: &Path| std::fs::read_to_string(d.join("sweep.json")).unwrap();
    assert_eq!(summary(&cut), summary(&reference));
}

#[test]
fn a_signal_before_the_runs_start_quits_at_once_writing_nothing() {
    // Every run's bounded normal draw fails after 10⁶ attempts, so the dry run's thousand sampled runs,
    // and the coverage warning's search for a valid run before a real sweep, take a minute; a signal
    // was ignored until they ended (the dry run then said "the catalogue of what finished is written").
    let dir = tempfile::tempdir().unwrap();
    write_sweep(
        dir.path(),
        "s.toml",
        r#"
base = "wobble"
[random]
seed = 3
count = 1000
[[random.draw]]
key = "body.mass"
normal = { mean = 1.0, std = 1e-300, min = 5.0, max = 6.0 }
"#,
    );
    for args in [&["--dry-run"][..], &["-o", "out"]] {
        let mut command = Command::new(exe());
        for v in SCHEDULER_VARIABLES {
            command.env_remove(v);
        }
        let mut child = command
            .args(["sweep", "s.toml"])
            .args(args)
            .current_dir(dir.path())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        std::thread::sleep(Duration::from_millis(500));
        let _ = Command::new("kill")
            .args(["-INT", &child.id().to_string()])
            .status();
        let started = std::time::Instant::now();
        let code = loop {
            if let Some(status) = child.try_wait().unwrap() {
                break status.code();
            }
            if started.elapsed() > Duration::from_secs(10) {
                let _ = child.kill();
                panic!("{args:?}: still running 10 s after SIGINT");
            }
            std::thread::sleep(Duration::from_millis(20));
        };
        let mut err = String::new();
        std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut err).unwrap();
        assert_eq!(code, Some(130), "{args:?}: {err}");
        assert!(
            err.contains("stopped before any run: nothing written"),
            "{err}"
        );
        assert!(!err.contains("catalogue"), "{err}");
        assert!(
            !dir.path().join("out").exists(),
            "{args:?} wrote the folder"
        );
    }
}

/// A sweep resumed on its folder reads the plan in place and does not write it again: publishing it
/// wrote a temporary file first, so a state folder that takes no new file (full disk, `chattr +i`)
/// failed "writing the sweep's plan" when the plan was there all along, and a finished sweep could not
/// even be looked at again.
#[test]
fn a_resume_reads_the_plan_in_place_without_writing_it_again() {
    let dir = tempfile::tempdir().unwrap();
    write_sweep(dir.path(), "s.toml", SMALL);
    assert_eq!(sweep_json(dir.path(), "s.toml", "out", &[]).0, 0);
    let mut attributes = crate::support::Attributes::default();
    if !attributes.set("+i", &dir.path().join("out/.coin-log-sweep")) {
        return; // Not root, or a file system without attributes.
    }
    let (code, json) = sweep_json(dir.path(), "s.toml", "out", &[]);
    assert_eq!(
        (code, json["kept"].as_u64(), json["done"].as_u64()),
        (0, Some(SMALL_RUNS as u64), Some(0)),
        "{json}"
    );
}

/// On a terminal, the first signal's message is printed over the progress bar, which is cleared first:
/// it once ran on from the bar's line (`… 5/40 runs, 0 failed, 4s (eta 26s)      stopping: no new runs`).
/// Run under `script` (a pseudo-terminal; util-linux, in every Debian); the signal comes after 3, 6 or
/// 12 s, until the bar was drawn before it (it is drawn after the first second).
#[test]
fn the_stop_message_starts_its_own_line_under_the_progress_bar() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = "base = \"wobble\"\nset = { \"run.duration\" = 300.0 }\n[[axis]]\nkey = \"initial.theta\"\nlinspace = [0.3, 1.0, 40]\n";
    write_sweep(dir.path(), "s.toml", sweep);
    for (attempt, wait) in [3, 6, 12].into_iter().enumerate() {
        let script = format!(
            "'{}' sweep s.toml -o out{attempt} --jobs 2 & p=$!\nsleep {wait}\nkill -INT $p\nwait $p\n",
            exe().display()
        );
        std::fs::write(dir.path().join("interrupt.sh"), script).unwrap();
        let out = Command::new("script")
            .args(["-qec", "sh interrupt.sh", "/dev/null"])
            .current_dir(dir.path())
            .stdin(Stdio::null())
            .output()
            .expect("`script` runs the sweep on a pseudo-terminal (Debian: apt install bsdutils)");
        let text = String::from_utf8_lossy(&out.stdout);
        let at = text
            .find("stopping: no new runs")
            .unwrap_or_else(|| panic!("the sweep said it stops: {text}"));
        let before = &text[..at];
        if !before.contains(" runs, ") {
            continue; // The bar was not drawn yet (a busy machine): wait longer.
        }
        assert!(
            before.ends_with("\u{1b}[2K") || before.ends_with('\n'),
            "the message runs on from the bar: {:?}",
            &before[before.len().saturating_sub(80)..]
        );
        return;
    }
    panic!("no progress bar was drawn within 12 s of the sweep's start");
}

//! The sweep on a real Slurm cluster (docs/format.md: Shards and collect): a single-node cluster is
//! brought up by `scripts/slurm/up DIR` (daemons started by process id, their environment in `DIR/env`),
//! the sweep is submitted as a job array of 4 tasks with `sbatch --wait`, `coin-log sweep collect` merges
//! the parts, and the collected catalogue, `sweep.json` and files equal, bit for bit (wall times aside),
//! those of the same sweep run in one process with `--jobs 1`. `scripts/slurm/down DIR` then stops exactly
//! the daemons `up` started. Built with the cargo feature `slurm` (`scripts/test` turns it on); a cluster
//! that cannot be brought up fails the test, never skips it.
//!
//! `COIN_LOG_SLURM_SCRIPTS=tests/it/sweep_slurm_stub` runs the same test against a stand-in (`up`, `down`,
//! and an `sbatch` that runs the tasks in turn with Slurm's variables), to check the test without a cluster.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use crate::support::record::exe;
use crate::support::repo;
use crate::sweep::{run_files, run_in, sweep_json, write_sweep, Csv, SMALL, SMALL_RUNS};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The job array's tasks.
const TASKS: u32 = 4;
/// How long the array may take before the test calls it hung (12 short runs; about 10 s on 2 cores).
const DEADLINE: Duration = Duration::from_secs(600);

/// The folder of `up` and `down`.
fn scripts() -> PathBuf {
    std::env::var_os("COIN_LOG_SLURM_SCRIPTS")
        .map_or_else(|| repo().join("scripts/slurm"), |p| repo().join(p))
}

/// The cluster, brought down when dropped (also when the test fails).
struct Cluster {
    dir: PathBuf,
}

impl Cluster {
    fn up(dir: &Path) -> Self {
        let up = scripts().join("up");
        let out = Command::new(&up)
            .arg(dir)
            .stdin(Stdio::null())
            .output()
            .unwrap_or_else(|e| {
                panic!(
                    "cannot run {} ({e}): the Slurm test needs scripts/slurm/up",
                    up.display()
                )
            });
        let cluster = Self {
            dir: dir.to_path_buf(),
        };
        assert!(
            out.status.success() && dir.join("env").is_file(),
            "{} {} could not bring a Slurm cluster up (exit {:?}); the test fails rather than skip:\n{}{}",
            up.display(),
            dir.display(),
            out.status.code(),
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        cluster
    }

    /// A shell command line with the cluster's environment (`DIR/env`'s KEY=VALUE lines, exported), as a
    /// command.
    fn command(&self, line: &str) -> Command {
        let mut command = Command::new("sh");
        command.arg("-c").arg(format!(
            "set -a && . '{}' && set +a && {line}",
            self.dir.join("env").display()
        ));
        command
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        let down = scripts().join("down");
        match Command::new(&down)
            .arg(&self.dir)
            .stdin(Stdio::null())
            .output()
        {
            Ok(out) if out.status.success() => {}
            Ok(out) => eprintln!(
                "{} failed (exit {:?}): {}{}",
                down.display(),
                out.status.code(),
                String::from_utf8_lossy(&out.stdout),
                String::from_utf8_lossy(&out.stderr)
            ),
            Err(e) => eprintln!("cannot run {}: {e}", down.display()),
        }
    }
}

/// The job script a user submits (README.md, Sweeps): one array task per shard, the shard from Slurm's
/// variables.
fn job_script(sweep: &Path, shared: &Path) -> String {
    format!(
        "#!/bin/sh\n#SBATCH --job-name=coin-log-sweep\n#SBATCH --array=0-{}\n#SBATCH --cpus-per-task=1\nexec '{}' sweep '{}' -o '{}' --jobs 1\n",
        TASKS - 1,
        exe().display(),
        sweep.display(),
        shared.display()
    )
}

/// Runs `command` to its end or kills it at [`DEADLINE`]; exit status and output.
fn run_to_end(mut command: Command) -> (Option<i32>, String) {
    let mut child = command
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let started = Instant::now();
    loop {
        if child.try_wait().unwrap().is_some() {
            let out = child.wait_with_output().unwrap();
            let text = format!(
                "{}{}",
                String::from_utf8_lossy(&out.stdout),
                String::from_utf8_lossy(&out.stderr)
            );
            return (out.status.code(), text);
        }
        if started.elapsed() > DEADLINE {
            let _ = child.kill();
            panic!("the job array still ran after {DEADLINE:?}");
        }
        std::thread::sleep(Duration::from_millis(100));
    }
}

#[test]
fn a_sweep_run_as_a_slurm_job_array_and_collected_equals_the_one_process_sweep() {
    let work = tempfile::tempdir().unwrap();
    let cluster = Cluster::up(&work.path().join("cluster"));
    let sweep = write_sweep(work.path(), "s.toml", SMALL);
    let shared = work.path().join("shared");
    let script = work.path().join("job.sh");
    std::fs::write(&script, job_script(&sweep, &shared)).unwrap();
    let logs = work.path().join("log-%A_%a.txt");
    let line = format!(
        "sbatch --wait --array=0-{} --output='{}' '{}'",
        TASKS - 1,
        logs.display(),
        script.display()
    );
    let (code, text) = run_to_end(cluster.command(&line));
    let task_logs: String = std::fs::read_dir(work.path())
        .unwrap()
        .flatten()
        .filter(|e| e.file_name().to_string_lossy().starts_with("log-"))
        .map(|e| {
            format!(
                "--- {}\n{}",
                e.path().display(),
                std::fs::read_to_string(e.path()).unwrap_or_default()
            )
        })
        .collect();
    println!("{line}: exit {code:?}\n{text}{task_logs}");
    assert_eq!(code, Some(0), "every array task succeeds");
    for k in 0..TASKS {
        assert!(
            shared
                .join(format!("catalogue.part-{k}-of-{TASKS}.csv"))
                .is_file(),
            "task {k} wrote its part"
        );
    }
    let (code, out, err) = run_in(work.path(), &["sweep", "collect", "shared"]);
    assert_eq!(code, 0, "{out}{err}");
    assert_eq!(
        sweep_json(work.path(), "s.toml", "one", &["--jobs", "1"]).0,
        0
    );
    let one = work.path().join("one");
    let rows = |d: &Path| Csv::read(&d.join("catalogue.csv")).without_wall_time();
    assert_eq!(
        rows(&shared),
        rows(&one),
        "the cluster's collected catalogue = one process's, wall times aside"
    );
    let summary = |d: &Path| std::fs::read_to_string(d.join("sweep.json")).unwrap();
    assert_eq!(summary(&shared), summary(&one));
    assert_eq!(run_files(&shared).len(), SMALL_RUNS);
    for name in run_files(&one) {
        assert!(
            std::fs::read(shared.join(&name)).unwrap() == std::fs::read(one.join(&name)).unwrap(),
            "{name} differs"
        );
    }
    drop(cluster);
}

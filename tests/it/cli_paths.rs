//! `coin-log record`'s output path and signals: nothing but a regular file is ever replaced (device nodes,
//! named pipes, symbolic links, folders, the scene file itself are refused, with or without
//! `--overwrite`), a target that cannot be created fails before the simulation with the system's reason,
//! and SIGTERM and SIGHUP finish the file like SIGINT. No case leaves a file behind that it should not.
// Helpers outside #[test] functions panic on failure too: a failed step is a failed test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use crate::support::mkfifo;
use crate::support::process::Process;
use crate::support::record::{coin_log, exe, listing, read_back};
use coin_log::format::{ResultMetadata, Termination, RESULT_METADATA_NAME};
use std::os::unix::fs::{FileTypeExt, MetadataExt};
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn code(output: &Output) -> i32 {
    output.status.code().expect("exited normally")
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// A run long enough (1e5 time units at 1000 samples per unit) that a test finishing quickly proves it
/// never simulated.
const LONG: [&str; 6] = [
    "--duration",
    "100000",
    "--rate",
    "1000",
    "--integrator",
    "rk4",
];

/// Runs `record wobble` (a long run) in `dir` with `-o target --overwrite`; expects exit 1 with every
/// needle in stderr, within a few seconds (before any simulation), and the folder unchanged.
fn refused(dir: &Path, target: &str, needles: &[&str]) {
    let before = listing(dir);
    let started = Instant::now();
    let mut args = vec!["record", "wobble", "-o", target, "--overwrite"];
    args.extend_from_slice(&LONG);
    let out = coin_log(dir, &args);
    let err = stderr(&out);
    println!(
        "-o {target}: exit {} after {:.2} s: {err}",
        code(&out),
        started.elapsed().as_secs_f64()
    );
    assert_eq!(code(&out), 1, "exit code; stderr: {err}");
    for needle in needles {
        assert!(err.contains(needle), "stderr should say {needle:?}: {err}");
    }
    assert!(
        started.elapsed() < Duration::from_secs(20),
        "refused only after {:?}: it simulated first",
        started.elapsed()
    );
    assert_eq!(listing(dir), before, "the folder is unchanged");
}

#[test]
fn an_immutable_or_append_only_target_or_folder_is_refused_before_the_work() {
    // `record -o imm.mcap --overwrite` on a `chattr +i` file simulated the whole run, then failed the
    // move and kept the finished temporary file; in an append-only folder the probe and the temporary
    // file were left behind (neither may be removed there). statx's attributes tell before the work.
    use coin_log::files::Attribute;
    assert_eq!(
        [(true, false), (true, true), (false, true), (false, false)]
            .map(|(i, a)| Attribute::from_attributes(i, a)),
        [
            Some(Attribute::Immutable),
            Some(Attribute::Immutable),
            Some(Attribute::AppendOnly),
            None
        ]
    );
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    assert_eq!(
        code(&coin_log(
            d,
            &["record", "wobble", "--duration", "1", "-o", "run.mcap"]
        )),
        0
    );
    std::fs::write(d.join("imm.mcap"), "mine").unwrap();
    for folder in ["apd", "immdir"] {
        std::fs::create_dir(d.join(folder)).unwrap();
    }
    assert_eq!(Attribute::of(&d.join("imm.mcap")), None);
    let mut attributes = crate::support::Attributes::default();
    let set = [("+i", "imm.mcap"), ("+a", "apd"), ("+i", "immdir")]
        .iter()
        .all(|&(flag, path)| attributes.set(flag, &d.join(path)));
    if !set {
        // Not root, or a file system without these attributes: the logic above is what is checked.
        return;
    }
    assert_eq!(
        Attribute::of(&d.join("imm.mcap")),
        Some(Attribute::Immutable)
    );
    assert_eq!(Attribute::of(&d.join("apd")), Some(Attribute::AppendOnly));
    refused(d, "imm.mcap", &[
        "`imm.mcap` is immutable, so the system lets no file replace it, even with --overwrite: clear the attribute (chattr -i imm.mcap), or choose another file with -o",
    ]);
    refused(d, "apd/new.mcap", &[
        "the folder `apd` is append-only, so the system lets no file be moved into place in it (for `apd/new.mcap`): clear the attribute (chattr -a apd), or choose another file with -o",
    ]);
    assert!(listing(&d.join("apd")).is_empty(), "nothing left in apd");
    let before = listing(d);
    for (args, says) in [
        (
            &["analyse", "map", "--out", "immdir"][..],
            "the folder `immdir` is immutable",
        ),
        (
            &["export", "run.mcap", "--out", "apd"],
            "the folder `apd` is append-only",
        ),
        (
            &["plot", "run.mcap", "--out", "imm.mcap", "--overwrite"],
            "`imm.mcap` is immutable",
        ),
    ] {
        let out = coin_log(d, args);
        assert_eq!(code(&out), 1, "{args:?}: {}", stderr(&out));
        assert!(stderr(&out).contains(says), "{args:?}: {}", stderr(&out));
    }
    assert_eq!(listing(d), before, "nothing created");
    assert!(listing(&d.join("apd")).is_empty() && listing(&d.join("immdir")).is_empty());
    assert_eq!(std::fs::read_to_string(d.join("imm.mcap")).unwrap(), "mine");
}

/// `man`, `analyse map` and `bench` always replace their own files and have no `--overwrite`: refusing an
/// immutable page or map, they told the user the system allowed no replacement "even with --overwrite",
/// a flag they do not take. Only `record`, `plot`, `export` (and `live`) have it to name.
#[test]
fn an_immutable_file_of_a_command_without_overwrite_does_not_name_the_flag() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for folder in ["pages", "map"] {
        std::fs::create_dir(d.join(folder)).unwrap();
    }
    std::fs::write(d.join("pages/coin-log.1"), "mine").unwrap();
    std::fs::write(d.join("map/stability-map.csv"), "mine").unwrap();
    let mut attributes = crate::support::Attributes::default();
    if !["pages/coin-log.1", "map/stability-map.csv"]
        .iter()
        .all(|path| attributes.set("+i", &d.join(path)))
    {
        // Not root, or a file system without these attributes.
        return;
    }
    for (args, says) in [
        (
            &["man", "--out", "pages"][..],
            "`pages/coin-log.1` is immutable, so the system lets no file replace it: clear the attribute (chattr -i pages/coin-log.1), or choose another folder with --out",
        ),
        (
            &["analyse", "map", "--theta", "0.1:1:2", "--omega-z", "0:1:2", "--out", "map"],
            "`map/stability-map.csv` is immutable, so the system lets no file replace it: clear the attribute (chattr -i map/stability-map.csv), or choose another folder with --out",
        ),
    ] {
        let out = coin_log(d, args);
        assert_eq!(code(&out), 1, "{args:?}: {}", stderr(&out));
        assert!(stderr(&out).contains(says), "{args:?}: {}", stderr(&out));
        assert!(!stderr(&out).contains("--overwrite"), "{args:?}: {}", stderr(&out));
    }
    assert_eq!(listing(&d.join("pages")), ["coin-log.1"]);
    assert_eq!(listing(&d.join("map")), ["stability-map.csv"]);
}

#[test]
fn a_device_node_is_never_replaced_even_with_overwrite() {
    let dir = tempfile::tempdir().unwrap();
    refused(
        dir.path(),
        "/dev/null",
        &[
            "`/dev/null` is a character device, not a regular file",
            "would replace the character device",
            "choose a file path",
        ],
    );
    let meta = std::fs::symlink_metadata("/dev/null").unwrap();
    assert!(meta.file_type().is_char_device(), "/dev/null is intact");
}

#[test]
fn dev_stdout_is_a_symbolic_link_and_is_refused() {
    // /dev/stdout is a link to /proc/self/fd/1; replacing it would break the machine for everyone.
    let dir = tempfile::tempdir().unwrap();
    refused(
        dir.path(),
        "/dev/stdout",
        &["`/dev/stdout` is a symbolic link", "not a regular file"],
    );
    assert!(std::fs::symlink_metadata("/dev/stdout")
        .unwrap()
        .file_type()
        .is_symlink());
}

#[test]
fn a_named_pipe_is_never_replaced() {
    let dir = tempfile::tempdir().unwrap();
    mkfifo(&dir.path().join("pipe"));
    refused(
        dir.path(),
        "pipe",
        &["`pipe` is a named pipe, not a regular file"],
    );
    let meta = std::fs::symlink_metadata(dir.path().join("pipe")).unwrap();
    assert!(meta.file_type().is_fifo(), "the pipe is intact");
}

#[test]
fn a_symbolic_link_is_never_replaced_by_a_plain_file() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("real.mcap"), "precious").unwrap();
    std::os::unix::fs::symlink("real.mcap", dir.path().join("link.mcap")).unwrap();
    refused(
        dir.path(),
        "link.mcap",
        &[
            "`link.mcap` is a symbolic link (to `real.mcap`)",
            "would replace the link itself with a plain file",
        ],
    );
    assert!(std::fs::symlink_metadata(dir.path().join("link.mcap"))
        .unwrap()
        .file_type()
        .is_symlink());
    assert_eq!(
        std::fs::read(dir.path().join("real.mcap")).unwrap(),
        b"precious"
    );
}

#[test]
fn the_scene_file_is_never_the_output_by_any_path() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(crate::support::repo().join("datasets/scenes/wobble.toml"))
        .unwrap();
    std::fs::write(dir.path().join("scene.toml"), &text).unwrap();
    std::fs::create_dir(dir.path().join("sub")).unwrap();
    std::fs::hard_link(
        dir.path().join("scene.toml"),
        dir.path().join("sub/same.toml"),
    )
    .unwrap();
    for (scene, target) in [
        ("scene.toml", "scene.toml"),
        ("scene.toml", "./scene.toml"),
        ("./scene.toml", "sub/../scene.toml"),
        ("scene.toml", "sub/same.toml"),
    ] {
        let before = listing(dir.path());
        let out = coin_log(
            dir.path(),
            &[
                "record",
                scene,
                "-o",
                target,
                "--overwrite",
                "--duration",
                "1",
            ],
        );
        let err = stderr(&out);
        println!("record {scene} -o {target}: exit {}: {err}", code(&out));
        assert_eq!(code(&out), 1);
        assert!(
            err.contains("is the scene file being recorded") && err.contains("-o scene.mcap"),
            "{err}"
        );
        assert_eq!(listing(dir.path()), before);
        assert_eq!(
            std::fs::read_to_string(dir.path().join("scene.toml")).unwrap(),
            text
        );
    }
}

#[test]
fn a_name_too_long_fails_at_once_with_the_systems_reason() {
    let dir = tempfile::tempdir().unwrap();
    let name = format!("{}.mcap", "a".repeat(300));
    refused(dir.path(), &name, &["File name too long"]);
    // Without --overwrite too, and no temporary file is left in either case.
    let out = coin_log(dir.path(), &["record", "wobble", "-o", &name]);
    assert_eq!(code(&out), 1, "{}", stderr(&out));
    assert!(stderr(&out).contains("File name too long"));
    assert!(listing(dir.path()).is_empty(), "{:?}", listing(dir.path()));
}

#[test]
fn a_missing_folder_or_a_file_used_as_a_folder_is_named() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("plain"), "x").unwrap();
    refused(
        dir.path(),
        "nowhere/x.mcap",
        &["the folder `nowhere` does not exist", "create it first"],
    );
    refused(dir.path(), "plain/x.mcap", &["Not a directory"]);
}

/// The benchmarks' `--out` folder is created as export's is: a device or file in its place is named as
/// not a folder before any measuring (it said "File exists (os error 17)").
#[test]
fn a_bench_out_that_is_no_folder_is_named_before_measuring() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("plain"), "x").unwrap();
    for (out, says) in [
        (
            "/dev/null",
            "`/dev/null` is not a folder; --out takes a folder",
        ),
        ("plain", "`plain` is not a folder; --out takes a folder"),
        (
            "plain/sub",
            "`plain` is not a folder, so `plain/sub` cannot be created in it",
        ),
    ] {
        let output = coin_log(dir.path(), &["bench", "euler", "--out", out]);
        assert_eq!(code(&output), 1, "{out}");
        assert!(stderr(&output).contains(says), "{out}: {}", stderr(&output));
    }
    assert_eq!(std::fs::read(dir.path().join("plain")).unwrap(), b"x");
}

/// A result file of a bench that is a pipe, a folder or a link is refused with a fix that works for a
/// folder's files: before, it said "choose a file path, e.g. --out bench-results" (--out takes a folder)
/// or "give the path it points to" (the bench names its files; no flag gives one).
#[test]
fn a_bench_result_file_that_cannot_be_replaced_gets_a_folder_fix() {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path();
    std::fs::create_dir_all(root.join("pipe")).unwrap();
    mkfifo(&root.join("pipe/euler.csv"));
    std::fs::create_dir_all(root.join("folder/euler.svg")).unwrap();
    std::fs::create_dir_all(root.join("link")).unwrap();
    std::os::unix::fs::symlink(root.join("elsewhere.svg"), root.join("link/euler.svg")).unwrap();
    for out in ["pipe", "folder", "link"] {
        let output = coin_log(root, &["bench", "euler", "--out", out]);
        let err = stderr(&output);
        assert_eq!(code(&output), 1, "{out}: {err}");
        assert!(
            err.contains("move it away, or choose another folder with --out"),
            "{out}: {err}"
        );
        assert!(
            !err.contains("file path") && !err.contains("points to"),
            "{out}: {err}"
        );
    }
    assert!(!root.join("elsewhere.svg").exists());
}

#[test]
fn a_folder_without_write_permission_fails_before_simulating() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let locked = dir.path().join("locked");
    std::fs::create_dir(&locked).unwrap();
    std::fs::set_permissions(&locked, std::fs::Permissions::from_mode(0o555)).unwrap();
    let probe = dir.path().join("probe");
    std::fs::write(&probe, "").unwrap();
    let root = std::fs::metadata(&probe).unwrap().uid() == 0;
    if root {
        // Root writes anywhere; the check cannot be exercised (CI runs it as a user).
        println!("running as root: a folder without write permission is writable; skipped");
    } else {
        refused(
            dir.path(),
            "locked/x.mcap",
            &["Permission denied", "locked"],
        );
        assert!(listing(&locked).is_empty());
    }
    std::fs::set_permissions(&locked, std::fs::Permissions::from_mode(0o755)).unwrap();
}

/// Starts a long recording in `dir`, waits for its temporary file, and sends `signals` (`-TERM`, ...),
/// each after its delay; returns the exit code and the process's stderr. Only the first signal must be
/// delivered: the process may be gone before a later one.
fn record_and_signal(dir: &Path, signals: &[(&str, Duration)]) -> (Option<i32>, String) {
    let mut child = Process::start(
        Command::new(exe())
            .args(["record", "long-horizon", "-o", "long.mcap"])
            .args(LONG)
            .current_dir(dir),
    );
    let started = Instant::now();
    while listing(dir).is_empty() {
        assert!(
            started.elapsed() < Duration::from_secs(30),
            "no temporary file appeared"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    for (i, (signal, delay)) in signals.iter().enumerate() {
        std::thread::sleep(*delay);
        let status = Command::new("kill")
            .args([*signal, &child.id().to_string()])
            .stderr(Stdio::null())
            .status()
            .unwrap();
        assert!(status.success() || i > 0, "kill {signal}");
    }
    // Within 60 s of the signals.
    let out = child.wait_within(Duration::from_secs(60));
    (out.status.code(), out.stderr)
}

/// SIGTERM (a service manager, `kill`) and SIGHUP (the terminal closed) finish the file like Ctrl-C:
/// marked interrupted, exit 130, and no hidden temporary file left.
#[test]
fn sigterm_and_sighup_finish_the_file_marked_interrupted() {
    for signal in ["-TERM", "-HUP"] {
        let dir = tempfile::tempdir().unwrap();
        let (exit, err) = record_and_signal(dir.path(), &[(signal, Duration::from_millis(500))]);
        println!("{signal}: exit {exit:?}: {err}");
        assert_eq!(exit, Some(130), "{signal}: {err}");
        assert!(err.contains("finishing the file"), "{err}");
        assert_eq!(listing(dir.path()), vec!["long.mcap".to_string()]);
        let file = read_back(&std::fs::read(dir.path().join("long.mcap")).unwrap());
        let result = ResultMetadata::from_map(&file.metadata[RESULT_METADATA_NAME].1).unwrap();
        println!(
            "  termination {} at t = {}, {} messages",
            result.termination,
            result.termination_time,
            file.messages.len()
        );
        assert_eq!(result.termination, Termination::Interrupted);
        assert!(result.termination_time > 0.0 && result.termination_time < 100_000.0);
    }
}

/// A second signal abandons the recording at once: exit 130, nothing written, no temporary file.
#[test]
fn a_second_signal_abandons_the_recording_and_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    // The second SIGTERM comes 1 ms after the first. Finishing the file takes a few milliseconds too, so
    // either may win; both outcomes must be clean: the finished file, or nothing at all.
    let (exit, err) = record_and_signal(
        dir.path(),
        &[
            ("-TERM", Duration::from_millis(500)),
            ("-TERM", Duration::from_millis(1)),
        ],
    );
    println!("exit {exit:?}: {err}");
    assert_eq!(exit, Some(130), "{err}");
    let files = listing(dir.path());
    assert!(
        files.is_empty() || files == vec!["long.mcap".to_string()],
        "a finished file or nothing, never a temporary file: {files:?}"
    );
}

/// `plot`, `export` and `analyse map` also move finished files into place: with `--overwrite` (or, for
/// the map, always replacing its own files) they must still refuse a named pipe and a symbolic link,
/// leave both intact, and leave no temporary file (negative control: a regular file is replaced).
#[test]
fn plot_export_and_the_map_never_replace_a_pipe_or_a_link() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let out = coin_log(d, &["record", "topple", "-o", "topple.mcap"]);
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    std::fs::create_dir(d.join("tables")).unwrap();
    std::fs::write(d.join("real"), "precious").unwrap();
    for name in ["pipe.svg", "tables/omega.csv", "stability-map.csv"] {
        mkfifo(&d.join(name));
    }
    std::os::unix::fs::symlink("real", d.join("link.svg")).unwrap();
    let runs: [(&[&str], &str); 4] = [
        (
            &["plot", "topple.mcap", "--out", "pipe.svg", "--overwrite"],
            "`pipe.svg` is a named pipe",
        ),
        (
            &["plot", "topple.mcap", "--out", "link.svg", "--overwrite"],
            "`link.svg` is a symbolic link (to `real`)",
        ),
        (
            &["export", "topple.mcap", "--out", "tables", "--overwrite"],
            "omega.csv` is a named pipe",
        ),
        (
            &[
                "analyse",
                "map",
                "--theta",
                "0.1:0.2:3",
                "--omega-z",
                "0.1:0.2:3",
                "--out",
                ".",
            ],
            "stability-map.csv` is a named pipe",
        ),
    ];
    let before = listing(d);
    for (args, needle) in runs {
        let out = coin_log(d, args);
        assert_eq!(code(&out), 1, "{args:?}: {}", stderr(&out));
        assert!(stderr(&out).contains(needle), "{args:?}: {}", stderr(&out));
        assert_eq!(listing(d), before, "{args:?}: the folder is as it was");
    }
    for name in ["pipe.svg", "tables/omega.csv", "stability-map.csv"] {
        let meta = std::fs::symlink_metadata(d.join(name)).unwrap();
        assert!(meta.file_type().is_fifo(), "{name} is intact");
    }
    assert!(std::fs::symlink_metadata(d.join("link.svg"))
        .unwrap()
        .file_type()
        .is_symlink());
    assert_eq!(std::fs::read(d.join("real")).unwrap(), b"precious");
    assert_eq!(
        listing(&d.join("tables")),
        ["omega.csv"],
        "no table, no temporary file"
    );
    // Negative control: a regular file in the way is replaced with --overwrite.
    std::fs::write(d.join("plain.svg"), "old").unwrap();
    let out = coin_log(
        d,
        &["plot", "topple.mcap", "--out", "plain.svg", "--overwrite"],
    );
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    assert!(std::fs::read_to_string(d.join("plain.svg"))
        .unwrap()
        .contains("<svg"));
}

/// A file-size limit (`ulimit -f`) reached mid-write is an error like a full disk: exit 1 naming it, and
/// no temporary file or created folder left. The signal of that limit, SIGXFSZ, used to kill the process
/// (exit 153, no message) with its `.coin-log-*.tmp` file left behind.
#[test]
fn a_file_size_limit_reached_mid_write_fails_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let under_limit = |kib: u32, args: &[&str]| {
        Command::new("sh")
            .arg("-c")
            .arg(format!("ulimit -f {kib} && exec \"$0\" \"$@\""))
            .arg(exe())
            .args(args)
            .current_dir(d)
            .output()
            .unwrap()
    };
    for (kib, args) in [
        (
            64,
            &["record", "wobble", "--duration", "30", "-o", "big.mcap"][..],
        ),
        (1, &["man", "--out", "pages"][..]),
        (
            1,
            &["analyse", "map", "--theta", "0.1:1:50", "--out", "map"][..],
        ),
    ] {
        let out = under_limit(kib, args);
        let err = stderr(&out);
        assert_eq!(
            out.status.code(),
            Some(1),
            "{args:?}: {:?} {err}",
            out.status
        );
        assert!(err.contains("File too large"), "{args:?}: {err}");
        assert_eq!(listing(d), Vec::<String>::new(), "{args:?}: nothing left");
    }
    // Negative control: under a limit it stays below, the recording is written.
    let out = under_limit(
        100_000,
        &["record", "wobble", "--duration", "1", "-o", "small.mcap"],
    );
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    assert_eq!(listing(d), ["small.mcap"]);
}

/// A finished output has the mode a new file gets from the umask, as any tool's output does: it was
/// 0644 whatever the umask, so `umask 077` still gave world-readable recordings.
#[test]
fn a_finished_file_has_the_mode_the_umask_gives() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for (umask, mode) in [("077", 0o600), ("002", 0o664), ("022", 0o644)] {
        let name = format!("u{umask}.mcap");
        let out = Command::new("sh")
            .arg("-c")
            .arg(format!("umask {umask} && exec \"$0\" \"$@\""))
            .arg(exe())
            .args(["record", "wobble", "--duration", "0.1", "-o", &name])
            .current_dir(d)
            .output()
            .unwrap();
        assert_eq!(code(&out), 0, "{}", stderr(&out));
        let found = std::fs::metadata(d.join(&name)).unwrap().mode() & 0o777;
        assert_eq!(found, mode, "umask {umask}: mode {found:o}");
    }
}

/// A legal target name with a long extension is written: its temporary file's name repeated the
/// extension and, 20 bytes longer than the target's, was refused as "File name too long".
#[test]
fn a_long_extension_does_not_make_the_temporary_name_too_long() {
    let dir = tempfile::tempdir().unwrap();
    let name = format!("x.{}", "e".repeat(245));
    let out = coin_log(
        dir.path(),
        &["record", "wobble", "--duration", "0.1", "-o", &name],
    );
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    assert_eq!(listing(dir.path()), [name]);
    // Negative control: a name beyond the system's limit is still refused, with its reason.
    refused(
        dir.path(),
        &format!("x.{}", "e".repeat(254)),
        &["File name too long"],
    );
}

/// A symbolic link in the way is refused with a fix that works: `/dev/stdout` leads to a pipe or a
/// terminal (it said "give the path it points to", that is `pipe:[…]`), and a page of `man --out`
/// cannot be given alone (the fix is another folder).
#[test]
fn a_refused_link_is_given_a_fix_that_works() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let out = Command::new(exe())
        .args(["record", "wobble", "-o", "/dev/stdout"])
        .args(LONG)
        .current_dir(d)
        .stdout(Stdio::piped())
        .output()
        .unwrap();
    let err = stderr(&out);
    assert_eq!(code(&out), 1, "{err}");
    assert!(
        err.contains("it leads to a named pipe")
            && err.contains("choose a file path, e.g. -o wobble.mcap")
            && !err.contains("give the path it points to"),
        "{err}"
    );
    std::fs::create_dir(d.join("pages")).unwrap();
    std::os::unix::fs::symlink("elsewhere", d.join("pages/coin-log.1")).unwrap();
    let out = coin_log(d, &["man", "--out", "pages"]);
    let err = stderr(&out);
    assert_eq!(code(&out), 1, "{err}");
    assert!(
        err.contains("move it away, or choose another folder with --out"),
        "{err}"
    );
    assert_eq!(listing(&d.join("pages")), ["coin-log.1"], "only the link");
    // Negative control: a link to a regular file is still told to give the file.
    std::fs::write(d.join("real.mcap"), "x").unwrap();
    std::os::unix::fs::symlink("real.mcap", d.join("link.mcap")).unwrap();
    refused(d, "link.mcap", &["give the path it points to"]);
}

/// A link in the way that leads to a folder is told to name a file in it, and an output folder that is
/// a link to nothing is named as such (it said "cannot create the folder `x`: File exists").
#[test]
fn a_link_to_a_folder_or_to_nothing_is_named_with_its_fix() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::create_dir(d.join("real")).unwrap();
    std::os::unix::fs::symlink("real", d.join("to-folder")).unwrap();
    refused(
        d,
        "to-folder",
        &["it leads to a folder; give a file name, e.g. -o to-folder/wobble.mcap"],
    );
    std::os::unix::fs::symlink("nowhere", d.join("dangling")).unwrap();
    for out in ["dangling", "dangling/sub"] {
        let output = coin_log(d, &["man", "--out", out]);
        let err = stderr(&output);
        assert_eq!(code(&output), 1, "{err}");
        assert!(
            err.contains("`dangling` is a symbolic link to `nowhere`, which does not exist"),
            "{out}: {err}"
        );
    }
    assert!(!d.join("nowhere").exists());
    // Negative control: a link to a folder is a folder to write into.
    let output = coin_log(d, &["man", "--out", "to-folder"]);
    assert_eq!(code(&output), 0, "{}", stderr(&output));
    assert!(d.join("real/coin-log.1").exists());
}

/// A scene file named like its default output (`s.mcap`, recorded to `s.mcap`) is protected, and the fix
/// suggests another name: it suggested `-o s.mcap`, the refused path itself.
#[test]
fn a_scene_named_like_its_output_is_told_another_name() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = coin_log(d, &["scenes", "--show", "wobble"]);
    std::fs::write(d.join("s.mcap"), &scene.stdout).unwrap();
    let out = coin_log(d, &["record", "./s.mcap", "--duration", "0.1"]);
    let err = stderr(&out);
    assert_eq!(code(&out), 1, "{err}");
    assert!(
        err.contains("is the scene file being recorded") && err.contains("e.g. -o s-recorded.mcap"),
        "{err}"
    );
    assert_eq!(std::fs::read(d.join("s.mcap")).unwrap(), scene.stdout);
    // Negative control: the suggestion works.
    let out = coin_log(
        d,
        &[
            "record",
            "./s.mcap",
            "--duration",
            "0.1",
            "-o",
            "s-recorded.mcap",
        ],
    );
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    // And a scene whose stem differs from the target keeps the usual example.
    std::fs::write(d.join("w.toml"), &scene.stdout).unwrap();
    let out = coin_log(d, &["record", "./w.toml", "-o", "w.toml", "--overwrite"]);
    assert!(stderr(&out).contains("e.g. -o w.mcap"), "{}", stderr(&out));
}

/// `-o new/` (a folder that is not there) is named as such: the system's reason was "cannot create
/// `new/`: Is a directory (os error 21)", about a name that does not exist.
#[test]
fn an_output_ending_with_a_slash_that_names_no_folder_is_named() {
    let dir = tempfile::tempdir().unwrap();
    refused(
        dir.path(),
        "new/",
        &["`new/` ends with `/`, so it names a folder, and there is none: drop the `/`, or create the folder and give a file name, e.g. -o new/wobble.mcap"],
    );
    // Negative control: an existing folder with a slash is the folder case, and without it the name works.
    std::fs::create_dir(dir.path().join("there")).unwrap();
    refused(
        dir.path(),
        "there/",
        &["`there/` is a folder; give a file name"],
    );
    let out = coin_log(
        dir.path(),
        &["record", "wobble", "--duration", "0.1", "-o", "new"],
    );
    assert_eq!(code(&out), 0, "{}", stderr(&out));
}

/// `plot` and `export` never replace the recording they read, even with `--overwrite` and however it is
/// named (the same path, another spelling of it, a table name in the export folder): it would be gone
/// once the output is moved into place. Negative control: another existing file is replaced.
#[test]
fn plot_and_export_never_replace_the_recording_they_read() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let out = coin_log(d, &["record", "topple", "-o", "run.mcap"]);
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    std::fs::create_dir(d.join("tables")).unwrap();
    std::fs::copy(d.join("run.mcap"), d.join("tables/omega.csv")).unwrap();
    let recording = std::fs::read(d.join("run.mcap")).unwrap();
    let runs: [(&[&str], &str, &str); 3] = [
        (
            &["plot", "run.mcap", "--out", "run.mcap", "--overwrite"],
            "`run.mcap` is the recording being plotted; writing there would replace it",
            "run.mcap",
        ),
        (
            &[
                "plot",
                "run.mcap",
                "--out",
                "./tables/../run.mcap",
                "--overwrite",
            ],
            "is the recording being plotted",
            "run.mcap",
        ),
        (
            &[
                "export",
                "tables/omega.csv",
                "--out",
                "tables",
                "--overwrite",
            ],
            "omega.csv` is the recording being exported; writing there would replace it",
            "tables/omega.csv",
        ),
    ];
    let before = (listing(d), listing(&d.join("tables")));
    for (args, needle, input) in runs {
        let out = coin_log(d, args);
        println!("{args:?}: exit {}: {}", code(&out), stderr(&out));
        assert_eq!(code(&out), 1, "{args:?}: {}", stderr(&out));
        assert!(stderr(&out).contains(needle), "{args:?}: {}", stderr(&out));
        assert_eq!(std::fs::read(d.join(input)).unwrap(), recording, "{args:?}");
        assert_eq!(
            (listing(d), listing(&d.join("tables"))),
            before,
            "{args:?}: the folders are as they were"
        );
    }
    // Negative control: another file of the same names is replaced with --overwrite.
    std::fs::write(d.join("other.svg"), "old").unwrap();
    let out = coin_log(
        d,
        &["plot", "run.mcap", "--out", "other.svg", "--overwrite"],
    );
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let out = coin_log(d, &["export", "run.mcap", "--out", "tables", "--overwrite"]);
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    assert!(std::fs::read_to_string(d.join("tables/omega.csv"))
        .unwrap()
        .starts_with("t,"));
}

/// `bench sweep` deletes its folder `DIR/sweep-bench` before and after its work: a folder of that name
/// holding anything the bench does not write (a sweep of the user's), or a link of that name, is refused
/// before any work and kept, not deleted.
#[test]
fn bench_sweep_never_deletes_a_sweep_bench_folder_it_did_not_write() {
    let dir = tempfile::tempdir().unwrap();
    let mine = dir.path().join("o/sweep-bench/my-dataset");
    std::fs::create_dir_all(&mine).unwrap();
    std::fs::write(mine.join("catalogue.csv"), "important").unwrap();
    std::fs::create_dir(dir.path().join("p")).unwrap();
    std::os::unix::fs::symlink(&mine, dir.path().join("p/sweep-bench")).unwrap();
    for (out, says) in [
        ("o", "it holds `my-dataset`, which the bench did not write"),
        ("p", "it is not a folder"),
    ] {
        let started = Instant::now();
        let output = coin_log(
            dir.path(),
            &["bench", "sweep", "--repeats", "1", "--out", out],
        );
        assert_eq!(code(&output), 1, "{out}: {}", stderr(&output));
        assert!(stderr(&output).contains(says), "{out}: {}", stderr(&output));
        assert!(
            stderr(&output).contains("choose another folder with --out"),
            "{}",
            stderr(&output)
        );
        assert!(
            started.elapsed() < Duration::from_secs(10),
            "refused before any sweep"
        );
    }
    assert_eq!(
        std::fs::read_to_string(mine.join("catalogue.csv")).unwrap(),
        "important"
    );
    assert!(std::fs::symlink_metadata(dir.path().join("p/sweep-bench"))
        .unwrap()
        .file_type()
        .is_symlink());
}

/// `--out -` of the commands that write into a folder is refused like `-o -` (it created a folder named
/// `-`): nothing goes to standard output, and `./-` names such a folder.
#[test]
fn a_folder_output_dash_is_refused_like_a_file_output_dash() {
    let dir = tempfile::tempdir().unwrap();
    let file = crate::support::repo().join("datasets/wobble.mcap");
    let file = file.to_str().unwrap();
    for args in [
        vec!["export", file, "--out", "-"],
        vec!["man", "--out", "-"],
        vec![
            "analyse",
            "map",
            "--theta",
            "0.1:1:3",
            "--omega-z",
            "0:1:3",
            "--out",
            "-",
        ],
        vec!["bench", "euler", "--out", "-"],
    ] {
        let output = coin_log(dir.path(), &args);
        assert_eq!(code(&output), 1, "{args:?}: {}", stderr(&output));
        assert!(
            stderr(&output).contains("`-` would be a folder named `-`")
                && stderr(&output).contains("`./-`"),
            "{args:?}: {}",
            stderr(&output)
        );
    }
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        0,
        "no folder `-`"
    );
    let output = coin_log(dir.path(), &["man", "--out", "./-"]);
    assert_eq!(code(&output), 0, "{}", stderr(&output));
    assert!(dir.path().join("-/coin-log.1").is_file());
}

/// A scene file whose name is not UTF-8 is recorded, analysed and mapped like any other (clap refused it:
/// "invalid UTF-8 was detected in one or more arguments"), and record's default output keeps the stem's
/// own bytes (`caf\xe9.mcap`, not a lossy `caf\u{fffd}.mcap`, which two such names would share).
#[test]
fn a_scene_file_whose_name_is_not_utf8_is_recorded_with_its_own_bytes() {
    use std::ffi::OsStr;
    use std::os::unix::ffi::OsStrExt;
    let dir = tempfile::tempdir().unwrap();
    let shown = coin_log(dir.path(), &["scenes", "--show", "wobble"]);
    let scene = OsStr::from_bytes(b"caf\xe9.toml");
    std::fs::write(dir.path().join(scene), &shown.stdout).unwrap();
    let runs: [&[&OsStr]; 3] = [
        &[
            OsStr::new("record"),
            scene,
            OsStr::new("--duration"),
            OsStr::new("1"),
        ],
        &[OsStr::new("analyse"), scene],
        &[
            OsStr::new("analyse"),
            OsStr::new("map"),
            scene,
            OsStr::new("--theta"),
            OsStr::new("0.1:0.2:2"),
            OsStr::new("--omega-z"),
            OsStr::new("1:2:2"),
            OsStr::new("--out"),
            OsStr::new("map"),
        ],
    ];
    for args in runs {
        let out = coin_log(dir.path(), args);
        assert_eq!(
            code(&out),
            0,
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let recorded = OsStr::from_bytes(b"caf\xe9.mcap");
    assert!(
        dir.path().join(recorded).is_file(),
        "{:?}",
        listing(dir.path())
    );
    let verified = coin_log(dir.path(), &[OsStr::new("verify"), recorded]);
    assert_eq!(
        code(&verified),
        0,
        "{}",
        String::from_utf8_lossy(&verified.stdout)
    );
}

//! One output policy and one input policy for every command (files::output, files::input), tested
//! command by command as child processes: nothing but a regular file is ever replaced (a symbolic link, a
//! named pipe, a device, a folder are refused, a pipe without blocking), an existing file only where the
//! command allows it (`--overwrite`, or a command that replaces its own files), and a finished file whose
//! move into place fails is kept under the name the error gives. Inputs are regular files: scene paths to
//! devices, pipes and folders, `-` and `/dev/stdin` are refused with the reason, at once; `plot` and
//! `export` exit non-zero on a damaged file or nothing to export, and leave nothing behind.
// Helpers outside #[test] functions panic on failure too: a failed step is a failed test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use crate::support::mkfifo;
use crate::support::record::{coin_log, exe, listing};
use coin_log::files::input::{check, read_toml, InputKind, SCENE_MAX_BYTES};
use coin_log::files::{cut, shown, Output, OutputFolder, Policy};
use std::io::{Read, Write};
use std::os::unix::fs::FileTypeExt;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// A command that should refuse at once; it blocking on a pipe would run into this.
const DEADLINE: Duration = Duration::from_secs(20);

/// Runs coin-log in `dir` with `stdin` as its standard input, killing it (and failing) after [`DEADLINE`];
/// returns the exit code, stdout and stderr.
fn run(dir: &Path, args: &[&str], stdin: Stdio) -> (i32, String, String) {
    let mut child = Command::new(exe())
        .args(args)
        .current_dir(dir)
        .stdin(stdin)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let drain = |mut pipe: Box<dyn Read + Send>| {
        std::thread::spawn(move || {
            let mut text = String::new();
            let _ = pipe.read_to_string(&mut text);
            text
        })
    };
    let out = drain(Box::new(child.stdout.take().unwrap()));
    let err = drain(Box::new(child.stderr.take().unwrap()));
    let started = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if started.elapsed() > DEADLINE {
            let _ = child.kill();
            panic!("`coin-log {}` still ran after {DEADLINE:?}", args.join(" "));
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let (out, err) = (out.join().unwrap(), err.join().unwrap());
    println!(
        "coin-log {}: exit {:?}\n{err}",
        args.join(" "),
        status.code()
    );
    (status.code().unwrap_or(-1), out, err)
}

/// Every file under `dir` (relative paths, sorted), with its kind, so that a test sees any file left
/// behind or replaced.
fn tree(dir: &Path) -> Vec<String> {
    let mut all = Vec::new();
    for name in listing(dir) {
        let path = dir.join(&name);
        let kind = std::fs::symlink_metadata(&path).unwrap().file_type();
        if kind.is_dir() {
            all.extend(tree(&path).into_iter().map(|n| format!("{name}/{n}")));
        }
        let tag = match () {
            () if kind.is_symlink() => "link",
            () if kind.is_fifo() => "pipe",
            () if kind.is_dir() => "folder",
            () => "file",
        };
        all.push(format!("{name} ({tag})"));
    }
    all.sort();
    all
}

/// A command that writes, as the tests drive it.
struct Writer {
    name: &'static str,
    /// Its arguments for an output at `path`: the file, or for a folder writer the folder.
    args: fn(&str) -> Vec<String>,
    /// For a command that writes several files into a folder: the file the cases put things in the way of.
    in_folder: Option<&'static str>,
    /// What it does to an existing regular file without a flag: `Some(flag)` refuses unless given the
    /// flag; `None` replaces it (the command always replaces its own files).
    overwrite: Option<&'static str>,
}

fn strings(args: &[&str]) -> Vec<String> {
    args.iter().map(ToString::to_string).collect()
}

const WRITERS: &[Writer] = &[
    Writer {
        name: "record",
        args: |t| strings(&["record", "wobble", "--duration", "1", "-o", t]),
        in_folder: None,
        overwrite: Some("--overwrite"),
    },
    Writer {
        name: "plot",
        args: |t| strings(&["plot", "w.mcap", "--out", t]),
        in_folder: None,
        overwrite: Some("--overwrite"),
    },
    Writer {
        name: "export",
        args: |t| strings(&["export", "w.mcap", "--out", t]),
        in_folder: Some("omega.csv"),
        overwrite: Some("--overwrite"),
    },
    Writer {
        name: "analyse map",
        args: |t| {
            strings(&[
                "analyse",
                "map",
                "--theta",
                "0.1:0.2:3",
                "--omega-z",
                "0.1:0.2:3",
                "--out",
                t,
            ])
        },
        in_folder: Some("stability-map.csv"),
        overwrite: None,
    },
    Writer {
        name: "man",
        args: |t| strings(&["man", "--out", t]),
        in_folder: Some("coin-log-record.1"),
        overwrite: None,
    },
    #[cfg(feature = "live")]
    Writer {
        name: "live",
        args: |t| {
            strings(&[
                "live",
                "wobble",
                "--duration",
                "0.2",
                "--speed",
                "100",
                "--no-wait",
                "--exit",
                "--port",
                "0",
                "-o",
                t,
            ])
        },
        in_folder: None,
        overwrite: Some("--overwrite"),
    },
];

/// A fresh folder with a recording `w.mcap` (the input of plot and export) and a precious `real` file.
fn setup() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let out = coin_log(
        dir.path(),
        &["record", "wobble", "--duration", "1", "-o", "w.mcap"],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    std::fs::write(dir.path().join("real"), "precious").unwrap();
    dir
}

/// What is put in the way of an output.
#[derive(Debug, Clone, Copy)]
enum InTheWay {
    Link,
    Pipe,
    Device,
    Folder,
    /// `-`, which is no standard output: a file named `-` is `./-`.
    Dash,
}

/// Puts `what` where `w` writes in `dir`; returns the output argument and what stderr must say.
fn obstruct(w: &Writer, dir: &Path, what: InTheWay) -> (String, &'static str) {
    let (arg, at) = match w.in_folder {
        Some(file) => ("d".to_string(), format!("d/{file}")),
        None => ("out".to_string(), "out".to_string()),
    };
    if w.in_folder.is_some() {
        std::fs::create_dir(dir.join("d")).unwrap();
    }
    let path = dir.join(&at);
    match what {
        InTheWay::Link => {
            let to = if w.in_folder.is_some() {
                "../real"
            } else {
                "real"
            };
            std::os::unix::fs::symlink(to, &path).unwrap();
            (arg, "is a symbolic link")
        }
        InTheWay::Pipe => {
            mkfifo(&path);
            (arg, "is a named pipe, not a regular file")
        }
        InTheWay::Device if w.in_folder.is_some() => ("/dev/null".into(), "is not a folder"),
        InTheWay::Device => (
            "/dev/null".into(),
            "is a character device, not a regular file",
        ),
        InTheWay::Folder => {
            std::fs::create_dir(&path).unwrap();
            (arg, "is a folder")
        }
        InTheWay::Dash => ("-".into(), "`-` would be a file named `-`"),
    }
}

/// Every writing command refuses a link, a pipe (without blocking), a device and a folder where its output
/// goes, and a file output `-` (no standard output), with or without its overwrite flag, and leaves
/// everything as it was.
#[test]
fn no_command_writes_over_a_link_a_pipe_a_device_or_a_folder() {
    for w in WRITERS {
        for what in [
            InTheWay::Link,
            InTheWay::Pipe,
            InTheWay::Device,
            InTheWay::Folder,
            InTheWay::Dash,
        ] {
            if matches!(what, InTheWay::Dash) && w.in_folder.is_some() {
                continue; // A folder output named `-` is just a folder.
            }
            for flag in [None, w.overwrite] {
                let dir = setup();
                let (arg, needle) = obstruct(w, dir.path(), what);
                let before = tree(dir.path());
                let mut args = (w.args)(&arg);
                args.extend(flag.map(String::from));
                let args: Vec<&str> = args.iter().map(String::as_str).collect();
                let (code, _, err) = run(dir.path(), &args, Stdio::null());
                let case = format!("{} with {what:?} in the way ({flag:?})", w.name);
                assert_eq!(code, 1, "{case}: {err}");
                assert!(
                    err.contains(needle),
                    "{case}: stderr should say {needle:?}: {err}"
                );
                assert_eq!(tree(dir.path()), before, "{case}: everything as it was");
                assert_eq!(std::fs::read(dir.path().join("real")).unwrap(), b"precious");
            }
        }
        let null = std::fs::symlink_metadata("/dev/null").unwrap();
        assert!(null.file_type().is_char_device(), "/dev/null intact");
    }
}

/// An existing regular file is replaced only with the overwrite flag (or by a command that replaces its
/// own files), and no temporary file is left either way.
#[test]
fn an_existing_file_is_replaced_only_where_allowed() {
    for w in WRITERS {
        let dir = setup();
        let (arg, at) = match w.in_folder {
            Some(file) => {
                std::fs::create_dir(dir.path().join("d")).unwrap();
                ("d".to_string(), format!("d/{file}"))
            }
            None => ("out".to_string(), "out".to_string()),
        };
        std::fs::write(dir.path().join(&at), "old").unwrap();
        let before = tree(dir.path());
        let args = (w.args)(&arg);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let (code, _, err) = run(dir.path(), &args, Stdio::null());
        if let Some(flag) = w.overwrite {
            assert_eq!(code, 1, "{}: {err}", w.name);
            assert!(
                err.contains("already exists") && err.contains(flag),
                "{}: {err}",
                w.name
            );
            assert_eq!(std::fs::read(dir.path().join(&at)).unwrap(), b"old");
            assert_eq!(tree(dir.path()), before, "{}", w.name);
            let mut args = args.clone();
            args.push(flag);
            let (code, _, err) = run(dir.path(), &args, Stdio::null());
            assert_eq!(code, 0, "{} {flag}: {err}", w.name);
        } else {
            assert_eq!(code, 0, "{} replaces its own files: {err}", w.name);
        }
        assert_ne!(
            std::fs::read(dir.path().join(&at)).unwrap(),
            b"old",
            "{}: replaced",
            w.name
        );
        let after = tree(dir.path());
        assert!(
            after.iter().all(|f| !f.contains(".coin-log-")),
            "{}: no temporary file left: {after:?}",
            w.name
        );
    }
}

/// The target replaced by a folder while the recording runs (`--overwrite`): the finished recording is kept
/// under the name the error gives, and it is a whole recording.
#[test]
fn a_recording_whose_move_fails_is_kept_under_the_name_the_error_gives() {
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("x.mcap");
    std::fs::write(&target, "old").unwrap();
    let mut child = Command::new(exe())
        .args(["record", "long-horizon", "-o", "x.mcap", "--overwrite"])
        .args([
            "--duration",
            "100000",
            "--rate",
            "1000",
            "--integrator",
            "rk4",
        ])
        .current_dir(dir.path())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let started = Instant::now();
    // Until the recording holds a few chunks (so that verify can judge it), not just the temporary file.
    let written = || {
        listing(dir.path())
            .iter()
            .filter(|n| n.starts_with(".coin-log-"))
            .filter_map(|n| std::fs::metadata(dir.path().join(n)).ok())
            .any(|m| m.len() > 4 << 20)
    };
    while !written() {
        assert!(started.elapsed() < DEADLINE, "no recording was written");
        std::thread::sleep(Duration::from_millis(10));
    }
    std::fs::remove_file(&target).unwrap();
    std::fs::create_dir(&target).unwrap();
    let status = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let mut err = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    let code = child.wait().unwrap().code();
    println!("exit {code:?}: {err}");
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("`x.mcap` is a folder"), "{err}");
    let kept = err
        .split("it is kept as `")
        .nth(1)
        .and_then(|rest| rest.split('`').next())
        .unwrap_or_else(|| panic!("the error names the kept file: {err}"));
    let bytes = std::fs::read(kept).unwrap();
    let file = crate::support::record::read_back(&bytes);
    assert!(
        !file.on_topic("/coin/omega").is_empty(),
        "a whole recording"
    );
    let out = coin_log(dir.path(), &["verify", kept]);
    assert_eq!(out.status.code(), Some(0), "the kept file verifies");
}

/// Scene paths that are not regular files are refused at once with the reason, for every command that
/// reads a scene; so is a scene file larger than the limit.
#[test]
fn a_scene_path_to_a_device_a_pipe_a_folder_or_stdin_is_refused_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("scene.toml");
    mkfifo(&fifo);
    let big = dir.path().join("big.toml");
    let mut file = std::fs::File::create(&big).unwrap();
    file.write_all(&vec![b'#'; (1 << 20) + 1]).unwrap();
    let fifo = fifo.to_str().unwrap();
    let cases = [
        ("/dev/zero", "is a character device, not a regular file"),
        ("/dev/urandom", "is a character device, not a regular file"),
        (fifo, "is a named pipe, not a regular file"),
        ("/tmp/", "is a directory, not a scene file"),
        ("-", "reading standard input is not offered"),
        ("big.toml", "more than 1048576 bytes"),
    ];
    for (scene, needle) in cases {
        for command in [&["record"][..], &["analyse"], &["bench", "precision"]] {
            let mut args = command.to_vec();
            args.push(scene);
            // An endless writer on standard input, in case anything reads it.
            let mut yes = Command::new("yes").stdout(Stdio::piped()).spawn().unwrap();
            let endless = Stdio::from(yes.stdout.take().unwrap());
            let (code, _, err) = run(dir.path(), &args, endless);
            let _ = yes.kill();
            yes.wait().unwrap();
            assert_eq!(code, 1, "{args:?}: {err}");
            assert!(
                err.contains(needle),
                "{args:?}: stderr should say {needle:?}: {err}"
            );
        }
    }
}

/// A sweep file, and the base scene file it names, are inputs like a scene: a device, a pipe, a folder,
/// `-` or a file above the limit is refused at once (exit 2, the sweep's code for a file it cannot use),
/// with nothing written; and a sweep folder's own files (journal, plan, catalogue parts, run files) are
/// read only if they are regular files, so a pipe put there cannot block a resume or a collect.
#[test]
fn a_sweep_file_its_base_and_its_folders_files_are_read_only_as_regular_files() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("pipe.toml");
    mkfifo(&fifo);
    std::fs::write(dir.path().join("big.toml"), vec![b'#'; (1 << 20) + 1]).unwrap();
    let cases = [
        (
            "/dev/zero",
            "is a character device, not a regular file: a sweep file is read whole",
        ),
        ("pipe.toml", "is a named pipe, not a regular file"),
        ("/tmp/", "is a directory, not a sweep file"),
        ("-", "reading standard input is not offered"),
        ("big.toml", "more than 1048576 bytes"),
    ];
    for (path, needle) in cases {
        let (code, _, err) = run(dir.path(), &["sweep", path, "-o", "out"], Stdio::null());
        assert_eq!(code, 2, "{path}: {err}");
        assert!(
            err.contains(needle),
            "{path}: stderr should say {needle:?}: {err}"
        );
        if path == "-" {
            continue; // As a base, `-` is a name: no built-in scene (tested in sweep.rs).
        }
        let base = format!("base = \"{path}\"\n");
        std::fs::write(dir.path().join("s.toml"), base).unwrap();
        let (code, _, err) = run(dir.path(), &["sweep", "s.toml", "-o", "out"], Stdio::null());
        assert_eq!(code, 2, "base {path}: {err}");
        let needle = needle.replace("a sweep file", "a scene file");
        assert!(
            err.contains("`base`") && err.contains(&needle),
            "base {path}: {err}"
        );
        assert!(!dir.path().join("out").exists(), "{path}: nothing written");
    }
    let sweep = "base = \"wobble\"\nset = { \"run.duration\" = 1.0, \"run.rate\" = 20.0 }\n";
    std::fs::write(dir.path().join("s.toml"), sweep).unwrap();
    let (code, _, err) = run(dir.path(), &["sweep", "s.toml", "-o", "out"], Stdio::null());
    assert_eq!(code, 0, "{err}");
    let state = dir.path().join("out/.coin-log-sweep");
    let journal = std::fs::read_dir(&state)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| {
            p.file_name()
                .unwrap()
                .to_str()
                .unwrap()
                .starts_with("journal-")
        })
        .expect("a journal");
    for (victim, needle) in [
        (journal, "reading the journal"),
        (state.join("plan.json"), "plan"),
    ] {
        let saved = std::fs::read(&victim).unwrap();
        std::fs::remove_file(&victim).unwrap();
        mkfifo(&victim);
        let (code, _, err) = run(dir.path(), &["sweep", "s.toml", "-o", "out"], Stdio::null());
        assert_ne!(code, 0, "{victim:?}: {err}");
        assert!(
            err.contains(needle) && err.contains("is a named pipe, not a regular file"),
            "{victim:?}: {err}"
        );
        std::fs::remove_file(&victim).unwrap();
        std::fs::write(&victim, saved).unwrap();
    }
}

/// `info` refuses a named pipe (it would block) and standard input, saying which; piped in, a real
/// recording is still refused as a stream, not called "not MCAP".
#[test]
fn info_refuses_a_pipe_and_says_when_it_is_standard_input() {
    let dir = setup();
    let fifo = dir.path().join("pipe.mcap");
    mkfifo(&fifo);
    for command in ["info", "export", "plot", "verify"] {
        let (code, _, err) = run(dir.path(), &[command, "pipe.mcap"], Stdio::null());
        assert!(code == 1 || code == 2, "{command}: {err}");
        assert!(
            err.contains("is not a regular file (a pipe, socket or device)"),
            "{command}: {err}"
        );
    }
    let recording = std::fs::File::open(dir.path().join("w.mcap")).unwrap();
    let mut cat = Command::new("cat")
        .stdin(recording)
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let piped = Stdio::from(cat.stdout.take().unwrap());
    let (code, _, err) = run(dir.path(), &["info", "/dev/stdin"], piped);
    let _ = cat.kill();
    cat.wait().unwrap();
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("is standard input, not a regular file"),
        "{err}"
    );
    assert!(!err.contains("not an MCAP"), "{err}");
    // Redirected from a file, standard input is that file, and is read.
    let recording = std::fs::File::open(dir.path().join("w.mcap")).unwrap();
    let (code, out, err) = run(dir.path(), &["info", "/dev/stdin"], Stdio::from(recording));
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("/coin/omega"), "{out}");
    let (code, _, err) = run(dir.path(), &["info", "-"], Stdio::null());
    assert_eq!(code, 1);
    assert!(
        err.contains("reading standard input is not offered"),
        "{err}"
    );
}

/// `plot` of a truncated file draws what there is but exits 1 and says "truncated"; a file cut right after
/// its magic is called truncated too, not "not a coin-log file".
#[test]
fn plot_of_a_damaged_file_exits_non_zero_and_names_the_problem() {
    let dir = setup();
    let bytes = std::fs::read(dir.path().join("w.mcap")).unwrap();
    std::fs::write(dir.path().join("half.mcap"), &bytes[..bytes.len() / 2]).unwrap();
    std::fs::write(dir.path().join("magic.mcap"), &bytes[..8]).unwrap();
    let (code, out, err) = run(dir.path(), &["plot", "half.mcap"], Stdio::null());
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("half.mcap: truncated") && err.contains("shows the file up to the break"),
        "{err}"
    );
    assert_eq!(out.trim(), "half.svg");
    let svg = std::fs::read_to_string(dir.path().join("half.svg")).unwrap();
    assert!(svg.contains("file breaks off"), "the picture says so too");
    let (code, _, err) = run(dir.path(), &["plot", "magic.mcap"], Stdio::null());
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("truncated") && !err.contains("not a coin-log file"),
        "{err}"
    );
    assert!(!dir.path().join("magic.svg").exists());
}

/// `export` of an MCAP file without a coin-log channel exits 1 and says there is nothing to export,
/// leaving no folder behind.
#[test]
fn export_of_a_file_without_coin_log_channels_exits_non_zero() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("other.mcap");
    let mut writer = mcap::Writer::new(std::io::BufWriter::new(
        std::fs::File::create(&path).unwrap(),
    ))
    .unwrap();
    let channel = writer
        .add_channel(0, "/weather", "json", &std::collections::BTreeMap::new())
        .unwrap();
    let header = mcap::records::MessageHeader {
        channel_id: channel,
        sequence: 0,
        log_time: 0,
        publish_time: 0,
    };
    writer.write_to_known_channel(&header, b"{}").unwrap();
    writer.finish().unwrap();
    drop(writer);
    let (code, _, err) = run(dir.path(), &["export", "other.mcap"], Stdio::null());
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("nothing to export") && err.contains("/weather: not a coin-log channel"),
        "{err}"
    );
    assert_eq!(listing(dir.path()), ["other.mcap"], "no folder left");
}

/// `export --overwrite` into a folder that holds a table this export does not write (another recording's
/// channel) replaces its own tables, leaves the other one alone and names it on stderr; the control, the
/// same export into the folder without it, warns of nothing.
#[test]
fn export_names_the_tables_in_its_folder_that_it_did_not_write() {
    let dir = tempfile::tempdir().unwrap();
    let file = crate::support::record::record_scene(dir.path(), "straight", &["--duration", "0.1"]);
    let file = file.to_str().unwrap();
    let (code, _, err) = run(dir.path(), &["export", file, "--out", "t"], Stdio::null());
    assert_eq!(code, 0, "{err}");
    assert!(
        !err.contains("warning"),
        "nothing else in the folder: {err}"
    );
    std::fs::write(dir.path().join("t/extra.csv"), "t,x\n0,1\n").unwrap();
    let (code, _, err) = run(
        dir.path(),
        &["export", file, "--out", "t", "--overwrite"],
        Stdio::null(),
    );
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("warning: t also holds extra.csv, which this export did not write"),
        "{err}"
    );
    assert_eq!(
        std::fs::read_to_string(dir.path().join("t/extra.csv")).unwrap(),
        "t,x\n0,1\n",
        "left alone"
    );
}

// The library's policies (coin_log::files) without a child process.

fn policy(overwrite: bool) -> Policy {
    Policy {
        overwrite,
        overwrite_flag: true,
        flag: "-o",
        example: "x.txt".into(),
        protect: None,
    }
}

#[test]
fn a_file_lands_whole_and_replaces_only_with_overwrite() {
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("a.txt");
    Output::write(&target, &policy(false), b"one").unwrap();
    assert_eq!(std::fs::read(&target).unwrap(), b"one");
    let e = Output::write(&target, &policy(false), b"two").unwrap_err();
    assert!(e.to_string().contains("already exists"), "{e}");
    Output::write(&target, &policy(true), b"two").unwrap();
    assert_eq!(std::fs::read(&target).unwrap(), b"two");
    assert_eq!(listing(dir.path()), ["a.txt"]);
}

#[test]
fn a_target_replaced_by_a_folder_keeps_the_finished_file_and_names_it() {
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("a.txt");
    std::fs::write(&target, "old").unwrap();
    let mut output = Output::create(&target, &policy(true)).unwrap();
    output.file().write_all(b"finished").unwrap();
    std::fs::remove_file(&target).unwrap();
    std::fs::create_dir(&target).unwrap();
    let e = output.commit().unwrap_err().to_string();
    println!("{e}");
    let kept = e.split("kept as `").nth(1).unwrap().trim_end_matches('`');
    assert!(e.contains("is a folder"), "{e}");
    assert_eq!(std::fs::read(kept).unwrap(), b"finished");
}

#[test]
fn a_dropped_folder_output_leaves_nothing_not_even_its_folders() {
    let dir = tempfile::tempdir().unwrap();
    let mut folder = OutputFolder::create(&dir.path().join("a/b"), false).unwrap();
    folder.file("t.csv").unwrap().write_all(b"x").unwrap();
    assert_eq!(
        listing(&dir.path().join("a/b")).len(),
        1,
        "the temporary file"
    );
    drop(folder);
    assert!(listing(dir.path()).is_empty(), "{:?}", listing(dir.path()));
    let mut folder = OutputFolder::create(&dir.path().join("c"), false).unwrap();
    folder.file("t.csv").unwrap().write_all(b"x").unwrap();
    folder.commit().unwrap();
    assert_eq!(listing(&dir.path().join("c")), ["t.csv"]);
}

#[test]
fn devices_folders_and_stdin_are_refused_with_the_reason() {
    for (path, needle) in [
        ("/dev/zero", "is a character device, not a regular file"),
        ("/dev/urandom", "is a character device"),
        ("/", "is a directory, not a scene file"),
        ("-", "reading standard input is not offered"),
    ] {
        let e = read_toml(Path::new(path), InputKind::Scene)
            .unwrap_err()
            .to_string();
        assert!(e.contains(needle), "{path}: {e}");
    }
    let e = check(Path::new("/dev/null"), InputKind::Mcap).unwrap_err();
    assert!(e.to_string().starts_with("is not a regular file"), "{e}");
}

#[test]
fn a_scene_above_the_limit_is_refused_and_one_at_it_read() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("s.toml");
    let at = usize::try_from(SCENE_MAX_BYTES).unwrap();
    std::fs::write(&path, "#".repeat(at)).unwrap();
    assert_eq!(read_toml(&path, InputKind::Scene).unwrap().len(), at);
    std::fs::write(&path, "#".repeat(at + 1)).unwrap();
    let e = read_toml(&path, InputKind::Scene).unwrap_err().to_string();
    assert!(e.contains("more than 1048576 bytes"), "{e}");
}

#[test]
fn a_cut_keeps_whole_characters() {
    assert_eq!(cut("ééé", 2), "éé…");
    assert_eq!(cut("ab", 2), "ab");
}

#[test]
fn control_characters_in_paths_are_escaped_and_the_rest_kept() {
    assert_eq!(shown(Path::new("a/b c é.mcap")), "a/b c é.mcap");
    assert_eq!(shown(Path::new("x\ny\r\u{1b}[31m")), "x\\ny\\r\\u{1b}[31m");
}

/// A scene that is not UTF-8 is refused saying where and what to do (it said only "stream did not
/// contain valid UTF-8"), and a large binary file for its size, whatever its first bytes (its UTF-8
/// error came first).
#[test]
fn a_scene_that_is_not_utf8_is_refused_saying_where_and_a_large_one_for_its_size() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("s.toml");
    std::fs::write(&path, b"description = \"ok\"\n# caf\xe9\n").unwrap();
    let e = read_toml(&path, InputKind::Scene).unwrap_err().to_string();
    assert!(
        e.contains("byte 0xe9 at line 2, column 6") && e.contains("save it as UTF-8"),
        "{e}"
    );
    let mut binary = vec![0xff_u8; 2 << 20];
    binary[0] = b'#';
    std::fs::write(&path, &binary).unwrap();
    let e = read_toml(&path, InputKind::Scene).unwrap_err().to_string();
    assert!(e.contains("more than 1048576 bytes"), "{e}");
    // Negative control: UTF-8 text (a BOM and a non-ASCII description included) reads.
    std::fs::write(&path, "\u{feff}description = \"café\"\n").unwrap();
    assert!(read_toml(&path, InputKind::Scene).unwrap().contains("café"));
}

/// A recording given where a scene is read (`record rec.mcap`, `analyse rec.mcap`) is named as one, with
/// the command that gets its scene: it said "not UTF-8 … save it as UTF-8 (iconv -f latin1)", or for a
/// recording over 1 MiB that it was too large.
#[test]
fn a_recording_given_as_a_scene_is_named_as_one() {
    let dir = tempfile::tempdir().unwrap();
    let recording = crate::support::repo().join("datasets/wobble.mcap");
    let small = dir.path().join("small.mcap");
    let bytes = std::fs::read(&recording).unwrap();
    std::fs::write(&small, &bytes[..4096]).unwrap();
    for path in [recording.as_path(), small.as_path()] {
        let e = read_toml(path, InputKind::Scene).unwrap_err().to_string();
        assert!(
            e.starts_with("is an MCAP recording, not a scene file: `coin-log info --scene FILE"),
            "{e}"
        );
        let e = read_toml(path, InputKind::Sweep).unwrap_err().to_string();
        assert_eq!(e, "is an MCAP recording, not a sweep file");
    }
    let out = coin_log(dir.path(), &["record", "small.mcap"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("`small.mcap`: is an MCAP recording, not a scene file"),
        "{stderr}"
    );
    assert_eq!(listing(dir.path()), ["small.mcap"], "nothing written");
}

/// `OutputFolder::check` refuses what `create` and `file` would, creating nothing: `analyse map` checks
/// with it before its work, so that a signal during the work leaves nothing (creating the outputs first
/// left two empty `.coin-log-*.tmp` files and the folder on SIGTERM).
#[test]
fn an_output_folder_is_checked_without_creating_anything() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    OutputFolder::check(&d.join("new/sub"), true, &["a.csv", "b.svg"]).unwrap();
    assert_eq!(listing(d), Vec::<String>::new(), "nothing created");
    std::fs::create_dir(d.join("out")).unwrap();
    std::os::unix::fs::symlink("/etc/passwd", d.join("out/b.svg")).unwrap();
    let e = OutputFolder::check(&d.join("out"), true, &["a.csv", "b.svg"])
        .unwrap_err()
        .to_string();
    assert!(e.contains("b.svg` is a symbolic link"), "{e}");
    std::fs::write(d.join("out/a.csv"), "old").unwrap();
    let e = OutputFolder::check(&d.join("out"), false, &["a.csv"])
        .unwrap_err()
        .to_string();
    assert!(e.contains("already exists"), "{e}");
    std::fs::write(d.join("plain"), "x").unwrap();
    let e = OutputFolder::check(&d.join("plain/sub"), true, &["a.csv"])
        .unwrap_err()
        .to_string();
    assert!(e.contains("plain` is not a folder, so"), "{e}");
    assert_eq!(listing(&d.join("out")), ["a.csv", "b.svg"], "nothing added");
}

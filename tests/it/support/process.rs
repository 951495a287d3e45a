//! Child processes with a deadline: their output read as it comes (so a child that fills a pipe cannot
//! stall), their exit waited for until a deadline, after which the child is killed and the test fails
//! with what it printed. The deadlines are hang detectors, generous, never speed tests.
// Helpers outside #[test] functions: a failed unwrap is a failed test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::io::{BufRead, BufReader, Read};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::mpsc::{channel, Receiver, Sender};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// A started child process; dropping it kills the child if it still runs.
pub struct Process {
    child: Child,
    /// The command line, for messages.
    command: String,
    stdout: Arc<Mutex<String>>,
    stderr: Arc<Mutex<String>>,
    readers: Vec<JoinHandle<()>>,
}

/// How a child process ended and what it printed.
#[derive(Debug)]
pub struct Finished {
    pub status: ExitStatus,
    pub stdout: String,
    pub stderr: String,
}

impl Finished {
    /// The exit code, −1 if a signal ended the process.
    pub fn code(&self) -> i32 {
        self.status.code().unwrap_or(-1)
    }
}

/// Reads `pipe` line by line into `text` (and each line to `lines`) until it closes.
fn read_lines(
    pipe: impl Read + Send + 'static,
    text: &Arc<Mutex<String>>,
    lines: Option<Sender<String>>,
) -> JoinHandle<()> {
    let text = Arc::clone(text);
    std::thread::spawn(move || {
        let mut pipe = BufReader::new(pipe);
        let mut line = Vec::new();
        while pipe.read_until(b'\n', &mut line).unwrap_or(0) > 0 {
            let s = String::from_utf8_lossy(&line);
            text.lock().unwrap().push_str(&s);
            if let Some(lines) = &lines {
                let _ = lines.send(s.trim_end_matches('\n').to_string());
            }
            line.clear();
        }
    })
}

impl Process {
    /// Starts `command` with its standard output and error piped.
    pub fn start(command: &mut Command) -> Self {
        Self::spawn(command, None, "")
    }

    /// Starts `command` like [`Process::start`]; its standard error also comes line by line on the receiver.
    #[cfg_attr(not(feature = "live"), allow(dead_code, reason = "live.rs's"))]
    pub fn start_with_stderr_lines(command: &mut Command) -> (Self, Receiver<String>) {
        let (tx, rx) = channel();
        (Self::spawn(command, Some(tx), ""), rx)
    }

    /// `hint` follows the error if the program cannot start (what to install).
    fn spawn(command: &mut Command, lines: Option<Sender<String>>, hint: &str) -> Self {
        let words: Vec<String> = std::iter::once(command.get_program())
            .chain(command.get_args())
            .map(|w| w.to_string_lossy().into_owned())
            .collect();
        let command_line = words.join(" ");
        let mut child = command
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap_or_else(|e| panic!("cannot start `{command_line}`: {e}{hint}"));
        let (stdout, stderr) = Default::default();
        let readers = vec![
            read_lines(child.stdout.take().unwrap(), &stdout, None),
            read_lines(child.stderr.take().unwrap(), &stderr, lines),
        ];
        Self {
            child,
            command: command_line,
            stdout,
            stderr,
            readers,
        }
    }

    /// The child's process id (to send it a signal).
    pub fn id(&self) -> u32 {
        self.child.id()
    }

    /// What the child has written to its standard error so far.
    pub fn stderr(&self) -> String {
        self.stderr.lock().unwrap().clone()
    }

    /// Waits for the child to exit and for its output; kills it and fails the test, with what it printed,
    /// if it still runs after `deadline`.
    pub fn wait_within(&mut self, deadline: Duration) -> Finished {
        self.wait_or_kill(deadline).unwrap_or_else(|| {
            panic!(
                "`{}` still ran after {deadline:?}: it hangs\nstdout:\n{}\nstderr:\n{}",
                self.command,
                self.stdout.lock().unwrap(),
                self.stderr()
            )
        })
    }

    /// Waits for the child to exit and for its output; `None` if it still ran after `deadline`, and was
    /// killed.
    fn wait_or_kill(&mut self, deadline: Duration) -> Option<Finished> {
        let start = Instant::now();
        let status = loop {
            if let Some(status) = self.child.try_wait().unwrap() {
                break status;
            }
            if start.elapsed() > deadline {
                let _ = self.child.kill();
                let _ = self.child.wait();
                // A grandchild may hold the pipes open: what came within a second.
                let end = Instant::now() + Duration::from_secs(1);
                while self.readers.iter().any(|r| !r.is_finished()) && Instant::now() < end {
                    std::thread::sleep(Duration::from_millis(5));
                }
                return None;
            }
            std::thread::sleep(Duration::from_millis(5));
        };
        for reader in self.readers.drain(..) {
            reader.join().unwrap();
        }
        Some(Finished {
            status,
            stdout: self.stdout.lock().unwrap().clone(),
            stderr: self.stderr(),
        })
    }
}

impl Drop for Process {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Runs `command` to its end within `deadline` (see [`Process::wait_within`]).
pub fn run_within(command: &mut Command, deadline: Duration) -> Finished {
    Process::start(command).wait_within(deadline)
}

/// How long an external tool (Python, Node, Rerun) may run: its heaviest call takes under a minute on a
/// loaded 2-core machine.
const TOOL_DEADLINE: Duration = Duration::from_secs(300);

/// An external tool started, to be finished by [`Tool::finish`].
pub struct Tool<'a> {
    command: &'a mut Command,
    process: Process,
}

impl<'a> Tool<'a> {
    /// Starts `command`; `hint` (e.g. "run scripts/test") follows the error if it cannot start.
    pub fn start(command: &'a mut Command, hint: &str) -> Self {
        let process = Process::spawn(command, None, &format!(": {hint}"));
        Self { command, process }
    }

    /// Waits for the tool. One still running after [`TOOL_DEADLINE`] is killed and run once more:
    /// Node 20 can hang in its own shutdown after its work is done (nodejs/node#64274; CI saw
    /// `rewrite.mjs` sit in futex waits for ten minutes once). A second hang fails the test.
    pub fn finish(self) -> Finished {
        self.finish_within(TOOL_DEADLINE)
    }

    fn finish_within(mut self, deadline: Duration) -> Finished {
        if let Some(done) = self.process.wait_or_kill(deadline) {
            return done;
        }
        eprintln!(
            "`{}` still ran after {deadline:?}: killed, running it once more",
            self.process.command
        );
        run_within(self.command, deadline)
    }
}

/// Runs an external tool to its end (see [`Tool::finish`]).
#[cfg_attr(
    not(feature = "external-readers"),
    allow(dead_code, reason = "the external readers' tests'")
)]
pub fn run_tool(command: &mut Command, hint: &str) -> Finished {
    Tool::start(command, hint).finish()
}

/// The negative control: a child still running at its deadline is killed at once, and the test fails
/// with what it printed.
#[test]
fn a_child_past_its_deadline_is_killed_and_fails_with_what_it_printed() {
    let start = Instant::now();
    let failed = std::panic::catch_unwind(|| {
        run_within(
            Command::new("sh").args(["-c", "echo started; sleep 30"]),
            Duration::from_millis(300),
        )
    });
    let message = *failed.unwrap_err().downcast::<String>().unwrap();
    println!("after {:?}: {message}", start.elapsed());
    assert!(
        message.contains("still ran after 300ms: it hangs"),
        "{message}"
    );
    assert!(message.contains("stdout:\nstarted\n"), "{message}");
    assert!(start.elapsed() < Duration::from_secs(10));
    let done = run_within(
        Command::new("sh").args(["-c", "echo out; echo err >&2; exit 3"]),
        Duration::from_secs(20),
    );
    assert_eq!(
        (done.code(), &*done.stdout, &*done.stderr),
        (3, "out\n", "err\n")
    );
}

/// A tool that hangs once is run again and its second run counts; one that hangs twice fails the test.
#[test]
fn a_tool_that_hangs_once_runs_again_and_one_that_hangs_twice_fails() {
    let dir = tempfile::tempdir().unwrap();
    let mark = dir.path().join("ran");
    let script = format!(
        "if [ -e {0} ]; then echo second; else touch {0}; exec sleep 30; fi",
        mark.display()
    );
    let mut once = Command::new("sh");
    once.args(["-c", &script]);
    let done = Tool::start(&mut once, "").finish_within(Duration::from_millis(500));
    assert!(done.status.success());
    assert_eq!(done.stdout, "second\n");
    let failed = std::panic::catch_unwind(|| {
        Tool::start(Command::new("sleep").arg("30"), "").finish_within(Duration::from_millis(300))
    });
    let message = *failed.unwrap_err().downcast::<String>().unwrap();
    assert!(
        message.contains("still ran after 300ms: it hangs"),
        "{message}"
    );
    let missing = std::panic::catch_unwind(|| {
        Tool::start(&mut Command::new("/nonexistent/tool"), "install it").finish()
    });
    let message = *missing.unwrap_err().downcast::<String>().unwrap();
    assert!(message.ends_with(": install it"), "{message}");
}

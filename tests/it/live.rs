//! `coin-log live` (format.md: live) seen by a WebSocket client on loopback, as a viewer sees it: the server
//! info, every channel advertised with the schema and encodings the file gets, messages byte for byte the
//! file's in time order from the first sample to the last, the pace (simulated time / speed), a clean end
//! (Ctrl-C after the run: exit 0; during the run: the file finished and marked interrupted, exit 130), and
//! bad input refused with exit 2 before anything is written. The client speaks the Foxglove WebSocket
//! protocol (subprotocol `foxglove.sdk.v1`) with tungstenite, the WebSocket crate the server is built on.
// Helpers outside #[test] functions: a failed unwrap is a failed test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use super::support::process::Process;
use super::support::record::{exe, read_back, ReadBack};
use serde_json::{json, Value};
use std::collections::BTreeMap;
use std::net::TcpStream;
use std::path::Path;
use std::process::Command;
use std::sync::mpsc::Receiver;
use std::time::{Duration, Instant};
use tungstenite::client::IntoClientRequest;
use tungstenite::http::HeaderValue;
use tungstenite::{Message, WebSocket};

/// A hang detector for every wait below (the runs of these tests take about a second): never a speed test.
const DEADLINE: Duration = Duration::from_secs(60);

/// A running `coin-log live` with its stderr lines as they come.
struct LiveProcess {
    process: Process,
    lines: Receiver<String>,
}

impl LiveProcess {
    fn start(dir: &Path, args: &[&str]) -> Self {
        let (process, lines) = Process::start_with_stderr_lines(
            Command::new(exe()).arg("live").args(args).current_dir(dir),
        );
        Self { process, lines }
    }

    /// Waits for a stderr line containing `needle`; returns it.
    fn wait_for(&self, needle: &str) -> String {
        let start = Instant::now();
        while start.elapsed() < DEADLINE {
            match self.lines.recv_timeout(Duration::from_millis(100)) {
                Ok(line) if line.contains(needle) => return line,
                _ => {}
            }
        }
        panic!(
            "no stderr line with `{needle}` within {DEADLINE:?}; stderr:\n{}",
            self.stderr()
        );
    }

    /// The URL printed on the `serving … ws://…` line.
    fn url(&self) -> String {
        let line = self.wait_for("serving");
        line.split_whitespace()
            .find(|w| w.starts_with("ws://"))
            .unwrap_or_else(|| panic!("no ws:// URL in `{line}`"))
            .to_string()
    }

    fn stderr(&self) -> String {
        self.process.stderr()
    }

    /// Sends `signal` (INT, TERM) and waits for the exit code and stdout.
    fn signal_and_wait(&mut self, signal: &str) -> (i32, String) {
        let status = Command::new("kill")
            .arg(format!("-{signal}"))
            .arg(self.process.id().to_string())
            .status()
            .expect("kill runs");
        assert!(status.success(), "kill -{signal} failed");
        let out = self.process.wait_within(DEADLINE);
        (out.code(), out.stdout)
    }
}

/// Opens a WebSocket to `url` offering `subprotocol`, with reads that time out so the client can idle.
fn connect(url: &str, subprotocol: &str) -> Result<WebSocket<TcpStream>, String> {
    let mut request = url.into_client_request().map_err(|e| e.to_string())?;
    request.headers_mut().insert(
        "Sec-WebSocket-Protocol",
        HeaderValue::from_str(subprotocol).unwrap(),
    );
    let address = url.trim_start_matches("ws://");
    let stream = TcpStream::connect(address).map_err(|e| e.to_string())?;
    stream
        .set_read_timeout(Some(Duration::from_millis(50)))
        .unwrap();
    tungstenite::client(request, stream)
        .map(|(ws, _)| ws)
        .map_err(|e| e.to_string())
}

/// An advertised channel.
#[derive(Debug, Clone)]
struct Advertised {
    topic: String,
    encoding: String,
    schema_name: String,
    schema_encoding: String,
    schema: String,
}

/// What the client saw: server info, channels, and per topic the messages (log time, bytes) in arrival order.
#[derive(Debug, Default)]
struct Seen {
    server_info: Value,
    channels: BTreeMap<u64, Advertised>,
    subscriptions: BTreeMap<u32, u64>,
    messages: BTreeMap<String, Vec<(u64, Vec<u8>)>>,
    times: Vec<u64>,
    /// The server's status messages (e.g. "Unknown channel ID" for a refused subscription).
    statuses: Vec<Value>,
}

impl Seen {
    /// Handles one frame: records it and subscribes to every newly advertised channel, as a viewer does.
    fn take(&mut self, ws: &mut WebSocket<TcpStream>, message: Message) {
        match message {
            Message::Text(text) => {
                let v: Value = serde_json::from_str(text.as_str()).unwrap();
                match v["op"].as_str() {
                    Some("serverInfo") => self.server_info = v,
                    Some("advertise") => self.advertise(ws, &v),
                    Some("status") => self.statuses.push(v),
                    _ => {}
                }
            }
            Message::Binary(bytes) => self.binary(&bytes),
            _ => {}
        }
    }

    fn advertise(&mut self, ws: &mut WebSocket<TcpStream>, v: &Value) {
        let mut subscriptions = Vec::new();
        for c in v["channels"].as_array().unwrap() {
            let id = c["id"].as_u64().unwrap();
            let text = |k: &str| c[k].as_str().unwrap_or_default().to_string();
            self.channels.insert(
                id,
                Advertised {
                    topic: text("topic"),
                    encoding: text("encoding"),
                    schema_name: text("schemaName"),
                    schema_encoding: text("schemaEncoding"),
                    schema: text("schema"),
                },
            );
            let sub = u32::try_from(self.subscriptions.len()).unwrap() + 1;
            self.subscriptions.insert(sub, id);
            subscriptions.push(json!({"id": sub, "channelId": id}));
        }
        let request = json!({"op": "subscribe", "subscriptions": subscriptions});
        ws.send(Message::Text(request.to_string().into())).unwrap();
    }

    /// Binary frames: 0x01 message data (u32 subscription, u64 log time, payload), 0x02 time (u64).
    fn binary(&mut self, b: &[u8]) {
        match b.first() {
            Some(1) => {
                let sub = u32::from_le_bytes(b[1..5].try_into().unwrap());
                let time = u64::from_le_bytes(b[5..13].try_into().unwrap());
                let topic = self.channels[&self.subscriptions[&sub]].topic.clone();
                self.messages
                    .entry(topic)
                    .or_default()
                    .push((time, b[13..].to_vec()));
            }
            Some(2) => self
                .times
                .push(u64::from_le_bytes(b[1..9].try_into().unwrap())),
            _ => {}
        }
    }
}

/// Reads frames until `done` says so (checked while idle) or the deadline.
fn read_until(ws: &mut WebSocket<TcpStream>, seen: &mut Seen, mut done: impl FnMut(&Seen) -> bool) {
    let start = Instant::now();
    while start.elapsed() < DEADLINE {
        match ws.read() {
            Ok(m) => seen.take(ws, m),
            Err(tungstenite::Error::Io(e))
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                ) =>
            {
                if done(seen) {
                    return;
                }
            }
            Err(e) => panic!("the WebSocket failed: {e}"),
        }
    }
    panic!("the client did not get everything within {DEADLINE:?}");
}

/// Every disagreement between what the viewer got and the file: channels (topic set, schema name, schema
/// encoding and bytes, message encoding) and messages. Per topic the received messages, with the latch's
/// re-sends removed, must be in time order, each byte for byte a message of the
/// file, and include the file's last one; topics the file has from its first sample (advertised before the
/// clock started) must have arrived complete: exactly the file's list.
fn disagreements(file: &ReadBack, seen: &Seen) -> Vec<String> {
    let mut problems = Vec::new();
    let advertised: BTreeMap<&str, &Advertised> = seen
        .channels
        .values()
        .map(|a| (a.topic.as_str(), a))
        .collect();
    // Every topic of the recorded channels is advertised before the run (`LiveTap::announce_topics`), so
    // the served topics are the file's and those the run had no message for (higher track levels).
    let file_topics = file.topics();
    let served: Vec<String> = advertised.keys().map(|t| (*t).to_string()).collect();
    let missing: Vec<&String> = file_topics.iter().filter(|t| !served.contains(t)).collect();
    if !missing.is_empty() {
        problems.push(format!("topics {missing:?} of the file were not served"));
    }
    for extra in served.iter().filter(|t| !file_topics.contains(t)) {
        if seen.messages.get(extra).is_some_and(|m| !m.is_empty()) {
            problems.push(format!("{extra}: served messages, the file has none"));
        }
    }
    for status in seen.statuses.iter().filter(|s| s["level"] == 2) {
        problems.push(format!("the server reported an error: {status}"));
    }
    let first_time = file.messages.iter().map(|m| m.log_time).min().unwrap_or(0);
    for channel in file.summary.channels.values() {
        let Some(a) = advertised.get(channel.topic.as_str()) else {
            continue;
        };
        let schema = channel.schema.as_ref().unwrap();
        let expected = (
            schema.name.as_str(),
            schema.encoding.as_str(),
            schema.data.to_vec(),
            channel.message_encoding.as_str(),
        );
        // The protocol sends binary schemas (protobuf) in base64, text schemas as they are.
        let schema_bytes = if a.schema_encoding == "protobuf" {
            use base64::Engine;
            base64::engine::general_purpose::STANDARD
                .decode(&a.schema)
                .unwrap_or_default()
        } else {
            a.schema.as_bytes().to_vec()
        };
        let got = (
            a.schema_name.as_str(),
            a.schema_encoding.as_str(),
            schema_bytes,
            a.encoding.as_str(),
        );
        if got != expected {
            problems.push(format!(
                "{}: served (schema name, schema encoding, schema, encoding) {got:?}, file {expected:?}",
                channel.topic
            ));
        }
        let in_file: Vec<(u64, &[u8])> = file
            .on_topic(&channel.topic)
            .iter()
            .map(|m| (m.log_time, m.data.as_slice()))
            .collect();
        let mut got: Vec<(u64, &[u8])> = seen
            .messages
            .get(&channel.topic)
            .map(|v| v.iter().map(|(t, d)| (*t, d.as_slice())).collect())
            .unwrap_or_default();
        // A message identical in log time and bytes to one received before is the latch's re-send.
        let mut unique = std::collections::BTreeSet::new();
        got.retain(|m| unique.insert(*m));
        problems.extend(topic_disagreements(
            &channel.topic,
            &in_file,
            &got,
            first_time,
        ));
    }
    problems
}

fn topic_disagreements(
    topic: &str,
    in_file: &[(u64, &[u8])],
    got: &[(u64, &[u8])],
    first_time: u64,
) -> Vec<String> {
    let mut problems = Vec::new();
    if let Some(w) = got.windows(2).find(|w| w[1].0 < w[0].0) {
        problems.push(format!(
            "{topic}: log time {} after {}: not in time order",
            w[1].0, w[0].0
        ));
    }
    if let Some(m) = got.iter().find(|m| !in_file.contains(m)) {
        problems.push(format!(
            "{topic}: a message at {} ns is not the file's",
            m.0
        ));
    }
    if in_file.last() != got.last() {
        problems.push(format!(
            "{topic}: last message at {:?} ns, file's last at {:?} ns",
            got.last().map(|m| m.0),
            in_file.last().map(|m| m.0)
        ));
    }
    if in_file.first().is_some_and(|m| m.0 == first_time) && got != in_file {
        problems.push(format!(
            "{topic}: {} messages served, the file has {} (first sample: all must arrive)",
            got.len(),
            in_file.len()
        ));
    }
    problems
}

#[test]
fn a_viewer_on_loopback_gets_the_files_json_channels_and_messages_in_time_order() {
    viewer_round("json");
}

#[test]
fn a_viewer_on_loopback_gets_the_files_protobuf_channels_and_messages_in_time_order() {
    viewer_round("protobuf");
}

/// The whole round: start on a free port, refuse a client without a Foxglove subprotocol, connect,
/// subscribe to everything advertised, receive until the run is over, end with Ctrl-C (exit 0), then
/// compare with the file recorded at the same time (`-o`), and check the pace from the summary.
fn viewer_round(encoding: &str) {
    let dir = tempfile::tempdir().unwrap();
    let (duration, speed) = (1.0, 4.0);
    let mut live = LiveProcess::start(
        dir.path(),
        &[
            "circle-plus",
            "--port",
            "0",
            "--speed",
            "4",
            "--duration",
            "1",
            "-o",
            "live.mcap",
            "--json",
            "--encoding",
            encoding,
        ],
    );
    let url = live.url();
    assert!(
        url.starts_with("ws://127.0.0.1:"),
        "URL {url}: not loopback"
    );
    // A client of the old protocol name only (Lichtblick before foxglove.sdk.v1) is refused at the
    // handshake; it must not start the clock either.
    let old = connect(&url, "foxglove.websocket.v1");
    assert!(
        old.is_err(),
        "a foxglove.websocket.v1-only client was accepted"
    );
    let mut ws = connect(&url, "foxglove.sdk.v1").unwrap();
    let mut seen = Seen::default();
    read_until(&mut ws, &mut seen, |_| {
        live.stderr().contains("the run is over")
    });
    // Drain what is still queued: the final messages of every topic.
    let quiet = Instant::now();
    read_until(&mut ws, &mut seen, |_| {
        quiet.elapsed() > Duration::from_millis(500)
    });
    let (code, stdout) = live.signal_and_wait("INT");
    assert_eq!(
        code,
        0,
        "Ctrl-C after the run: exit 0; stderr:\n{}",
        live.stderr()
    );
    let summary: Value =
        serde_json::from_str(stdout.trim()).unwrap_or_else(|e| panic!("{e}: {stdout}"));

    assert_eq!(seen.server_info["op"], "serverInfo");
    let capabilities = seen.server_info["capabilities"].to_string();
    assert!(capabilities.contains("time"), "capabilities {capabilities}");
    let file = read_back(&std::fs::read(dir.path().join("live.mcap")).unwrap());
    let encodings: Vec<&str> = seen
        .channels
        .values()
        .map(|a| a.encoding.as_str())
        .collect();
    assert!(
        encodings.iter().all(|e| *e == encoding),
        "served encodings {encodings:?}"
    );
    let problems = disagreements(&file, &seen);
    assert!(
        problems.is_empty(),
        "served vs file:\n{}",
        problems.join("\n")
    );
    assert!(
        seen.times.windows(2).all(|w| w[0] <= w[1]) && !seen.times.is_empty(),
        "time broadcasts not in order"
    );
    // Completeness is checked per topic above (topics of the first sample complete; a topic that first
    // appears mid-run may lose, before the viewer's subscription reaches the server, messages that its
    // latest one supersedes); here the totals, for the log.
    let received: usize = seen.messages.values().map(Vec::len).sum();
    println!(
        "{encoding}: received {received} messages, file {}",
        summary["messages"]
    );
    // Pace: the clock ran at least duration / speed (the last sample waits for its instant); the upper
    // side depends on the machine's load and is not tested.
    let clock = summary["clock_s"].as_f64().unwrap();
    let expected = duration / speed;
    assert!(
        clock >= expected - 1e-3,
        "the clock ran {clock} s, expected at least {expected} s (duration {duration} / speed {speed}, 1 ms slack for timer rounding)"
    );
}

/// Negative control of the comparison: a reordered, a changed and a missing message are each caught.
#[test]
fn the_comparison_catches_reordered_changed_and_missing_messages() {
    let a: &[u8] = b"{\"t\":0}";
    let b: &[u8] = b"{\"t\":1}";
    let c: &[u8] = b"{\"t\":2}";
    let file = [(0, a), (10, b), (20, c)];
    assert!(
        topic_disagreements("/x", &file, &file, 0).is_empty(),
        "identical lists"
    );
    let reordered = [(0, a), (20, c), (10, b)];
    let changed = [(0, a), (10, c), (20, c)];
    let missing = [(0, a), (20, c)];
    let no_last = [(0, a), (10, b)];
    for (name, got) in [
        ("reordered", &reordered[..]),
        ("changed", &changed[..]),
        ("missing", &missing[..]),
        ("no last", &no_last[..]),
    ] {
        assert!(
            !topic_disagreements("/x", &file, got, 0).is_empty(),
            "{name}: not caught"
        );
    }
    // A topic that first appears later than the first sample may miss messages, not its last.
    assert!(topic_disagreements("/x", &file, &missing, 5).is_empty());
}

/// Ctrl-C during the run finishes the file with what was recorded, marked interrupted, exit 130 (as
/// `record`); with `--no-wait` the clock runs without a viewer.
#[test]
fn ctrl_c_during_the_run_finishes_the_file_marked_interrupted() {
    let dir = tempfile::tempdir().unwrap();
    let mut live = LiveProcess::start(
        dir.path(),
        &[
            "circle-plus",
            "--port",
            "0",
            "--no-wait",
            "--duration",
            "100",
            "-o",
            "cut.mcap",
        ],
    );
    live.wait_for("running at");
    std::thread::sleep(Duration::from_millis(300));
    let (code, _) = live.signal_and_wait("INT");
    assert_eq!(code, 130, "stderr:\n{}", live.stderr());
    let file = read_back(&std::fs::read(dir.path().join("cut.mcap")).unwrap());
    let result = &file.metadata["coin-log.result"].1;
    assert_eq!(result["termination"], "interrupted", "{result:?}");
    let last = file.messages.iter().map(|m| m.log_time).max().unwrap();
    assert!(
        last < 100_000_000_000,
        "the run went to {last} ns: the pace did not hold it (speed 1, stopped after ≈0.3 s)"
    );
}

/// `circle-plus` served fast: 20 000 samples at 100 times real time.
const FAST_CIRCLE: &[&str] = &[
    "circle-plus",
    "--port",
    "0",
    "--duration",
    "20",
    "--rate",
    "1000",
    "--speed",
    "100",
];

/// A viewer of `live` that has read until it subscribed (the server advertises, the viewer subscribes to
/// every channel); the caller then stops reading from it.
fn subscribed_viewer(live: &LiveProcess) -> WebSocket<TcpStream> {
    let mut ws = connect(&live.url(), "foxglove.sdk.v1").unwrap();
    let mut seen = Seen::default();
    let start = Instant::now();
    while seen.subscriptions.is_empty() && start.elapsed() < DEADLINE {
        match ws.read() {
            Ok(m) => seen.take(&mut ws, m),
            Err(tungstenite::Error::Io(e))
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                ) => {}
            Err(e) => panic!("the WebSocket failed: {e}"),
        }
    }
    assert!(!seen.subscriptions.is_empty(), "nothing was advertised");
    ws
}

/// A viewer that subscribes and then reads nothing fills its socket, and the server's task for it blocks.
/// Before, `live --exit` then never exited once the run was over (SIGTERM only said "stopping the run"):
/// closing the server waited for that task. It now waits a bounded time.
#[test]
fn a_viewer_that_stops_reading_does_not_keep_live_exit_from_exiting() {
    let dir = tempfile::tempdir().unwrap();
    let mut live = LiveProcess::start(dir.path(), &[FAST_CIRCLE, &["--exit"]].concat());
    let ws = subscribed_viewer(&live);
    // From here the viewer reads nothing; 200 000 messages are served to it.
    let out = live.process.wait_within(Duration::from_secs(30));
    assert_eq!(out.code(), 0, "stderr:\n{}", live.stderr());
    drop(ws);
}

/// Once the run is over its file is complete: Ctrl-C closes the server, which waits up to 2 s for a viewer
/// that stopped reading, and a second Ctrl-C in that time quits. Before, that second signal said "the
/// recording is abandoned and nothing is written" and exited 130, while the file was there, finished.
#[test]
fn a_second_ctrl_c_after_the_run_abandons_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let mut live = LiveProcess::start(dir.path(), &[FAST_CIRCLE, &["-o", "done.mcap"]].concat());
    let ws = subscribed_viewer(&live);
    // From here the viewer reads nothing, so closing the server waits for it.
    live.wait_for("still serving its final state");
    let kill = |live: &LiveProcess| {
        Command::new("kill")
            .args(["-INT", &live.process.id().to_string()])
            .status()
            .unwrap()
    };
    assert!(kill(&live).success());
    live.wait_for("stopping the server");
    assert!(
        kill(&live).success(),
        "live exited before the second signal"
    );
    let out = live.process.wait_within(DEADLINE);
    let stderr = live.stderr();
    assert_eq!(out.code(), 0, "stderr:\n{stderr}");
    assert!(
        stderr.contains("stopped again: quitting at once"),
        "{stderr}"
    );
    assert!(!stderr.contains("nothing is written"), "{stderr}");
    let file = read_back(&std::fs::read(dir.path().join("done.mcap")).unwrap());
    assert_eq!(
        file.metadata["coin-log.result"].1["termination"], "completed",
        "stderr:\n{stderr}"
    );
    drop(ws);
}

/// An output that cannot be written is refused before a viewer is invited to connect, and a speed is
/// printed in a few digits: before, `-o existing.mcap` printed "serving … open it in Foxglove" and then
/// refused, and `--speed 1e300` printed 301 digits.
#[test]
fn a_refused_output_is_named_before_serving_and_the_speed_is_short() {
    let dir = tempfile::tempdir().unwrap();
    let kept = dir.path().join("kept.mcap");
    std::fs::write(&kept, b"mine").unwrap();
    let live = ["live", "circle-plus", "--port", "0", "--no-wait", "--exit"];
    let (code, _, err) = super::support::record::coin_log_text(
        &[
            &live[..],
            &["--duration", "1", "-o", kept.to_str().unwrap()],
        ]
        .concat(),
    );
    assert_ne!(code, 0, "{err}");
    assert!(err.contains("already exists"), "{err}");
    assert!(!err.contains("serving"), "{err}");
    assert_eq!(std::fs::read(&kept).unwrap(), b"mine");
    let (code, out, err) = super::support::record::coin_log_text(
        &[&live[..], &["--duration", "0.1", "--speed", "1e300"]].concat(),
    );
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("running at 1e300× real time"), "{err}");
    assert!(out.contains(" at 1e300× real time"), "{out}");
}

/// Bad input is refused with exit 2 and a message naming the problem, before anything is written.
#[test]
fn bad_speed_host_or_busy_port_exit_2_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let busy = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let port = busy.local_addr().unwrap().port().to_string();
    // A broadcast or multicast host was bound, and live waited for a viewer that cannot connect.
    let cases: [(&[&str], &str); 9] = [
        (&["--speed", "0"], "speed"),
        (&["--speed", "-2"], "speed"),
        (&["--speed", "nan"], "speed"),
        (&["--speed", "fast"], "not a number"),
        (&["--host", "my-laptop"], "not an IP address"),
        (&["--host", "255.255.255.255"], "broadcast or multicast"),
        (&["--host", "224.0.0.1"], "broadcast or multicast"),
        (&["--host", "ff02::1"], "broadcast or multicast"),
        (&["--port", &port], "in use"),
    ];
    for (args, needle) in cases {
        let out = Command::new(exe())
            .args([
                "live",
                "circle-plus",
                "--duration",
                "1",
                "-o",
                "x.mcap",
                "--no-wait",
                "--exit",
            ])
            .args(args)
            .current_dir(dir.path())
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: stderr {stderr}");
        assert!(
            stderr.contains(needle),
            "{args:?}: `{needle}` not in {stderr}"
        );
        let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert!(left.is_empty(), "{args:?}: files left behind: {left:?}");
    }
}

/// `coin-log --help` lists `live`, and `live --help` says what exposing the server means.
#[test]
fn help_lists_live_and_says_what_host_exposes() {
    let (code, help, _) = super::support::record::coin_log_text(&["--help"]);
    assert_eq!(code, 0);
    assert!(help.contains("live"), "`live` in --help:\n{help}");
    let (code, help, _) = super::support::record::coin_log_text(&["live", "--help"]);
    assert_eq!(code, 0);
    for needle in [
        "--speed",
        "--port",
        "--host",
        "0.0.0.0",
        "anyone",
        "Open connection",
        "--no-wait",
    ] {
        assert!(help.contains(needle), "`{needle}` in live --help");
    }
}

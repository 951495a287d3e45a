//! Recordings rewritten losslessly by the MCAP project's own writers, in many layouts: the Python `mcap`
//! package (`scripts/readers/rewrite.py`) and `@mcap/core`'s McapWriter (`scripts/readers/rewrite.mjs`),
//! both installed by `scripts/test`. A missing tool fails the test (never skips it).
//!
//! The files are made once per test run (all writers run at once) in `target/tmp/other-writers/`, and
//! shared by the tests that read them.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use super::process;
use super::record::record_scene;
use super::repo;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

/// The venv's Python (`scripts/test` creates it with the pinned `mcap` package).
pub fn python() -> PathBuf {
    let p = repo().join(".venv/bin/python");
    assert!(
        p.exists(),
        "{} is missing: run scripts/test (it creates the venv with the Python `mcap` and `jsonschema` packages)",
        p.display()
    );
    p
}

/// `scripts/readers`, with its pinned npm packages installed.
pub fn node_readers() -> PathBuf {
    let dir = repo().join("scripts/readers");
    assert!(
        dir.join("node_modules/@mcap/core").exists(),
        "scripts/readers/node_modules is missing: run scripts/test (it runs `npm ci` there)"
    );
    dir
}

/// Which writer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tool {
    /// The Python `mcap` package's Writer.
    Python,
    /// `@mcap/core`'s McapWriter.
    Node,
}

/// One layout: a writer and its options.
#[derive(Debug)]
pub struct Layout {
    /// The file name (without `.mcap`).
    pub name: &'static str,
    /// The writer.
    pub tool: Tool,
    /// Options of `rewrite.py` / `rewrite.mjs`.
    pub args: &'static [&'static str],
    /// The `coin-log` metadata record comes after the first chunk (or message): the layout that hung.
    pub late: bool,
}

const SMALL: &str = "16384";

/// Lossless rewrites that must verify exactly like the original.
#[rustfmt::skip]
pub const LAYOUTS: &[Layout] = &[
    Layout { name: "py-zstd", tool: Tool::Python, args: &[], late: false },
    Layout { name: "py-zstd-small", tool: Tool::Python, args: &["--chunk-size", SMALL], late: false },
    Layout { name: "py-zstd-first", tool: Tool::Python, args: &["--chunk-size", SMALL, "--metadata", "first"], late: false },
    Layout { name: "py-zstd-last", tool: Tool::Python, args: &["--metadata", "last"], late: true },
    Layout { name: "py-zstd-small-last", tool: Tool::Python, args: &["--chunk-size", SMALL, "--metadata", "last"], late: true },
    Layout { name: "py-lz4", tool: Tool::Python, args: &["--compression", "lz4"], late: false },
    Layout { name: "py-lz4-small-last", tool: Tool::Python, args: &["--compression", "lz4", "--chunk-size", SMALL, "--metadata", "last"], late: true },
    Layout { name: "py-none", tool: Tool::Python, args: &["--compression", "none"], late: false },
    Layout { name: "py-none-small-last", tool: Tool::Python, args: &["--compression", "none", "--chunk-size", SMALL, "--metadata", "last"], late: true },
    Layout { name: "py-unchunked", tool: Tool::Python, args: &["--unchunked"], late: false },
    Layout { name: "py-unchunked-last", tool: Tool::Python, args: &["--unchunked", "--metadata", "last"], late: true },
    Layout { name: "ts-zstd", tool: Tool::Node, args: &[], late: false },
    Layout { name: "ts-zstd-small", tool: Tool::Node, args: &["--chunk-size", SMALL], late: false },
    Layout { name: "ts-zstd-last", tool: Tool::Node, args: &["--metadata", "last"], late: true },
    Layout { name: "ts-zstd-small-last", tool: Tool::Node, args: &["--chunk-size", SMALL, "--metadata", "last"], late: true },
    Layout { name: "ts-none", tool: Tool::Node, args: &["--compression", "none"], late: false },
    Layout { name: "ts-none-small-last", tool: Tool::Node, args: &["--compression", "none", "--chunk-size", SMALL, "--metadata", "last"], late: true },
];

/// Valid MCAP files that are not lossless in coin-log's layout: verify must judge the physics the same
/// and say what is missing or wrong in the structure.
#[rustfmt::skip]
pub const DEFECTIVE: &[Layout] = &[
    // No summary, no indexes (footer summary_start = 0), metadata after the chunks: found by the scan.
    Layout { name: "py-no-summary-last", tool: Tool::Python, args: &["--no-summary", "--chunk-size", SMALL, "--metadata", "last"], late: true },
    // @mcap/core 2.2 without chunks indexes a metadata record at the offset of the messages it still
    // buffers: the index is wrong, the records are found by the scan.
    Layout { name: "ts-unchunked-last", tool: Tool::Node, args: &["--unchunked", "--compression", "none", "--metadata", "last"], late: true },
];

/// The original recording and its rewrites.
#[derive(Debug)]
pub struct Rewrites {
    /// `coin-log record circle-plus --duration 6` (every check runs on it).
    pub original: PathBuf,
    /// Each layout of [`LAYOUTS`] and [`DEFECTIVE`] with its file.
    pub files: Vec<(&'static Layout, PathBuf)>,
}

impl Rewrites {
    /// The file of layout `name`.
    pub fn file(&self, name: &str) -> &Path {
        &self.files.iter().find(|(l, _)| l.name == name).unwrap().1
    }
}

/// The rewrites, made on first use.
pub fn rewrites() -> &'static Rewrites {
    static REWRITES: OnceLock<Rewrites> = OnceLock::new();
    REWRITES.get_or_init(make)
}

fn command(layout: &Layout, original: &Path, target: &Path) -> Command {
    let mut command = match layout.tool {
        Tool::Python => {
            let mut c = Command::new(python());
            c.arg(repo().join("scripts/readers/rewrite.py"));
            c
        }
        Tool::Node => {
            let mut c = Command::new("node");
            c.arg(node_readers().join("rewrite.mjs"));
            c
        }
    };
    command.arg(original).arg(target).args(layout.args);
    command
}

fn make() -> Rewrites {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("other-writers");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let original = record_scene(&dir, "circle-plus", &["--duration", "6"]);
    let mut commands: Vec<(&'static Layout, PathBuf, Command)> = LAYOUTS
        .iter()
        .chain(DEFECTIVE)
        .map(|l| {
            let path = dir.join(format!("{}.mcap", l.name));
            let command = command(l, &original, &path);
            (l, path, command)
        })
        .collect();
    let running: Vec<_> = commands
        .iter_mut()
        .map(|(l, path, command)| {
            (
                *l,
                path.clone(),
                process::Tool::start(command, "run scripts/test"),
            )
        })
        .collect();
    let files = running
        .into_iter()
        .map(|(l, path, tool)| {
            let out = tool.finish();
            assert!(
                out.status.success(),
                "rewriting as {}: {}{}",
                l.name,
                out.stdout,
                out.stderr
            );
            (l, path)
        })
        .collect();
    Rewrites { original, files }
}

//! `coin-log sweep collect DIR` (format.md: Collecting shards): the shards' catalogue parts merged into
//! the one catalogue, after checking that every run is there exactly once and that every file matches
//! its row (size and SHA-256, each file read once). Nothing is written unless every check holds.

use super::catalogue::RunStatus;
use super::error::SweepError;
use super::folder::{self, Folder};
use super::hash::sha256_file;
use crate::csv;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// Missing runs listed by number before the rest are only counted.
const LISTED_RANGES: usize = 20;

/// What collect found and wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct Collected {
    /// The sweep's runs.
    pub runs: u64,
    /// The parts read, by name.
    pub parts: Vec<String>,
    /// Rows finished.
    pub finished: u64,
    /// Rows failed.
    pub failed: u64,
    /// What is missing or wrong, one sentence each; empty when the catalogue was written.
    pub problems: Vec<String>,
    /// The catalogue and `sweep.json`, when written.
    pub written: Option<(PathBuf, PathBuf)>,
}

/// A row as found in a part.
struct Found {
    part: String,
    fields: Vec<String>,
}

/// Merges the catalogue parts in `dir`, hashing the files on `jobs` threads.
///
/// # Errors
/// [`SweepError`] when the folder holds no sweep, or a part or the catalogue cannot be read or written.
pub fn collect(dir: &std::path::Path, jobs: usize) -> Result<Collected, SweepError> {
    let folder = Folder::existing(dir)?;
    let columns = folder.columns();
    let runs = folder.runs();
    let mut parts: Vec<(super::shard::Shard, String)> = std::fs::read_dir(dir)
        .map_err(SweepError::io("reading the sweep folder", dir))?
        .flatten()
        .filter_map(|e| {
            let name = e.file_name().to_string_lossy().into_owned();
            folder::shard_of_part(&name).map(|s| (s, name))
        })
        .collect();
    parts.sort_by_key(|(s, _)| (s.count(), s.index()));
    let mut problems = Vec::new();
    if let Some(shard) = folder.held_lock(|_| true) {
        problems.push(format!(
            "shard {shard} is still running in `{}`: collect when every shard has ended",
            dir.display()
        ));
    }
    if parts.is_empty() {
        problems.push(format!(
            "no catalogue parts (catalogue.part-K-of-N.csv) in `{}`: run the shards first, `coin-log sweep SWEEP.toml -o DIR --shard K/N`",
            dir.display()
        ));
    }
    let mut rows: BTreeMap<u64, Found> = BTreeMap::new();
    for (_, name) in &parts {
        read_part(&folder, name, &columns, runs, &mut rows, &mut problems)?;
    }
    problems.extend(missing(runs, &rows));
    let at = |name: &str| columns.iter().position(|c| c == name).unwrap_or(0);
    problems.extend(check_files(
        &folder,
        &rows,
        [at("file"), at("bytes"), at("sha256")],
        jobs,
    ));
    let status_at = at("status");
    let failed = rows
        .values()
        .filter(|f| f.fields[status_at] == RunStatus::Failed.name())
        .count() as u64;
    let finished = rows.len() as u64 - failed;
    let written = if problems.is_empty() {
        let lines = rows.values().map(|f| csv::line(&f.fields));
        let catalogue = folder.write_catalogue(folder::CATALOGUE_FILE, lines)?;
        Some((catalogue, folder.write_summary(finished, failed, 0)?))
    } else {
        None
    };
    Ok(Collected {
        runs,
        parts: parts.into_iter().map(|(_, n)| n).collect(),
        finished,
        failed,
        problems,
        written,
    })
}

/// Reads one part into `rows`, noting a wrong header, unreadable lines, runs out of range and runs
/// already in another part.
fn read_part(
    folder: &Folder,
    name: &str,
    columns: &[String],
    runs: u64,
    rows: &mut BTreeMap<u64, Found>,
    problems: &mut Vec<String>,
) -> Result<(), SweepError> {
    let path = folder.file(name);
    let text = crate::files::read_regular(&path)
        .map_err(SweepError::io("reading the catalogue part", &path))?;
    let mut lines = text.lines();
    let header = lines.next().and_then(csv::split);
    if header.as_deref() != Some(columns) {
        problems.push(format!("`{name}` does not start with this sweep's header: it is not a part of this sweep; delete it"));
        return Ok(());
    }
    for (n, line) in lines.enumerate() {
        let fields = csv::split(line).filter(|f| f.len() == columns.len());
        let index = fields
            .as_ref()
            .and_then(|f| f[0].parse::<u64>().ok())
            .filter(|&i| i < runs);
        let (Some(fields), Some(index)) = (fields, index) else {
            problems.push(format!(
                "`{name}` line {}: not a row of this sweep: run its shard again",
                n + 2
            ));
            continue;
        };
        if let Some(other) = rows.get(&index) {
            problems.push(format!(
                "run {index} is in both `{}` and `{name}`: delete the parts of an earlier sharding (shards of one N make each run once)",
                other.part
            ));
            continue;
        }
        rows.insert(
            index,
            Found {
                part: name.to_string(),
                fields,
            },
        );
    }
    Ok(())
}

/// The runs no part holds, as ranges (`3, 8–12`), with how to make them.
fn missing(runs: u64, rows: &BTreeMap<u64, Found>) -> Option<String> {
    let mut ranges: Vec<(u64, u64)> = Vec::new();
    let mut count = 0u64;
    let mut expect = 0u64;
    for &index in rows.keys().chain(std::iter::once(&runs)) {
        if index > expect {
            ranges.push((expect, index - 1));
            count += index - expect;
        }
        expect = index + 1;
    }
    if count == 0 {
        return None;
    }
    let listed: Vec<String> = ranges
        .iter()
        .take(LISTED_RANGES)
        .map(|&(a, b)| {
            if a == b {
                a.to_string()
            } else {
                format!("{a}–{b}")
            }
        })
        .collect();
    let more = if ranges.len() > LISTED_RANGES {
        ", …"
    } else {
        ""
    };
    Some(format!(
        "{count} of {runs} runs are in no part: {}{more}; run the shards that hold them again (run i is in shard i mod N of N)",
        listed.join(", ")
    ))
}

/// Each row's file against its size and SHA-256, hashed on `jobs` threads.
fn check_files(
    folder: &Folder,
    rows: &BTreeMap<u64, Found>,
    [file_at, bytes_at, sha_at]: [usize; 3],
    jobs: usize,
) -> Vec<String> {
    let with_files: Vec<&Found> = rows
        .values()
        .filter(|f| !f.fields[file_at].is_empty())
        .collect();
    let next = AtomicUsize::new(0);
    let problems = Mutex::new(Vec::new());
    std::thread::scope(|scope| {
        for _ in 0..jobs.clamp(1, with_files.len().max(1)) {
            scope.spawn(|| {
                while let Some(found) = with_files.get(next.fetch_add(1, Ordering::SeqCst)) {
                    let f = &found.fields;
                    let problem = match sha256_file(&folder.file(&f[file_at])) {
                        Err(e) => Some(format!("`{}` (run {}) cannot be read: {e}", f[file_at], f[0])),
                        Ok((_, len)) if len.to_string() != f[bytes_at] => Some(format!(
                            "`{}` (run {}) has {len} bytes, its row {}: it was changed or cut; run its shard again to redo it",
                            f[file_at], f[0], f[bytes_at])),
                        Ok((sha, _)) if sha != f[sha_at] => Some(format!(
                            "`{}` (run {}) does not match its row's SHA-256: it was changed; run its shard again to redo it",
                            f[file_at], f[0])),
                        Ok(_) => None,
                    };
                    if let Some(p) = problem {
                        problems.lock().unwrap_or_else(std::sync::PoisonError::into_inner).push((f[0].parse::<u64>().unwrap_or(0), p));
                    }
                }
            });
        }
    });
    let mut problems = problems
        .into_inner()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    problems.sort();
    problems.into_iter().map(|(_, p)| p).collect()
}

//! `coin-log sweep collect DIR` (format.md: Collecting shards): the shards' catalogue parts merged into
//! the one catalogue, after checking that every run is there exactly once and that every file matches
//! its row (size and SHA-256, each file read once). Nothing is written unless every check holds.

use super::catalogue::{consistent, index_of, RunStatus};
use super::definition::Sweep;
use super::error::SweepError;
use super::folder::{self, Folder};
use super::hash::sha256_file;
use crate::csv;
use crate::files::shown_name;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

/// Missing runs listed by number before the rest are only counted.
const LISTED_RANGES: usize = 20;

/// The wrong lines of a part named one by one before the rest are only counted.
const LISTED_LINES: usize = 20;

/// What collect found and wrote: the sweep's `runs`, the `parts` read (by name), the rows `finished` and
/// `failed`.
#[derive(Debug, Clone, PartialEq)]
#[allow(missing_docs)]
pub struct Collected {
    pub runs: u64,
    pub parts: Vec<String>,
    pub finished: u64,
    pub failed: u64,
    /// What is missing or wrong, one sentence each; empty when the catalogue was written.
    pub problems: Vec<String>,
    /// The catalogue and `sweep.json`, when written.
    pub written: Option<(PathBuf, PathBuf)>,
}

/// A row as found in a part.
struct Found {
    part: String,
    line: usize,
    fields: Vec<String>,
}

/// Merges the catalogue parts in `dir`, hashing the files on `jobs` threads.
pub fn collect(dir: &std::path::Path, jobs: usize) -> Result<Collected, SweepError> {
    let folder = Folder::existing(dir)?;
    folder.check_outputs(super::Shard::ALL)?;
    let columns = folder.columns();
    let runs = folder.runs();
    let mut parts =
        (folder::PART.list(dir)).map_err(SweepError::io("reading the sweep folder", dir))?;
    parts.sort_by_key(|(s, _)| (s.count(), s.index()));
    let mut problems = Vec::new();
    // While a shard runs, its part is yet to come: advising to run the shards of the runs in no part
    // (which a second process on that shard is refused) would be premature.
    let running = folder.held_locks(|_| true);
    // Every one of them: the first alone hid the others (two arrays of 2 and 4 on one folder).
    let names: Vec<String> = running.iter().map(ToString::to_string).collect();
    if !names.is_empty() {
        let (shards, are) = if names.len() == 1 {
            ("shard", "is")
        } else {
            ("shards", "are")
        };
        problems.push(format!(
            "{shards} {} {are} still running in `{}`: collect when every shard has ended",
            names.join(", "),
            dir.display()
        ));
    }
    // A folder swept whole has no parts: the sweep wrote its catalogue itself. Running "the shards that
    // hold" its runs, as the list of missing runs advised, wrote no part either (one shard is the whole).
    if parts.is_empty() && running.is_empty() {
        let what = if folder.swept_whole() {
            "it was swept whole, not in shards, so the sweep wrote its catalogue.csv and sweep.json itself \
             (collect merges the parts of shards, --shard K/N); to bring them up to date, run `coin-log \
             sweep SWEEP.toml -o DIR` again: it resumes"
        } else {
            "run the shards first, `coin-log sweep SWEEP.toml -o DIR --shard K/N`"
        };
        problems.push(format!(
            "no catalogue parts (catalogue.part-K-of-N.csv) in `{}`: {what}",
            dir.display()
        ));
    }
    let mut rows: BTreeMap<u64, Found> = BTreeMap::new();
    let sweep = folder.sweep();
    for (_, name) in &parts {
        let part = Part {
            name,
            columns: &columns,
            runs,
            sweep: sweep.as_ref(),
            at: ["status", "failure", "file", "verify"].map(|c| folder.column(c)),
        };
        read_part(&folder, &part, &mut rows, &mut problems)?;
    }
    if !parts.is_empty() && running.is_empty() {
        problems.extend(missing(runs, &rows));
    }
    let at = ["file", "bytes", "sha256"].map(|c| folder.column(c));
    problems.extend(check_rows(&folder, sweep.as_ref(), &rows, at, jobs));
    let status_at = folder.column("status");
    let failed = rows
        .values()
        .filter(|f| f.fields[status_at] == RunStatus::Failed.name())
        .count() as u64;
    let finished = rows.len() as u64 - failed;
    let lines = rows.values().map(|f| csv::line(&f.fields));
    let written = (problems.is_empty())
        .then(|| folder.write_whole(lines, [finished, failed, 0]))
        .transpose()?;
    Ok(Collected {
        runs,
        parts: parts.into_iter().map(|(_, n)| n).collect(),
        finished,
        failed,
        problems,
        written,
    })
}

/// A part to read, and what its rows must agree with: the plan's columns, runs and sweep (`None` when the
/// plan does not give it back: then whether it verifies is not checked).
struct Part<'a> {
    name: &'a str,
    columns: &'a [String],
    runs: u64,
    sweep: Option<&'a Sweep>,
    /// The columns `status`, `failure`, `file`, `verify`.
    at: [usize; 4],
}

/// Reads one part into `rows`, noting a wrong header, unreadable lines, runs out of range, rows with
/// another run's file or none a run writes, and runs already in another part or twice in this one.
fn read_part(
    folder: &Folder,
    part: &Part,
    rows: &mut BTreeMap<u64, Found>,
    problems: &mut Vec<String>,
) -> Result<(), SweepError> {
    let Part { name, columns, .. } = *part;
    let path = folder.file(name);
    let text = match crate::files::read_regular(&path) {
        Ok(text) => text,
        // Bytes that are no UTF-8: a damaged part, or no part (the bare "stream did not contain valid
        // UTF-8" said neither, nor what to do).
        Err(e) if e.kind() == std::io::ErrorKind::InvalidData => {
            problems.push(format!(
                "`{name}` is not UTF-8 text, so not a part as a shard writes it: delete it and run its shard again"
            ));
            return Ok(());
        }
        Err(e) => return Err(SweepError::io("reading the catalogue part", &path)(e)),
    };
    let mut lines = text.lines();
    let header = lines.next().and_then(csv::split);
    if header.as_deref() != Some(columns) {
        problems.push(format!("`{name}` does not start with this sweep's header: it is not a part of this sweep; delete it"));
        return Ok(());
    }
    // What is wrong line by line, listed up to LISTED_LINES (a part of 300 000 garbage lines printed as
    // many errors); each with whether it is a run another part holds too, which running this part's
    // shard again does not mend (the part of an earlier sharding must go).
    let mut found: Vec<(bool, String)> = Vec::new();
    for (n, line) in lines.enumerate() {
        let (index, fields) = match row(folder, part, line) {
            Ok(row) => row,
            Err(problem) => {
                found.push((false, format!("`{name}` line {}: {problem}", n + 2)));
                continue;
            }
        };
        let problem = match rows.get(&index) {
            // Twice in this part: no shard writes that, and no other part is to blame.
            Some(other) if other.part == name => (false, format!(
                "`{name}` line {}: run {index}'s row is in the part twice: the part was changed; run its shard again",
                n + 2
            )),
            Some(other) => (true, format!(
                "run {index} is in both `{}` and `{name}`: delete the parts of an earlier sharding (shards of one N make each run once)",
                other.part
            )),
            None => {
                let (part, line) = (name.to_string(), n + 2);
                rows.insert(index, Found { part, line, fields });
                continue;
            }
        };
        found.push(problem);
    }
    let unlisted = found.split_off(found.len().min(LISTED_LINES));
    problems.extend(found.into_iter().map(|(_, problem)| problem));
    let elsewhere = unlisted.iter().filter(|(elsewhere, _)| *elsewhere).count();
    let wrong = unlisted.len() - elsewhere;
    let more = [
        (wrong, "lines are wrong as well: run its shard again"),
        (elsewhere, "of its runs are in another part as well: delete the parts of an earlier sharding (shards of one N make each run once)"),
    ];
    for (count, what) in more.into_iter().filter(|&(count, _)| count > 0) {
        problems.push(format!("`{name}`: {count} more {what}"));
    }
    Ok(())
}

/// A part's line as a row of this sweep: its index and fields; else what is wrong with it. A row names its
/// own run's file or none (one that names another's, an edited index, would pass the file checks with
/// another run's values), and its status, failure, file and verify cells agree as a run writes them.
fn row(folder: &Folder, part: &Part, line: &str) -> Result<(u64, Vec<String>), String> {
    let fields = csv::split(line).filter(|f| f.len() == part.columns.len());
    let index = fields.as_ref().and_then(|f| index_of(&f[0]));
    let index = index.filter(|&i| i < part.runs);
    let (Some(fields), Some(index)) = (fields, index) else {
        return Err("not a row of this sweep: run its shard again".into());
    };
    let cells = part.at.map(|at| fields[at].as_str());
    let (file, own) = (cells[2], folder.run_file_name(index));
    if !file.is_empty() && file != own {
        return Err(format!(
            "run {index}'s row names the file `{file}`, not `{own}`: the part was changed; run its shard again"
        ));
    }
    if !consistent(cells, part.sweep.map(|s| s.settings.verify)) {
        let [status, failure, file, verify] = cells.map(shown_name);
        return Err(format!(
            "run {index}'s row is none a run writes (status `{status}`, failure `{failure}`, file `{file}`, verify `{verify}`): the part was changed; run its shard again"
        ));
    }
    Ok((index, fields))
}

/// How a row's values differ from its run's in the sweep, if they do.
fn other_values(sweep: &Sweep, fields: &[String], index: u64) -> Option<String> {
    let own = sweep.cells(index);
    let cells = fields.iter().skip(1).zip(&own);
    let (key, (found, own)) = sweep.keys().zip(cells).find(|(_, (f, o))| f != o)?;
    let [key, found, own] = [key, found, own].map(shown_name);
    Some(format!(
        "run {index}'s row has {key} = `{found}`, but this sweep's run {index} has `{own}`: the part is another sweep's; delete it and run its shard again"
    ))
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

/// Each row's values against its run's in the sweep (when the plan gives it back: a part of another
/// sweep with the same keys passes every other check), and its file against its size and SHA-256, on
/// `jobs` threads (a bounded normal draw that finds no value takes a tenth of a second to recompute).
fn check_rows(
    folder: &Folder,
    sweep: Option<&Sweep>,
    rows: &BTreeMap<u64, Found>,
    [file_at, bytes_at, sha_at]: [usize; 3],
    jobs: usize,
) -> Vec<String> {
    let rows: Vec<&Found> = rows.values().collect();
    let check = |found: &&Found| {
        let f = &found.fields;
        let index = f[0].parse::<u64>().unwrap_or(0);
        if let Some(problem) = sweep.and_then(|s| other_values(s, f, index)) {
            return Some((
                index,
                format!("`{}` line {}: {problem}", found.part, found.line),
            ));
        }
        if f[file_at].is_empty() {
            return None;
        }
        let path = folder.file(&f[file_at]);
        // The size first: a file of another size is not hashed (a sparse 20 GB file under a run's name
        // took 40 s to read before its size was compared).
        let size = std::fs::metadata(&path)
            .ok()
            .filter(std::fs::Metadata::is_file);
        let hashed = match size.map(|m| m.len()) {
            Some(len) if len.to_string() != f[bytes_at] => Ok((String::new(), len)),
            _ => sha256_file(&path),
        };
        let problem = match hashed {
            Err(e) => format!("cannot be read: {e}"),
            Ok((_, len)) if len.to_string() != f[bytes_at] => format!(
                "has {len} bytes, its row {}: it was changed or cut; run its shard again to redo it",
                f[bytes_at]
            ),
            Ok((sha, _)) if sha != f[sha_at] => {
                "does not match its row's SHA-256: it was changed; run its shard again to redo it".into()
            }
            Ok(_) => return None,
        };
        Some((index, format!("`{}` (run {}) {problem}", f[file_at], f[0])))
    };
    let mut problems = Vec::new();
    let never = AtomicBool::new(false);
    let check_at = |i: u64| rows.get(usize::try_from(i).ok()?).and_then(check);
    let len = rows.len() as u64;
    super::on_threads(len, jobs, &never, check_at, |b| problems.extend(b));
    problems.sort();
    problems.into_iter().map(|(_, p)| p).collect()
}

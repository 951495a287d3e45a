//! The sweep's folder (format.md: The sweep folder): the run files, the catalogue (or its parts), the
//! sweep's JSON, and the private state in `.coin-log-sweep/`: the plan (written once) and one append-only
//! journal per shard, synced as the runs end, so that a crash loses at most the runs in progress.

use super::catalogue;
use super::definition::Sweep;
use super::error::SweepError;
use super::random;
use super::shard::Shard;
use crate::csv;
use crate::files;
use std::fs::{self, File, OpenOptions};
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::time::UNIX_EPOCH;

const STATE_DIR: &str = ".coin-log-sweep";
/// The plan, in the state folder: the sweep as resolved and its identity.
const PLAN_FILE: &str = "plan.json";
const CATALOGUE_FILE: &str = "catalogue.csv";
/// The whole sweep's JSON: the plan and the counts.
const SWEEP_JSON_FILE: &str = "sweep.json";
/// What `format` says in the plan and `sweep.json`.
const FORMAT_NAME: &str = "coin-log sweep";
/// The version of the sweep folder's layout (format.md: The sweep folder).
const FORMAT_VERSION: &str = "1";
/// The journal's first column, before the catalogue's: the file's modification time when its row was
/// written, nanoseconds since 1970 (0 without a file).
const MTIME_COLUMN: &str = "mtime_ns";

/// `run-<index>.mcap`, the index zero-padded to `width` digits.
fn run_file_name(index: u64, width: usize) -> String {
    format!("run-{index:0width$}.mcap")
}

/// The name of a file that each shard has its own of: `<prefix>K-of-N<suffix>`.
pub struct ShardFile {
    prefix: &'static str,
    suffix: &'static str,
}

/// A shard's catalogue, in the folder.
pub const PART: ShardFile = ShardFile {
    prefix: "catalogue.part-",
    suffix: ".csv",
};
/// A shard's journal, in the state folder.
const JOURNAL: ShardFile = ShardFile {
    prefix: "journal-",
    suffix: ".csv",
};
/// A shard's lock, in the state folder.
const LOCK: ShardFile = ShardFile {
    prefix: "lock-",
    suffix: "",
};

impl ShardFile {
    pub fn name(&self, shard: Shard) -> String {
        let (k, n) = (shard.index(), shard.count());
        format!("{}{k}-of-{n}{}", self.prefix, self.suffix)
    }

    fn shard_of(&self, name: &str) -> Option<Shard> {
        let rest = name.strip_prefix(self.prefix)?.strip_suffix(self.suffix)?;
        let (k, n) = rest.split_once("-of-")?;
        Shard::new(k.parse().ok()?, n.parse().ok()?).ok()
    }

    /// The files of this kind in `dir`, with their shards, sorted by name.
    pub fn list(&self, dir: &Path) -> io::Result<Vec<(Shard, String)>> {
        let mut found: Vec<(Shard, String)> = fs::read_dir(dir)?
            .flatten()
            .filter_map(|e| {
                let name = e.file_name().into_string().ok()?;
                Some((self.shard_of(&name)?, name))
            })
            .collect();
        found.sort_by(|a, b| a.1.cmp(&b.1));
        Ok(found)
    }
}

/// A shard's lock (an advisory `flock` on `.coin-log-sweep/lock-K-of-N`), held while a process makes
/// the shard's runs; the system releases it when the process ends, however it ends.
#[derive(Debug)]
pub struct ShardLock {
    _file: Option<File>,
}

/// The plan: the sweep as resolved, its identity, and what `collect` needs (runs, columns, file names).
fn plan_json(sweep: &Sweep) -> serde_json::Value {
    serde_json::json!({
        "format": FORMAT_NAME,
        "format_version": FORMAT_VERSION,
        "tool_version": env!("CARGO_PKG_VERSION"),
        "identity": sweep.identity(),
        "runs": sweep.runs(),
        "keys": sweep.keys().collect::<Vec<_>>(),
        "columns": catalogue::columns(sweep.keys()),
        "index_width": sweep.index_width(),
        "sweep": sweep.description_json(),
    })
}

/// A sweep folder, open, and the plan it holds.
#[derive(Debug, Clone)]
pub struct Folder {
    path: PathBuf,
    plan: serde_json::Value,
}

/// The size and modification time (ns since 1970, 0 when the system gives none) of a file, if it is there.
pub fn size_and_mtime(path: &Path) -> Option<(u64, u128)> {
    let meta = fs::metadata(path).ok()?;
    let since = meta
        .modified()
        .ok()
        .and_then(|t| t.duration_since(UNIX_EPOCH).ok());
    Some((meta.len(), since.map_or(0, |d| d.as_nanos())))
}

impl Folder {
    /// Opens `path` for `sweep`: creates it if missing; otherwise it must be empty or hold this same
    /// sweep (same identity, same tool version). Several shards may open one folder at once.
    pub fn open(path: &Path, sweep: &Sweep) -> Result<Self, SweepError> {
        let folder_error = SweepError::folder(path);
        if path.exists() && !path.is_dir() {
            return Err(folder_error(
                "is not a folder: give -o a folder for the sweep's files".into(),
            ));
        }
        // The folder and its missing parents: a link to nothing or a file among them would make
        // creating it fail with a bare "File exists" or "Not a directory".
        let mut missing = path.ancestors().filter(|d| !d.as_os_str().is_empty());
        let in_the_way = missing.find_map(|d| {
            let why = match fs::metadata(d) {
                Ok(m) if m.is_dir() => return Some(None),
                Ok(_) => "is not a folder; give -o a folder for the sweep's files".to_string(),
                Err(_) => format!(
                    "is a symbolic link to `{}`, which does not exist: create that folder, or give -o another",
                    files::dangling_link(d)?.display()
                ),
            };
            Some(Some(if d == path {
                why
            } else {
                format!("cannot be created: `{}` {why}", d.display())
            }))
        });
        if let Some(reason) = in_the_way.flatten() {
            return Err(folder_error(reason));
        }
        refuse_attribute(path, path)?;
        fs::create_dir_all(path).map_err(SweepError::io("creating the sweep folder", path))?;
        let state = path.join(STATE_DIR);
        // Not `is_dir`, which follows a link: the state would be written wherever it points.
        let state_kind = fs::symlink_metadata(&state).map(|m| m.file_type());
        if state_kind.as_ref().is_ok_and(|t| !t.is_dir()) {
            return Err(folder_error(format!(
                "holds `{STATE_DIR}` as a {}, not the folder a sweep keeps its state in: it is no sweep's \
                 folder; give -o a new or empty folder",
                if state_kind.is_ok_and(|t| t.is_symlink()) { "symbolic link" } else { "file" }
            )));
        }
        let plan_path = state.join(PLAN_FILE);
        let not_empty = |name: String| {
            folder_error(format!(
                "is not empty and holds no sweep (it has `{name}`): give -o a new or empty folder"
            ))
        };
        if state_kind.is_err() {
            let entries =
                fs::read_dir(path).map_err(SweepError::io("reading the sweep folder", path))?;
            if let Some(other) = entries.flatten().find(|e| e.file_name() != STATE_DIR) {
                return Err(not_empty(other.file_name().to_string_lossy().into_owned()));
            }
            fs::create_dir_all(&state)
                .map_err(SweepError::io("creating the sweep's state folder", &state))?;
        } else if fs::symlink_metadata(&plan_path).is_err() {
            // A state folder without a plan is left only by a process stopped before it published the
            // plan, and then holds nothing else (but the plan's temporary file). Anything more was not
            // made by a sweep (a journal or run files of a folder whose plan was deleted, the user's
            // own files), and the sweep would append to it and move its files over them. Another
            // process may have published the plan (and started its runs) since: then it is a sweep's.
            if let Some(other) = foreign_entry(path, &state) {
                if fs::symlink_metadata(&plan_path).is_err() {
                    return Err(not_empty(other));
                }
            }
        }
        let plan = plan_json(sweep);
        // A plan in place is read, not written again: publishing writes a temporary file first, which
        // on a full disk failed as "writing the sweep's plan" when the plan was there all along.
        let published = if fs::symlink_metadata(&plan_path).is_ok() {
            Err(io::ErrorKind::AlreadyExists.into())
        } else {
            publish_new(&plan_path, format!("{plan}\n").as_bytes())
        };
        match published {
            Ok(()) => {}
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => {
                let held = read_plan(&plan_path)?;
                check_same(path, &held, &plan)?;
            }
            Err(e) => return Err(SweepError::io("writing the sweep's plan", &plan_path)(e)),
        }
        Ok(Self {
            path: path.to_path_buf(),
            plan,
        })
    }

    /// Opens a folder that holds a sweep, for `collect`.
    pub fn existing(path: &Path) -> Result<Self, SweepError> {
        let plan_path = path.join(STATE_DIR).join(PLAN_FILE);
        if !plan_path.is_file() {
            return Err(SweepError::folder(path)(format!(
                "holds no sweep (no {STATE_DIR}/{PLAN_FILE}): give the folder a sweep was run into"
            )));
        }
        Ok(Self {
            path: path.to_path_buf(),
            plan: read_plan(&plan_path)?,
        })
    }

    /// The sweep the plan describes, if it gives it back ([`Sweep::from_plan`]).
    pub fn sweep(&self) -> Option<Sweep> {
        Sweep::from_plan(&self.plan)
    }

    fn state(&self) -> PathBuf {
        self.path.join(STATE_DIR)
    }

    pub fn file(&self, name: &str) -> PathBuf {
        self.path.join(name)
    }

    pub fn runs(&self) -> u64 {
        self.plan["runs"].as_u64().unwrap_or(0)
    }

    /// The name of run `index`'s file in this sweep (`run-007.mcap`), as the plan's `index_width` pads it.
    pub fn run_file_name(&self, index: u64) -> String {
        let width = self.plan["index_width"].as_u64().unwrap_or(1);
        run_file_name(index, usize::try_from(width).unwrap_or(1))
    }

    /// Whether the whole sweep (no `--shard`, or 1 shard) was run in this folder: it has that journal.
    pub fn swept_whole(&self) -> bool {
        let journal = self.state().join(JOURNAL.name(Shard::ALL));
        fs::symlink_metadata(journal).is_ok()
    }

    /// The catalogue's columns in the plan.
    pub fn columns(&self) -> Vec<String> {
        let columns = self.plan["columns"].as_array().into_iter().flatten();
        columns
            .filter_map(|c| c.as_str().map(str::to_string))
            .collect()
    }

    /// The position of the catalogue's column `name`.
    pub fn column(&self, name: &str) -> usize {
        self.columns().iter().position(|c| c == name).unwrap_or(0)
    }

    /// Takes `shard`'s lock, so that no two processes make a run at once (the second would also delete
    /// the first's temporary files as stale). Refused while another process holds the lock of this shard
    /// or of one whose runs overlap it (`sweep` without `--shard` and shard 1/4, say). On a file system
    /// without locks, runs unlocked.
    pub fn lock(&self, shard: Shard) -> Result<ShardLock, SweepError> {
        let path = self.state().join(LOCK.name(shard));
        let file = open_append(&path).map_err(SweepError::io("opening the shard's lock", &path))?;
        // A process looking whether the lock is held (below, or `collect`) holds it shared for a moment:
        // try again before calling the shard busy.
        for attempt in 1.. {
            match file.try_lock() {
                Ok(()) => break,
                Err(fs::TryLockError::WouldBlock) if attempt < 5 => {
                    std::thread::sleep(std::time::Duration::from_millis(20));
                }
                Err(fs::TryLockError::WouldBlock) => return Err(self.busy(shard, shard)),
                Err(fs::TryLockError::Error(_)) => return Ok(ShardLock { _file: None }),
            }
        }
        let others = self.held_locks(|other| other != shard && other.overlaps(shard));
        if let Some(&other) = others.first() {
            return Err(self.busy(shard, other));
        }
        Ok(ShardLock { _file: Some(file) })
    }

    /// The shards whose locks other processes hold, among those `wanted` takes, by count and index.
    pub fn held_locks(&self, wanted: impl Fn(Shard) -> bool) -> Vec<Shard> {
        let Ok(locks) = LOCK.list(&self.state()) else {
            return Vec::new();
        };
        let wanted = locks.into_iter().filter(|&(s, _)| wanted(s));
        let mut held: Vec<Shard> = wanted
            .filter_map(|(other, name)| {
                let file = files::open_regular(&self.state().join(name)).ok()?;
                // Shared, so that two processes looking at once do not see each other; dropped at once.
                let held = matches!(file.try_lock_shared(), Err(fs::TryLockError::WouldBlock));
                held.then_some(other)
            })
            .collect();
        held.sort_by_key(|s| (s.count(), s.index()));
        held
    }

    fn busy(&self, shard: Shard, holder: Shard) -> SweepError {
        let shares = if holder == shard {
            String::new()
        } else {
            format!(", which shares runs with shard {shard}")
        };
        SweepError::folder(&self.path)(format!(
            "is in use: another `coin-log sweep` is making shard {holder} now{shares} (it holds \
             {STATE_DIR}/{}); wait for it to end or stop it, then run again to resume",
            LOCK.name(holder)
        ))
    }

    /// Refuses, before any run, a folder in which `shard`'s catalogue (or part) and `sweep.json` could
    /// not be moved into place, each refused as its write would refuse it (not a regular file, no
    /// temporary file beside it) or by [`refuse_attribute`], and the folder by the latter: found at the
    /// end, the work was done for nothing, and a catalogue could be written without its `sweep.json`.
    pub fn check_outputs(&self, shard: Shard) -> Result<(), SweepError> {
        refuse_attribute(&self.path, &self.path)?;
        for name in outputs(shard) {
            let path = self.file(&name);
            files::absent_or_plain(&path).map_err(SweepError::io("writing", &path))?;
            refuse_attribute(&self.path, &path)?;
            // The temporary file it is written through: a folder we may not write in (permissions, a
            // read-only mount) failed only at the end, once every file was hashed.
            temp_file(&path).map_err(SweepError::io("writing", &path))?;
        }
        Ok(())
    }

    /// Deletes the temporary files a killed process of `shard` left: of its runs, and of its catalogue
    /// (for the whole sweep, also of `sweep.json`).
    pub fn remove_stale_temps(&self, shard: Shard) {
        let Ok(entries) = fs::read_dir(&self.path) else {
            return;
        };
        let own = outputs(shard);
        for entry in entries.flatten() {
            // `.NAME.<random>.tmp` (temp_beside): NAME is the file it was to become.
            let name = entry.file_name();
            let target = name.to_str().and_then(|n| {
                let rest = n.strip_prefix('.')?.strip_suffix(".tmp")?;
                rest.rsplit_once('.').map(|(target, _)| target)
            });
            let Some(target) = target else { continue };
            let run = target
                .strip_prefix("run-")
                .and_then(|r| r.strip_suffix(".mcap"));
            let run = run.and_then(|i| i.parse::<u64>().ok());
            if run.is_some_and(|i| shard.takes(i)) || own.iter().any(|n| n == target) {
                let _ = fs::remove_file(entry.path());
            }
        }
    }

    /// Every journal line of every shard, in the order written (journals by name): the rows, each with
    /// its file's recorded modification time. A last line without its line break (torn by a crash) and
    /// any line that does not parse (or is no UTF-8) are left out.
    pub fn journal_rows(&self) -> Result<Vec<JournalRow>, SweepError> {
        let width = 1 + self.columns().len();
        let journals = JOURNAL.list(&self.state()).map_err(SweepError::io(
            "reading the sweep's state folder",
            self.state(),
        ))?;
        let mut rows = Vec::new();
        for (_, name) in journals {
            let path = self.state().join(name);
            let bytes = files::absent_or_regular(&path)
                .and_then(|()| fs::read(&path))
                .map_err(SweepError::io("reading the journal", &path))?;
            // Bytes that are no UTF-8 (a crash's or a disk's damage) spoil their line only: it is left
            // out (its run redone), as a torn line is.
            let text = String::from_utf8_lossy(&bytes);
            let complete = text.rfind('\n').map_or("", |end| &text[..end]);
            rows.extend(
                complete
                    .lines()
                    .filter(|line| !line.contains(char::REPLACEMENT_CHARACTER))
                    .filter_map(|line| JournalRow::parse(line, width)),
            );
        }
        Ok(rows)
    }

    /// The journal of `shard`, opened for appending (created with its header line if new).
    pub fn journal(&self, shard: Shard) -> Result<Journal, SweepError> {
        let path = self.state().join(JOURNAL.name(shard));
        let file = open_append(&path).map_err(SweepError::io("opening the journal", &path))?;
        let last = last_byte(&file, &path).map_err(SweepError::io("reading the journal", &path))?;
        let mut journal = Journal { file, path };
        match last {
            None => {
                let mut header = vec![MTIME_COLUMN.to_string()];
                header.extend(self.columns());
                journal.write(&format!("{}\n", csv::line(&header)))?;
            }
            // A line torn by a crash: end it, so that it stays one bad (ignored) line instead of
            // swallowing the next row.
            Some(last) if last != b'\n' => journal.write("\n")?,
            Some(_) => {}
        }
        Ok(journal)
    }

    /// The whole sweep's catalogue of `lines`, then `sweep.json`: the plan with the counts (format.md:
    /// sweep.json).
    pub fn write_whole<S: AsRef<str>>(
        &self,
        lines: impl Iterator<Item = S>,
        [finished, failed, pending]: [u64; 3],
    ) -> Result<(PathBuf, PathBuf), SweepError> {
        let catalogue = self.write_catalogue(CATALOGUE_FILE, lines)?;
        let mut json = self.plan.clone();
        json["counts"] =
            serde_json::json!({"finished": finished, "failed": failed, "pending": pending});
        let summary = self.write_atomically(SWEEP_JSON_FILE, |w| writeln!(w, "{json}"))?;
        Ok((catalogue, summary))
    }

    /// A catalogue (or part) `name`: the header, then `lines`, each ending in a line break, streamed
    /// into place atomically.
    pub fn write_catalogue<S: AsRef<str>>(
        &self,
        name: &str,
        lines: impl Iterator<Item = S>,
    ) -> Result<PathBuf, SweepError> {
        let header = csv::line(&self.columns());
        self.write_atomically(name, |w| {
            writeln!(w, "{header}")?;
            for line in lines {
                writeln!(w, "{}", line.as_ref())?;
            }
            Ok(())
        })
    }

    /// Writes `name` in the folder atomically: a temporary file beside it, synced, then renamed over it.
    fn write_atomically(
        &self,
        name: &str,
        write: impl FnOnce(&mut dyn Write) -> io::Result<()>,
    ) -> Result<PathBuf, SweepError> {
        let path = self.path.join(name);
        let persist =
            |temp: tempfile::NamedTempFile| temp.persist(&path).map(drop).map_err(|e| e.error);
        files::absent_or_plain(&path)
            .and_then(|()| temp_beside(&path, write))
            .and_then(persist)
            .map_err(SweepError::io("writing", &path))?;
        Ok(path)
    }
}

/// The first entry of the sweep folder `path`, or of its state folder `state`, that a sweep without a
/// plan yet cannot have made: anything but the state folder and the plan's temporary files.
fn foreign_entry(path: &Path, state: &Path) -> Option<String> {
    let names = |dir: &Path| {
        let entries = fs::read_dir(dir).into_iter().flatten().flatten();
        entries.map(|e| e.file_name().to_string_lossy().into_owned())
    };
    let plan_temp = |name: &str| {
        name.strip_prefix(&format!(".{PLAN_FILE}."))
            .is_some_and(|rest| rest.ends_with(".tmp"))
    };
    let outside = names(path).find(|n| n != STATE_DIR);
    outside.or_else(|| {
        let inside = names(state).find(|n| !plan_temp(n));
        inside.map(|n| format!("{STATE_DIR}/{n}"))
    })
}

/// The files `shard` writes when it ends: its catalogue part, or the catalogue and `sweep.json`.
fn outputs(shard: Shard) -> Vec<String> {
    if shard.is_all() {
        vec![CATALOGUE_FILE.to_string(), SWEEP_JSON_FILE.to_string()]
    } else {
        vec![PART.name(shard)]
    }
}

/// Refuses `path` (the sweep folder `folder`, or a file in it) when it is immutable or append-only
/// (`chattr +i`, `+a`): a rename may not replace it (nor, for the folder, move a file into it), even for
/// root, which would show only once the work was done. The folder is one that cannot hold the sweep; a
/// file in it is an I/O error writing it, as when it is a folder or a link.
fn refuse_attribute(folder: &Path, path: &Path) -> Result<(), SweepError> {
    let Some(attribute) = files::Attribute::of(path) else {
        return Ok(());
    };
    let (name, clear) = attribute.words();
    let why = format!(
        "is {name}, so the system lets no file be moved into place there: clear the attribute ({clear} \
         {}), or give -o another folder",
        files::shown(path)
    );
    if path == folder {
        return Err(SweepError::folder(folder)(why));
    }
    let denied = io::Error::new(io::ErrorKind::PermissionDenied, why);
    Err(SweepError::io("writing", path)(denied))
}

fn last_byte(file: &File, path: &Path) -> io::Result<Option<u8>> {
    use std::io::{Read, Seek, SeekFrom};
    if file.metadata()?.len() == 0 {
        return Ok(None);
    }
    let mut file = File::open(path)?;
    let mut last = [0u8];
    file.seek(SeekFrom::End(-1))?;
    file.read_exact(&mut last)?;
    Ok(Some(last[0]))
}

/// A journal line: the `MTIME_COLUMN` value, then the catalogue row's fields (the index first).
#[derive(Debug, Clone, PartialEq)]
pub struct JournalRow {
    pub mtime_ns: u128,
    pub index: u64,
    pub fields: Vec<String>,
}

impl JournalRow {
    fn parse(line: &str, width: usize) -> Option<Self> {
        let mut fields = csv::split(line).filter(|f| f.len() == width)?;
        let mtime_ns = fields.first()?.parse().ok()?;
        fields.remove(0);
        let index = catalogue::index_of(fields.first()?)?;
        Some(Self {
            mtime_ns,
            index,
            fields,
        })
    }
}

/// One shard's journal, open for appending.
#[derive(Debug)]
pub struct Journal {
    file: File,
    path: PathBuf,
}

impl Journal {
    /// Appends rows (each with its file's modification time) and syncs them to disk before returning
    /// (a row torn by a failure is ignored when read back).
    pub fn append(&mut self, rows: &[(u128, String)]) -> Result<(), SweepError> {
        if rows.is_empty() {
            return Ok(());
        }
        let text: String = rows
            .iter()
            .map(|(mtime, line)| format!("{mtime},{line}\n"))
            .collect();
        self.write(&text)
    }

    fn write(&mut self, text: &str) -> Result<(), SweepError> {
        self.file
            .write_all(text.as_bytes())
            .and_then(|()| self.file.sync_data())
            .map_err(SweepError::io("writing the journal", &self.path))
    }
}

fn read_plan(path: &Path) -> Result<serde_json::Value, SweepError> {
    let parse = |text: String| {
        serde_json::from_str(&text).map_err(|e| io::Error::new(io::ErrorKind::InvalidData, e))
    };
    files::read_regular(path)
        .and_then(parse)
        .map_err(SweepError::io("reading the sweep's plan", path))
}

/// The folder's plan against this sweep's: same identity, same tool version.
fn check_same(
    folder: &Path,
    held: &serde_json::Value,
    plan: &serde_json::Value,
) -> Result<(), SweepError> {
    let error = |reason| Err(SweepError::folder(folder)(reason));
    let text = |v: &serde_json::Value, key: &str| v[key].as_str().unwrap_or_default().to_string();
    // A plan written before the generator was named drew with generator 1.
    let random = &held["sweep"]["random"];
    let generator = random["generator"].as_u64().unwrap_or(1);
    if random.is_object() && plan["sweep"]["random"].is_object() && generator != random::GENERATOR {
        return error(format!(
            "holds a sweep whose random draws come from generator {generator}, and this coin-log draws with \
             generator {} (format.md: Random draws): its remaining runs would get other values; finish it \
             with the coin-log that started it, or start over in a new folder",
            random::GENERATOR));
    }
    if text(held, "identity") != text(plan, "identity") {
        return error(format!(
            "holds another sweep (identity {}, this one {}): its sweep file, its base scene or its settings \
             differ; give -o a new folder for this sweep, or delete this folder to start it over",
            short(&text(held, "identity")), short(&text(plan, "identity"))));
    }
    if text(held, "tool_version") != text(plan, "tool_version") {
        return error(format!(
            "holds a sweep made by coin-log {}, and this is {}: its files could differ byte for byte from \
             what this version records; finish it with coin-log {0}, or start over in a new folder",
            text(held, "tool_version"), text(plan, "tool_version")));
    }
    Ok(())
}

fn short(identity: &str) -> &str {
    identity.get(..12).unwrap_or(identity)
}

fn open_append(path: &Path) -> io::Result<File> {
    files::absent_or_plain(path)?;
    OpenOptions::new().create(true).append(true).open(path)
}

/// Writes `path` through a synced temporary file beside it, unless `path` exists (`AlreadyExists`).
fn publish_new(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let temp = temp_beside(path, |w| w.write_all(bytes))?;
    temp.persist_noclobber(path).map(drop).map_err(|e| e.error)
}

/// An empty temporary file beside `path`, `.NAME.<random>.tmp`: named after it, so that a process
/// cleans up only its own ([`Folder::remove_stale_temps`]).
pub fn temp_file(path: &Path) -> io::Result<tempfile::NamedTempFile> {
    let name = path.file_name().unwrap_or_default().to_string_lossy();
    tempfile::Builder::new()
        .prefix(&format!(".{name}."))
        .suffix(".tmp")
        .tempfile_in(path.parent().unwrap_or_else(|| Path::new(".")))
}

/// A [`temp_file`] holding what `write` wrote, synced and readable.
fn temp_beside(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> io::Result<tempfile::NamedTempFile> {
    let mut temp = temp_file(path)?;
    {
        let mut buffered = io::BufWriter::new(temp.as_file_mut());
        write(&mut buffered)?;
        buffered.flush()?;
    }
    temp.as_file().sync_all()?;
    files::make_readable(temp.as_file());
    Ok(temp)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_torn_last_journal_line_and_garbage_are_left_out() {
        let width = 3;
        assert!(JournalRow::parse("12,0,a", width).is_some());
        assert!(JournalRow::parse("12,0", width).is_none());
        assert!(JournalRow::parse("x,0,a", width).is_none());
        assert!(JournalRow::parse("12,\"0,a", width).is_none());
        assert!(JournalRow::parse("12,+0,a", width).is_none());
        assert!(JournalRow::parse("12,01,a", width).is_none());
    }

    #[test]
    fn part_names_give_their_shard() {
        let s = Shard::new(2, 5).unwrap();
        assert_eq!(PART.shard_of(&PART.name(s)), Some(s));
        assert_eq!(PART.shard_of("catalogue.part-5-of-5.csv"), None);
        assert_eq!(run_file_name(7, 3), "run-007.mcap");
    }
}

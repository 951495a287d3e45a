//! How every output is written (format.md: Commands, Inputs and outputs): into an owner-only temporary file
//! beside the target, moved into place by rename once finished and synced. A rename replaces whatever has
//! the target's name, so targets are looked at with `symlink_metadata` (never following a link, never
//! opening a pipe), before any work and again just before the move. [`OutputFolder`] does the same for
//! several files in one folder.

use super::shown;
use std::borrow::Cow;
use std::fs::{self, File, Metadata, OpenOptions};
use std::io::{self, ErrorKind, Write};
use std::path::{Path, PathBuf};
use tempfile::NamedTempFile;

/// What may be at a target, and how messages tell the user to name another.
#[derive(Debug, Clone, Default)]
pub struct Policy {
    /// An existing regular file may be replaced (`--overwrite`, or a command that always replaces its own
    /// files).
    pub overwrite: bool,
    /// The command has `--overwrite`, which messages may then name; false for a command that always
    /// replaces its own files and has no such flag (`man`, `analyse map`, `bench`).
    pub overwrite_flag: bool,
    /// The flag that names the target (`-o`, `--out`), for the fixes messages suggest.
    pub flag: &'static str,
    /// A file name to suggest instead of a folder or a special file (`wobble.mcap`).
    pub example: Cow<'static, str>,
    /// A file the output must never replace, however reached (another path, a hard or symbolic link),
    /// and what it is: `(scene, "the scene file being recorded")`.
    pub protect: Option<(PathBuf, &'static str)>,
}

/// Why an output cannot be written, or was not moved into place, and what to do instead.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct OutputError(String);

impl OutputError {
    fn system(doing: &str, path: &Path, source: &io::Error) -> Self {
        Self(format!("cannot {doing} `{}`: {source}", shown(path)))
    }
}

/// What a refused target is, for the fix a message suggests.
#[derive(Clone, Copy)]
enum Refused {
    Folder,
    Special,
    Protected,
    Exists,
}

impl Policy {
    /// What to do instead of writing to `target`, refused as `refused`. Without an example the target is a
    /// file of an output folder (`export`, `man`): the fix is another folder.
    fn fix(&self, refused: Refused, target: &Path) -> String {
        let (flag, other) = (self.flag, self.other());
        match refused {
            Refused::Exists => {
                format!("pass --overwrite to replace it, or choose another {other} with {flag}")
            }
            _ if self.example.is_empty() => {
                format!("move it away, or choose another {other} with {flag}")
            }
            Refused::Folder => format!(
                "give a file name, e.g. {flag} {}",
                shown(&target.join(&*self.example))
            ),
            Refused::Special => format!("choose a file path, e.g. {flag} {}", self.example),
            Refused::Protected => {
                // The example is the scene's stem + .mcap, the protected file itself for a scene file
                // named `s.mcap`: then another name.
                let example = Path::new(&*self.example);
                let example = if target.file_name() == Some(example.as_os_str()) {
                    let stem = example.file_stem().unwrap_or_default().to_string_lossy();
                    match example.extension() {
                        Some(ext) => format!("{stem}-recorded.{}", ext.to_string_lossy()),
                        None => format!("{stem}-recorded"),
                    }
                } else {
                    self.example.to_string()
                };
                format!("choose another output, e.g. {flag} {example}")
            }
        }
    }

    /// What a message tells the user to choose another of: a folder for the files of an output folder
    /// (no example), else a file.
    fn other(&self) -> &'static str {
        if self.example.is_empty() {
            "folder"
        } else {
            "file"
        }
    }
}

/// What a file that is neither regular nor a link is, in words.
pub(super) fn kind_of(meta: &Metadata) -> &'static str {
    if meta.is_dir() {
        return "a folder";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let t = meta.file_type();
        let kinds = [
            (t.is_char_device(), "a character device"),
            (t.is_block_device(), "a block device"),
            (t.is_fifo(), "a named pipe"),
            (t.is_socket(), "a socket"),
        ];
        if let Some((_, what)) = kinds.into_iter().find(|(is, _)| *is) {
            return what;
        }
    }
    "a special file"
}

/// An attribute by which the system forbids replacing or removing a file, or changing a folder's entries,
/// whatever the permissions and even for root (Linux: `chattr +i`, `chattr +a`): the move into place
/// would fail only after the work.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Attribute {
    /// `chattr +i`: nothing may change, replace or remove it (nor, in a folder, add or rename files).
    Immutable,
    /// `chattr +a`: it may only grow (a folder may gain files, but none may be renamed or removed).
    AppendOnly,
}

impl Attribute {
    /// The attribute `path` (not followed if a link) has, if the system says; `None` where it does not.
    #[must_use]
    pub fn of(path: &Path) -> Option<Self> {
        #[cfg(target_os = "linux")]
        {
            use rustix::fs::{statx, AtFlags, StatxAttributes, StatxFlags, CWD};
            let stat = statx(CWD, path, AtFlags::SYMLINK_NOFOLLOW, StatxFlags::empty()).ok()?;
            Self::from_attributes(
                stat.stx_attributes.contains(StatxAttributes::IMMUTABLE),
                stat.stx_attributes.contains(StatxAttributes::APPEND),
            )
        }
        #[cfg(not(target_os = "linux"))]
        {
            let _ = path;
            None
        }
    }

    /// The attribute of statx's `immutable` and `append` flags (immutable first: it forbids more).
    #[must_use]
    pub fn from_attributes(immutable: bool, append: bool) -> Option<Self> {
        match (immutable, append) {
            (true, _) => Some(Self::Immutable),
            (false, true) => Some(Self::AppendOnly),
            (false, false) => None,
        }
    }

    /// Its name, and the command that clears it.
    #[must_use]
    pub fn words(self) -> (&'static str, &'static str) {
        match self {
            Self::Immutable => ("immutable", "chattr -i"),
            Self::AppendOnly => ("append-only", "chattr -a"),
        }
    }
}

/// Refuses a target whose folder, or which itself (when it is there), has an [`Attribute`] that forbids
/// moving a file into place.
fn check_attributes(target: &Path, exists: bool, policy: &Policy) -> Result<(), OutputError> {
    let (what, flag) = (policy.other(), policy.flag);
    if let Some(attribute) = exists.then(|| Attribute::of(target)).flatten() {
        let (name, clear) = attribute.words();
        let path = shown(target);
        let even = if policy.overwrite_flag {
            ", even with --overwrite"
        } else {
            ""
        };
        return Err(OutputError(format!(
            "`{path}` is {name}, so the system lets no file replace it{even}: clear the attribute \
             ({clear} {path}), or choose another {what} with {flag}"
        )));
    }
    let folder = folder_of(target);
    if let Some(attribute) = Attribute::of(&folder) {
        let (name, clear) = attribute.words();
        let folder = shown(&folder);
        return Err(OutputError(format!(
            "the folder `{folder}` is {name}, so the system lets no file be moved into place in it (for \
             `{}`): clear the attribute ({clear} {folder}), or choose another {what} with {flag}",
            shown(target)
        )));
    }
    Ok(())
}

/// The folder a target lives in (`.` for a bare file name).
fn folder_of(target: &Path) -> PathBuf {
    match target.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

fn exists(target: &Path, policy: &Policy) -> OutputError {
    let fix = policy.fix(Refused::Exists, target);
    OutputError(format!("`{}` already exists; {fix}", shown(target)))
}

fn not_a_folder(path: &str, folder: &str) -> OutputError {
    OutputError(format!(
        "`{folder}` is not a folder, so `{path}` cannot be created in it"
    ))
}

/// [`check`] but for an existing file, which is returned whatever the policy says of replacing it.
fn look_at(target: &Path, policy: &Policy) -> Result<Option<Metadata>, OutputError> {
    if target.as_os_str() == "-" {
        let fix = policy.fix(Refused::Special, target);
        return Err(OutputError(format!(
            "`-` would be a file named `-`: coin-log does not write to standard output, it writes a file and \
             moves it into place; {fix} (a file named `-` is `./-`)"
        )));
    }
    let path = shown(target);
    let meta = match fs::symlink_metadata(target) {
        Ok(meta) => meta,
        // `-o new/` names a folder that is not there (the system's word for it: "Is a directory").
        Err(e) if e.kind() == ErrorKind::NotFound && path.ends_with('/') => {
            let fix = policy.fix(Refused::Folder, target);
            return Err(OutputError(format!(
                "`{path}` ends with `/`, so it names a folder, and there is none: drop the `/`, or create \
                 the folder and {fix}"
            )));
        }
        Err(e) if e.kind() == ErrorKind::NotFound => {
            check_folder(target)?;
            return check_attributes(target, false, policy).map(|()| None);
        }
        Err(source) => return Err(OutputError::system("use", target, &source)),
    };
    let kind = meta.file_type();
    if kind.is_dir() {
        let fix = policy.fix(Refused::Folder, target);
        return Err(OutputError(format!("`{path}` is a folder; {fix}")));
    }
    if kind.is_symlink() {
        let to = fs::read_link(target).map_or_else(|_| "?".into(), |p| shown(&p));
        return Err(OutputError(format!(
            "`{path}` is a symbolic link (to `{to}`), not a regular file; coin-log writes a new file and moves \
             it into place, which would replace the link itself with a plain file: {}",
            link_fix(target, policy)
        )));
    }
    if !kind.is_file() {
        let what = kind_of(&meta);
        let the = what.replacen("a ", "the ", 1);
        let fix = policy.fix(Refused::Special, target);
        return Err(OutputError(format!(
            "`{path}` is {what}, not a regular file; coin-log writes a new file and moves it into place, \
             which would replace {the}: {fix}"
        )));
    }
    if let Some((_, what)) = policy
        .protect
        .as_ref()
        .filter(|(file, _)| same_file(&meta, file))
    {
        let fix = policy.fix(Refused::Protected, target);
        return Err(OutputError(format!(
            "`{path}` is {what}; writing there would replace it: {fix}"
        )));
    }
    check_attributes(target, true, policy)?;
    Ok(Some(meta))
}

/// What to do instead of writing over the symbolic link `target`. Its destination is the fix only when
/// it is (or would be) a regular file: `/dev/stdout` leads to a pipe or a terminal (`pipe:[…]`), and a
/// page of `man --out` cannot be given alone.
fn link_fix(target: &Path, policy: &Policy) -> String {
    if policy.example.is_empty() {
        return policy.fix(Refused::Special, target);
    }
    match fs::metadata(target) {
        Ok(meta) if meta.is_dir() => format!(
            "it leads to a folder; {}",
            policy.fix(Refused::Folder, target)
        ),
        Ok(meta) if !meta.is_file() => format!(
            "it leads to {}, which coin-log does not write into (nor to standard output); {}",
            kind_of(&meta),
            policy.fix(Refused::Special, target)
        ),
        Err(e) if e.kind() != ErrorKind::NotFound => policy.fix(Refused::Special, target),
        // A regular file, or nothing yet.
        _ => "give the path it points to, or choose another path".into(),
    }
}

/// The target's folder must exist (a clearer message than the temporary file's ENOENT).
fn check_folder(target: &Path) -> Result<(), OutputError> {
    let folder = folder_of(target);
    let (path, shown_folder) = (shown(target), shown(&folder));
    match fs::metadata(&folder) {
        Ok(m) if m.is_dir() => Ok(()),
        Ok(_) => Err(not_a_folder(&path, &shown_folder)),
        Err(e) if e.kind() == ErrorKind::NotFound => Err(OutputError(format!(
            "the folder `{shown_folder}` does not exist (for `{path}`): create it first, or choose another \
             path"
        ))),
        Err(source) => Err(OutputError::system("use the folder", &folder, &source)),
    }
}

/// True when `meta` (of the target) and the file at `other` are the same file, however reached.
fn same_file(meta: &Metadata, other: &Path) -> bool {
    let Ok(other) = fs::metadata(other) else {
        return false;
    };
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        meta.dev() == other.dev() && meta.ino() == other.ino()
    }
    #[cfg(not(unix))]
    {
        let _ = (meta, other);
        false
    }
}

/// Proves before any work that the move into place will work: a name that does not exist yet is created
/// and removed at once (the system then names any cause: "File name too long", "Read-only file system");
/// an existing file must be replaceable by us (in a folder with the sticky bit, only its owner may).
fn probe_target(
    target: &Path,
    existing: Option<&Metadata>,
    temp: &NamedTempFile,
    policy: &Policy,
) -> Result<(), OutputError> {
    let Some(meta) = existing else {
        return match OpenOptions::new().write(true).create_new(true).open(target) {
            Ok(file) => {
                drop(file);
                fs::remove_file(target)
                    .map_err(|source| OutputError::system("remove the probe", target, &source))
            }
            Err(e) if e.kind() == ErrorKind::AlreadyExists => Err(exists(target, policy)),
            Err(source) => Err(OutputError::system("create", target, &source)),
        };
    };
    match sticky_owner(target, meta, temp) {
        Some(uid) => Err(OutputError(format!(
            "cannot replace `{}`: it belongs to another user (uid {uid}) in a folder with the sticky bit \
             (like /tmp), where only its owner may replace it: choose another path",
            shown(target)
        ))),
        None => Ok(()),
    }
}

/// The owner of an existing file in a sticky folder when we may not replace it.
fn sticky_owner(target: &Path, meta: &Metadata, temp: &NamedTempFile) -> Option<u32> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::{MetadataExt, PermissionsExt};
        let folder = fs::metadata(folder_of(target)).ok()?;
        // The temporary file was just created by this process: its owner is our effective user.
        let me = temp.as_file().metadata().ok()?.uid();
        let sticky = folder.permissions().mode() & 0o1000 != 0;
        (sticky && me != 0 && meta.uid() != me && folder.uid() != me).then_some(meta.uid())
    }
    #[cfg(not(unix))]
    {
        let _ = (target, meta, temp);
        None
    }
}

/// A finished output file is an ordinary file (the temporary file is created owner-only): mode 0666 less
/// the process's umask, as `open` gives a new file (it was 0644 whatever the umask, so `umask 077` still
/// gave world-readable recordings).
pub fn make_readable(file: &File) {
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let _ = file.set_permissions(fs::Permissions::from_mode(0o666 & !umask()));
    }
    #[cfg(not(unix))]
    let _ = file;
}

/// The process's umask, from `/proc/self/status` (reading it with umask(2) would change it); 022, the
/// usual one, where the system does not say.
#[cfg(unix)]
fn umask() -> u32 {
    fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|status| {
            let line = status.lines().find_map(|l| l.strip_prefix("Umask:"))?;
            u32::from_str_radix(line.trim(), 8).ok()
        })
        .unwrap_or(0o022)
}

/// Checks `target` against `policy` as [`Output::create`] does, failing as its checks do, creating nothing
/// (for a command that works long before it writes, `bench`, so that a target it would refuse at the end is
/// refused first); returns its metadata when it is a regular file that may be replaced, `None` when it does
/// not exist (its folder then does).
pub fn check(target: &Path, policy: &Policy) -> Result<Option<Metadata>, OutputError> {
    let meta = look_at(target, policy)?;
    if meta.is_some() && !policy.overwrite {
        return Err(exists(target, policy));
    }
    Ok(meta)
}

/// The longest extension of a target repeated in its temporary file's name (`.coin-log-*.mcap.tmp`).
const MAX_SHOWN_EXTENSION: usize = 8;

/// One output file being written: a temporary file beside its target until [`Output::commit`].
#[derive(Debug)]
pub struct Output {
    target: PathBuf,
    temp: NamedTempFile,
    policy: Policy,
}

impl Output {
    /// Checks `target` against `policy` and creates the temporary file beside it; fails, leaving nothing
    /// behind, when the target is not a file that may be written or replaced, its folder is missing, or
    /// the system refuses the name or the folder.
    pub fn create(target: &Path, policy: &Policy) -> Result<Self, OutputError> {
        let existing = check(target, policy)?;
        let folder = folder_of(target);
        // The target's extension shows what the file will be; a long one is left out, so that the
        // temporary name (20 bytes more than it) fits wherever the target's does (`-o x.<245 bytes>` was
        // refused as "File name too long").
        let suffix = target
            .extension()
            .filter(|e| e.len() <= MAX_SHOWN_EXTENSION)
            .map_or_else(
                || ".tmp".to_string(),
                |e| format!(".{}.tmp", e.to_string_lossy()),
            );
        let temp = tempfile::Builder::new()
            .prefix(".coin-log-")
            .suffix(&suffix)
            .tempfile_in(&folder)
            .map_err(|source| {
                OutputError(format!(
                    "cannot write in `{}` (for `{}`): {source}",
                    shown(&folder),
                    shown(target)
                ))
            })?;
        probe_target(target, existing.as_ref(), &temp, policy)?;
        Ok(Self {
            target: target.to_path_buf(),
            temp,
            policy: policy.clone(),
        })
    }

    /// Writes `bytes` to `target` by [`Output::create`] and [`Output::commit`] (failing as they do).
    pub fn write(target: &Path, policy: &Policy, bytes: &[u8]) -> Result<(), OutputError> {
        let mut output = Self::create(target, policy)?;
        output
            .file()
            .write_all(bytes)
            .map_err(|source| output.write_error(source))?;
        output.commit()
    }

    /// The temporary file, to write the output into.
    pub fn file(&mut self) -> &mut File {
        self.temp.as_file_mut()
    }

    /// Where the output is written until it is finished.
    #[must_use]
    pub fn temp_path(&self) -> &Path {
        self.temp.path()
    }

    /// Where the output goes.
    #[must_use]
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// The error of a failed write into the output.
    #[must_use]
    pub fn write_error(&self, source: io::Error) -> OutputError {
        OutputError::system("write", &self.target, &source)
    }

    /// Syncs the finished file, makes it readable and moves it into place. Fails if the file cannot be
    /// synced (it is then removed: it is not finished), or was not moved into place: when the target no
    /// longer takes it or the move fails, the file is kept under its temporary name and the error says where.
    pub fn commit(self) -> Result<(), OutputError> {
        self.temp
            .as_file()
            .sync_all()
            .map_err(|source| self.write_error(source))?;
        make_readable(self.temp.as_file());
        // Checked again: something may have appeared there meanwhile.
        let reason = match look_at(&self.target, &self.policy) {
            Ok(Some(_)) if !self.policy.overwrite => format!(
                "{} (it appeared while the file was written, and was left alone)",
                exists(&self.target, &self.policy)
            ),
            Err(e) => e.to_string(),
            Ok(_) => {
                let moved = if self.policy.overwrite {
                    self.temp.persist(&self.target).map(drop)
                } else {
                    self.temp.persist_noclobber(&self.target).map(drop)
                };
                let Err(e) = moved else {
                    return Ok(());
                };
                let reason = format!("cannot move it to `{}`: {}", shown(&self.target), e.error);
                return Err(keep(e.file, reason));
            }
        };
        Err(keep(self.temp, reason))
    }
}

/// Keeps a finished temporary file that could not be moved into place.
fn keep(temp: NamedTempFile, reason: String) -> OutputError {
    let kept = match temp.keep() {
        // The temporary file's path is the folder's joined with its name: `/x/./.coin-log-…` for `.`.
        Ok((_, path)) => shown(
            &path
                .components()
                .filter(|c| *c != std::path::Component::CurDir)
                .collect::<PathBuf>(),
        ),
        Err(e) => format!("nowhere: it could not be kept either ({})", e.error),
    };
    OutputError(format!(
        "the finished file was not moved into place: {reason}; it is kept as `{kept}`"
    ))
}

/// Several output files in one folder, each an [`Output`]: created if missing (and removed again, with
/// every temporary file, if the outputs are dropped before [`OutputFolder::commit`]).
#[derive(Debug)]
pub struct OutputFolder {
    dir: PathBuf,
    policy: Policy,
    outputs: Vec<Output>,
    /// The folders this created, deepest first.
    created: Vec<PathBuf>,
}

impl OutputFolder {
    /// Opens `dir` for outputs, creating it (and missing parents) if needed, failing if it or a parent is
    /// not a folder or cannot be created; `overwrite` lets the files replace regular files of the same names.
    pub fn create(dir: &Path, overwrite: bool) -> Result<Self, OutputError> {
        let mut created = missing_folders(dir)?;
        // Created from the top down; on failure, what was created is removed (by `Drop`).
        let mut folder = Self {
            dir: dir.to_path_buf(),
            policy: folder_policy(overwrite),
            outputs: Vec::new(),
            created: Vec::new(),
        };
        while let Some(d) = created.pop() {
            fs::create_dir(&d)
                .map_err(|source| OutputError::system("create the folder", &d, &source))?;
            folder.created.insert(0, d);
        }
        Ok(folder)
    }

    /// Checks, creating nothing, what [`OutputFolder::create`] and [`OutputFolder::file`] would for each of
    /// `names`, failing as they do: for a command that works long before it writes (`analyse map`), so that
    /// a refused --out is refused before the work, and the work leaves nothing behind if it fails or is
    /// stopped by a signal.
    pub fn check(dir: &Path, overwrite: bool, names: &[&str]) -> Result<(), OutputError> {
        if missing_folders(dir)?.is_empty() {
            for name in names {
                check(&dir.join(name), &folder_policy(overwrite))?;
            }
        }
        Ok(())
    }

    /// The folder.
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.dir
    }

    /// The command has `--overwrite`, which messages may name ([`Policy::overwrite_flag`]).
    #[must_use]
    pub fn with_overwrite_flag(mut self) -> Self {
        self.policy.overwrite_flag = true;
        self
    }

    /// No file of the folder may replace `file` (the input being read, however reached), `what` saying
    /// what it is: [`Policy::protect`].
    #[must_use]
    pub fn protecting(mut self, file: &Path, what: &'static str) -> Self {
        self.policy.protect = Some((file.to_path_buf(), what));
        self
    }

    /// Starts the file `name` in the folder by [`Output::create`]; returns a handle to write it through.
    pub fn file(&mut self, name: &str) -> Result<File, OutputError> {
        let mut output = Output::create(&self.dir.join(name), &self.policy)?;
        let file = output
            .file()
            .try_clone()
            .map_err(|source| output.write_error(source))?;
        self.outputs.push(output);
        Ok(file)
    }

    /// Checks every target again, then moves every file into place: either all land, or (unless a move
    /// itself fails) none does, failing as [`Output::commit`].
    pub fn commit(mut self) -> Result<(), OutputError> {
        for output in &self.outputs {
            check(&output.target, &output.policy)?;
        }
        for output in std::mem::take(&mut self.outputs) {
            output.commit()?;
        }
        self.created.clear();
        Ok(())
    }
}

/// The policy of a file in an output folder.
fn folder_policy(overwrite: bool) -> Policy {
    Policy {
        overwrite,
        flag: "--out",
        ..Policy::default()
    }
}

/// The folders missing on the way to `dir`, deepest first (none if it exists); fails if `dir` or a parent
/// is not a folder, or is a link to nothing.
fn missing_folders(dir: &Path) -> Result<Vec<PathBuf>, OutputError> {
    if dir.as_os_str() == "-" {
        // As for a file output `-`: one who writes `--out -` expects standard output, not a folder `-`.
        return Err(OutputError(
            "`-` would be a folder named `-`: coin-log does not write to standard output, it writes its \
             files into a folder; choose one with --out, e.g. --out results (a folder named `-` is `./-`)"
                .to_string(),
        ));
    }
    let mut created = Vec::new();
    let mut missing = Some(dir);
    while let Some(d) = missing.filter(|d| !d.as_os_str().is_empty()) {
        match fs::metadata(d) {
            Ok(m) if m.is_dir() => break,
            Ok(_) if d == dir => {
                return Err(OutputError(format!(
                    "`{}` is not a folder; --out takes a folder (created if missing) for the \
                         files",
                    shown(dir)
                )))
            }
            Ok(_) => return Err(not_a_folder(&shown(dir), &shown(d))),
            Err(_) => match dangling_link(d) {
                Some(to) => {
                    return Err(OutputError(format!(
                    "`{}` is a symbolic link to `{}`, which does not exist: create the folder it \
                         points to, or choose another folder with --out",
                    shown(d),
                    shown(&to)
                )))
                }
                None => created.push(d.to_path_buf()),
            },
        }
        missing = d.parent();
    }
    Ok(created)
}

/// Where `path` points when it is a symbolic link to nothing (or to a loop of links): creating a
/// folder there fails with a bare "File exists", so the commands that create folders name it instead.
#[must_use]
pub fn dangling_link(path: &Path) -> Option<PathBuf> {
    let link = fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink());
    (link && fs::metadata(path).is_err())
        .then(|| fs::read_link(path).ok())
        .flatten()
}

impl Drop for OutputFolder {
    fn drop(&mut self) {
        self.outputs.clear();
        for d in &self.created {
            let _ = fs::remove_dir(d);
        }
    }
}

//! Where `record` may write (format.md: record, Writing). The recording is written to a temporary file
//! beside the target and moved into place by rename, which replaces whatever has the target's name. So
//! the target must be absent, or, with `--overwrite`, a regular file: never a device node (`/dev/null`,
//! `/dev/stdout`), a named pipe, a socket, a symbolic link (the link itself would become a plain file) or
//! a folder, and never the scene file being recorded. The target is looked at with `symlink_metadata`
//! (lstat), which never follows a link. Everything here runs before the simulation, so a bad target costs
//! nothing and leaves nothing behind.

use anyhow::bail;
use std::fs::{self, Metadata, OpenOptions};
use std::io::ErrorKind;
use std::path::{Path, PathBuf};
use tempfile::NamedTempFile;

/// The folder a target lives in (`.` for a bare file name).
pub fn folder_of(target: &Path) -> PathBuf {
    match target.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// What a file that is not regular is, in words, if we can tell.
fn kind_of(meta: &Metadata) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let t = meta.file_type();
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_fifo() {
            return "a named pipe";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    let _ = meta;
    "a special file"
}

/// Checks the target before anything is created; returns its metadata when it is a regular file that
/// `--overwrite` allows to replace, `None` when it does not exist.
///
/// # Errors
/// The target is not a regular file, is the scene file, exists without `--overwrite`, or cannot be
/// looked at (name too long, a part of the path is not a folder, no permission).
pub fn check_target(
    target: &Path,
    overwrite: bool,
    scene_file: Option<&Path>,
    stem: &str,
) -> anyhow::Result<Option<Metadata>> {
    let shown = target.display();
    let meta = match fs::symlink_metadata(target) {
        Ok(meta) => meta,
        Err(e) if e.kind() == ErrorKind::NotFound => {
            check_folder(target)?;
            return Ok(None);
        }
        Err(e) => bail!("cannot use `{shown}` as the output file: {e}"),
    };
    let kind = meta.file_type();
    if kind.is_dir() {
        bail!(
            "`{shown}` is a folder; give the recording a file name, e.g. -o {}",
            target.join(format!("{stem}.mcap")).display()
        );
    }
    if kind.is_symlink() {
        let to = fs::read_link(target).map_or_else(|_| "?".into(), |p| p.display().to_string());
        bail!(
            "`{shown}` is a symbolic link (to `{to}`), not a regular file; coin-log writes a new file and \
             moves it into place, which would replace the link itself with a plain file: give the path it \
             points to with -o, or choose another path"
        );
    }
    if !kind.is_file() {
        let what = kind_of(&meta);
        bail!(
            "`{shown}` is {what}, not a regular file; coin-log writes a new file and moves it into place, \
             which would replace {}: choose a file path, e.g. -o {stem}.mcap",
            what.replacen("a ", "the ", 1)
        );
    }
    if scene_file.is_some_and(|scene| same_file(&meta, scene)) {
        bail!(
            "`{shown}` is the scene file being recorded; writing there would replace the scene with MCAP \
             bytes: choose another output, e.g. -o {stem}.mcap"
        );
    }
    if !overwrite {
        bail!("`{shown}` already exists; pass --overwrite to replace it, or choose another file with -o");
    }
    Ok(Some(meta))
}

/// For the other commands that write files (`plot`, `export`, `analyse map`): an existing `target` must be
/// a regular file, since they too move a finished temporary file into place, which would replace a link,
/// a device, a pipe or a socket with a plain file, even with `--overwrite`. Looks without following links.
///
/// # Errors
/// `target` exists and is not a regular file.
pub fn refuse_special(target: &Path) -> anyhow::Result<()> {
    let shown = target.display();
    let Ok(meta) = fs::symlink_metadata(target) else {
        return Ok(());
    };
    let kind = meta.file_type();
    if kind.is_symlink() {
        let to = fs::read_link(target).map_or_else(|_| "?".into(), |p| p.display().to_string());
        bail!(
            "`{shown}` is a symbolic link (to `{to}`), not a regular file; the new file is moved into place, \
             which would replace the link itself with a plain file: give the path it points to, or choose \
             another path"
        );
    }
    if !kind.is_file() && !kind.is_dir() {
        let what = kind_of(&meta);
        bail!(
            "`{shown}` is {what}, not a regular file; the new file is moved into place, which would \
             replace {}: choose a file path",
            what.replacen("a ", "the ", 1)
        );
    }
    Ok(())
}

/// The target's folder must exist (a clearer message than the temporary file's ENOENT).
fn check_folder(target: &Path) -> anyhow::Result<()> {
    let folder = folder_of(target);
    match fs::metadata(&folder) {
        Ok(m) if m.is_dir() => Ok(()),
        Ok(_) => bail!(
            "`{}` is not a folder, so `{}` cannot be created in it",
            folder.display(),
            target.display()
        ),
        Err(e) if e.kind() == ErrorKind::NotFound => bail!(
            "the folder `{}` does not exist (for `{}`): create it first, or choose another path",
            folder.display(),
            target.display()
        ),
        Err(e) => bail!("cannot use the folder `{}`: {e}", folder.display()),
    }
}

/// True when `meta` (of the target) and the file at `scene` are the same file, however reached (another
/// path, a hard link, a symbolic link to it).
fn same_file(meta: &Metadata, scene: &Path) -> bool {
    let Ok(scene) = fs::metadata(scene) else {
        return false;
    };
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        meta.dev() == scene.dev() && meta.ino() == scene.ino()
    }
    #[cfg(not(unix))]
    {
        let _ = (meta, scene);
        false
    }
}

/// Proves, before simulating, that the move into place will work: a name that does not exist yet is
/// created and removed at once (the OS then names any cause: "File name too long", "Invalid argument" for
/// a character the file system refuses, "Read-only file system"); an existing file must be replaceable
/// by us (in a folder with the sticky bit, like /tmp, only its owner may).
///
/// # Errors
/// The name cannot be created, or the existing file cannot be replaced.
pub fn probe_target(
    target: &Path,
    existing: Option<&Metadata>,
    temp: &NamedTempFile,
) -> anyhow::Result<()> {
    let shown = target.display();
    let Some(meta) = existing else {
        return match OpenOptions::new().write(true).create_new(true).open(target) {
            Ok(file) => {
                drop(file);
                fs::remove_file(target)
                    .map_err(|e| anyhow::anyhow!("cannot remove the probe `{shown}`: {e}"))
            }
            Err(e) if e.kind() == ErrorKind::AlreadyExists => {
                bail!("`{shown}` appeared just now; pass --overwrite to replace it, or choose another file with -o")
            }
            Err(e) => bail!("cannot create `{shown}`: {e}"),
        };
    };
    if let Some(why) = sticky_refusal(target, meta, temp) {
        bail!("cannot replace `{shown}`: {why}");
    }
    Ok(())
}

/// Why an existing file in a sticky folder cannot be replaced by us, if it cannot.
fn sticky_refusal(target: &Path, meta: &Metadata, temp: &NamedTempFile) -> Option<String> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::{MetadataExt, PermissionsExt};
        let folder = fs::metadata(folder_of(target)).ok()?;
        // The temporary file was just created by this process: its owner is our effective user.
        let me = temp.as_file().metadata().ok()?.uid();
        let sticky = folder.permissions().mode() & 0o1000 != 0;
        (sticky && me != 0 && meta.uid() != me && folder.uid() != me).then(|| {
            format!(
                "it belongs to another user (uid {}) in a folder with the sticky bit (like /tmp), where only \
                 its owner may replace it: choose another path",
                meta.uid()
            )
        })
    }
    #[cfg(not(unix))]
    {
        let _ = (target, meta, temp);
        None
    }
}

//! Atomic writes: a file is replaced whole or not at all, through a hidden
//! temporary beside it whose name tags its writer, and the temporaries left
//! by writers that are gone are found and removed.

use crate::error::{Error, Result};
use crate::host::{file_age, writer_is_dead_here, writer_tag};
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use tempfile::NamedTempFile;

/// Replaces `path` whole or not at all: `write` fills a hidden temporary file
/// beside it (`.<name>.<host>.<pid>.<random>.partial`, unique per writer, so a
/// leftover one is never taken for a final file and `remove_stale_partials`
/// knows whose it is), which is flushed, synced and renamed over `path`. On
/// any error the temporary file is deleted. Files are readable by all.
///
/// Every error names `path`, and `write` is given `path` to name in its
/// own: the temporary is gone by the time the error is read, and the user
/// knows the file by its final name (`out/zoom/frame_00007.exr: No space
/// left on device`).
pub fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<&File>, &Path) -> Result<()>,
) -> Result<()> {
    through_temporary(path, true, write)
}

/// `write_atomic` for a file that must not exist yet: an existing `path` is
/// an `AlreadyExists` error and is left as it was; nothing else of the new
/// file is ever seen but the whole of it.
pub fn write_new_text(path: &Path, text: &str) -> Result<()> {
    through_temporary(path, false, |writer, file| {
        use std::io::Write as _;
        writer
            .write_all(text.as_bytes())
            .map_err(|e| Error::io(file, e))
    })
}

/// `write_atomic`, writing over an existing `path` only with `clobber`.
fn through_temporary(
    path: &Path,
    clobber: bool,
    write: impl FnOnce(&mut BufWriter<&File>, &Path) -> Result<()>,
) -> Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut builder = tempfile::Builder::new();
    let prefix = format!(".{}.{}", name.trim_start_matches('.'), writer_tag());
    builder.prefix(&prefix).suffix(".partial");
    #[cfg(unix)]
    {
        // Ordinary files, readable by all (tempfile's default is 0600).
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o644));
    }
    // Created and renamed under the interrupt lock, so Ctrl-C removes
    // every temporary file and none is renamed into place after it.
    let (temp, _removed_on_interrupt) = {
        let mut held = crate::interrupt::hold();
        let temp = builder.tempfile_in(dir).map_err(|e| Error::io(path, e))?;
        let temp_path = temp.path().to_path_buf();
        let removal = held.on_interrupt(move || {
            let _ = std::fs::remove_file(temp_path);
        });
        (temp, removal)
    };
    // Written through the plain file: the temporary file's own writer
    // would add its path to every error, which `Error::io` names already.
    let mut writer = BufWriter::new(temp.as_file());
    write(&mut writer, path)?;
    writer
        .into_inner()
        .map_err(|e| Error::io(path, e.into_error()))?
        .sync_all()
        .map_err(|e| Error::io(path, e))?;
    let _held = crate::interrupt::hold();
    let temp = match clobber {
        true => Some(temp),
        false => claimed(temp, path)?,
    };
    if let Err(e) = temp.map_or(Ok(()), |temp| temp.persist(path).map(drop)) {
        if !clobber {
            let _ = std::fs::remove_file(path);
        }
        return Err(Error::io(path, e.error));
    }
    Ok(())
}

/// `temp` moved to `path` where nothing is there (renameat2's NOREPLACE, or
/// a hard link): never an empty file in its place, even after kill -9. Where
/// the mount refuses both, `path` is claimed empty and `temp` handed back to
/// be renamed over it, under the caller's interrupt lock.
fn claimed(temp: NamedTempFile, path: &Path) -> Result<Option<NamedTempFile>> {
    match temp.persist_noclobber(path) {
        Ok(_) => Ok(None),
        Err(e) if e.error.kind() == std::io::ErrorKind::AlreadyExists => {
            Err(Error::io(path, e.error))
        }
        Err(e) => {
            std::fs::OpenOptions::new()
                .write(true)
                .create_new(true)
                .open(path)
                .map_err(|e| Error::io(path, e))?;
            Ok(Some(e.file))
        }
    }
}

/// `text` written over `path` whole, through a temporary file.
pub fn write_text(path: &Path, text: &str) -> Result<()> {
    write_text_as(path, text, None)
}

/// `text` over `path` through a temporary file given `mode` (where given)
/// before a byte is written: the text is never more readable than asked.
fn write_text_as(path: &Path, text: &str, mode: Option<std::fs::Permissions>) -> Result<()> {
    write_atomic(path, |writer, file| {
        use std::io::Write as _;
        if let Some(mode) = mode {
            writer
                .get_ref()
                .set_permissions(mode)
                .map_err(|e| Error::io(file, e))?;
        }
        writer
            .write_all(text.as_bytes())
            .map_err(|e| Error::io(file, e))
    })
}

/// `text` written whole over the file `path` names, through any link to
/// it (the link stays a link), keeping the file's permissions.
pub fn replace_text(path: &Path, text: &str) -> Result<()> {
    let real = std::fs::canonicalize(path).map_err(|e| Error::io(path, e))?;
    let mode = std::fs::metadata(&real)
        .map_err(|e| Error::io(&real, e))?
        .permissions();
    write_text_as(&real, text, Some(mode))
}

/// How old a temporary `.partial` file must be to count as left behind by a
/// killed render. A writer holds one only while encoding a finished frame
/// (seconds), so anything this old belongs to no live process.
pub const STALE_PARTIAL_AGE: std::time::Duration = std::time::Duration::from_secs(600);

/// The temporary files in `dir` (any writer's, any version's), each with
/// whether its writer is gone: a dead process on this machine, or older than
/// `STALE_PARTIAL_AGE`.
pub(crate) fn partials(dir: &Path) -> Result<Vec<(PathBuf, String, bool)>> {
    let entries = std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))?;
    Ok(entries
        .filter_map(|e| e.ok())
        .filter_map(|entry| {
            let name = entry.file_name().to_string_lossy().into_owned();
            // Every `write_atomic` temporary (frames, job file, checkpoints,
            // claims, sheets), and earlier versions' names too.
            if !(name.starts_with('.') && name.ends_with(".partial")) {
                return None;
            }
            let age = file_age(&entry.path());
            let stale = writer_is_dead_here(name.trim_end_matches(".partial"))
                || age.is_some_and(|a| a >= STALE_PARTIAL_AGE);
            Some((entry.path(), name, stale))
        })
        .collect())
}

/// Deletes temporary files in `dir` left by writers that are gone. Returns
/// how many went. Fresh ones of live writers may belong to a render running
/// beside this one and are left alone.
pub fn remove_stale_partials(dir: &Path) -> Result<usize> {
    Ok(partials(dir)?
        .into_iter()
        .filter(|(path, _, stale)| *stale && std::fs::remove_file(path).is_ok())
        .count())
}

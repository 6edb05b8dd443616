//! Writing a file all or nothing: into a hidden temporary file beside it, renamed into place.

use std::fs;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use super::io_error;
use crate::{Error, Result};

/// Writes `path` through `fill`, so that a failure never leaves a half-written file: into a
/// temporary file beside the file [`output_target`] names, renamed onto it.
pub(crate) fn write_atomically(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<()> {
    let target = output_target(path)?;
    let tmp = temp_path(&target)?;
    let written = write_to(&tmp, fill).and_then(|()| fs::rename(&tmp, &target));
    if let Err(e) = written {
        // Best effort: the temporary file may not exist if creating it failed.
        let _ = fs::remove_file(&tmp);
        return Err(io_error(path, &e));
    }
    Ok(())
}

/// Symbolic links followed at most this many times (as Linux's `ELOOP` limit).
const MAX_LINKS: usize = 40;

/// The file a write to `path` replaces: `path` itself, or, when `path` is a symbolic link, the
/// file its chain of links leads to (which need not exist yet), so that the link stays a link
/// and the file it names gets the new content.
///
/// Errors ([`Error::Io`] naming `path`): an existing target that is not a regular file (a
/// folder, a device such as `/dev/full`, a FIFO, a socket: writing replaces the file with a
/// regular one, which would destroy such a target), a chain of more than 40 links.
pub fn output_target(path: &Path) -> Result<PathBuf> {
    let refuse = |reason: String| Error::Io {
        path: path.display().to_string(),
        reason,
    };
    if let Ok(meta) = fs::metadata(path) {
        if !meta.is_file() {
            return Err(refuse(format!(
                "is {}, not a regular file: outputs replace regular files only",
                file_kind(&meta.file_type())
            )));
        }
    }
    let mut target = path.to_path_buf();
    for _ in 0..MAX_LINKS {
        match fs::symlink_metadata(&target) {
            Ok(meta) if meta.file_type().is_symlink() => {
                let next = fs::read_link(&target).map_err(|e| io_error(path, &e))?;
                target = match target.parent() {
                    Some(dir) if next.is_relative() => dir.join(next),
                    _ => next,
                };
            }
            _ => return Ok(target),
        }
    }
    Err(refuse(format!(
        "more than {MAX_LINKS} symbolic links in a row"
    )))
}

/// "a folder", "a character device", ... for messages.
fn file_kind(t: &fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    if t.is_dir() {
        "a folder"
    } else {
        "a special file"
    }
}

fn write_to(
    tmp: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let mut out = BufWriter::new(fs::File::create(tmp)?);
    fill(&mut out)?;
    let file = out.into_inner().map_err(|e| e.into_error())?;
    file.sync_all()
}

/// `.NAME.PID.COUNTER.part` next to `path`.
fn temp_path(path: &Path) -> Result<PathBuf> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let Some(name) = path.file_name() else {
        return Err(Error::Io {
            path: path.display().to_string(),
            reason: "not a file path".to_string(),
        });
    };
    let unique = COUNTER.fetch_add(1, Ordering::Relaxed);
    let mut tmp_name = std::ffi::OsString::from(".");
    tmp_name.push(name);
    tmp_name.push(format!(".{}.{unique}.part", std::process::id()));
    Ok(path.with_file_name(tmp_name))
}

/// The first face referring to a vertex `>= n_positions`, as an [`Error::InvalidArgument`].
pub(crate) fn check_face_indices(n_positions: usize, faces: &[[u32; 3]]) -> Result<()> {
    let bad = faces.iter().enumerate().find_map(|(t, f)| {
        f.iter()
            .find(|&&i| i as usize >= n_positions)
            .map(|&i| (t, i))
    });
    match bad {
        Some((t, i)) => Err(Error::InvalidArgument {
            name: "faces",
            reason: format!(
                "face {t} refers to vertex {i}, but there are only {n_positions} positions"
            ),
        }),
        None => Ok(()),
    }
}

/// The first vertex with a NaN or infinite coordinate, as an [`Error::InvalidArgument`]: no
/// format can read such a value back.
pub(crate) fn check_positions_finite(positions: &[[f64; 3]]) -> Result<()> {
    match positions
        .iter()
        .position(|p| p.iter().any(|c| !c.is_finite()))
    {
        Some(v) => Err(Error::InvalidArgument {
            name: "positions",
            reason: format!("vertex {v} has a NaN or infinite coordinate"),
        }),
        None => Ok(()),
    }
}

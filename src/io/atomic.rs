//! Writing a file all or nothing: into a hidden temporary file beside it, renamed into place.

use std::fs;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use super::io_error;
use crate::{Error, Result};

/// Writes `path` through `fill`, so that a failure never leaves a half-written file.
pub(crate) fn write_atomically(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<()> {
    let tmp = temp_path(path)?;
    let written = write_to(&tmp, fill).and_then(|()| fs::rename(&tmp, path));
    if let Err(e) = written {
        // Best effort: the temporary file may not exist if creating it failed.
        let _ = fs::remove_file(&tmp);
        return Err(io_error(path, &e));
    }
    Ok(())
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

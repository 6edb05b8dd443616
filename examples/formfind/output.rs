//! All-or-nothing output: every file is first written to a hidden temporary file beside its
//! destination, and only when all of them are written are they renamed into place. On any
//! failure (or drop without commit) the temporary files and the folders created for them are
//! removed, so a failed run leaves nothing behind.

use std::fs;
use std::path::{Path, PathBuf};

#[derive(Default)]
pub struct Staging {
    /// (temporary, final) paths of the files written so far.
    files: Vec<(PathBuf, PathBuf)>,
    /// Folders this run created, outermost first.
    created: Vec<PathBuf>,
    committed: bool,
}

fn describe(path: &Path, e: impl std::fmt::Display) -> String {
    format!("{}: {e}", path.display())
}

impl Staging {
    /// Creates `dir` and its missing ancestors, remembering which ones were new.
    pub fn ensure_dir(&mut self, dir: &Path) -> Result<(), String> {
        let mut missing = Vec::new();
        let mut d = Some(dir);
        while let Some(p) = d.filter(|p| !p.as_os_str().is_empty() && !p.exists()) {
            missing.push(p.to_path_buf());
            d = p.parent();
        }
        for p in missing.into_iter().rev() {
            fs::create_dir(&p).map_err(|e| describe(&p, e))?;
            self.created.push(p);
        }
        if !dir.as_os_str().is_empty() && !dir.is_dir() {
            return Err(describe(dir, "exists and is not a folder"));
        }
        Ok(())
    }

    /// A temporary path beside `target` (in the same folder, so renaming it is atomic).
    fn temp_for(&mut self, target: &Path) -> Result<PathBuf, String> {
        let name = target
            .file_name()
            .ok_or_else(|| describe(target, "not a file path"))?;
        self.ensure_dir(target.parent().unwrap_or(Path::new("")))?;
        let mut tmp = std::ffi::OsString::from(".");
        tmp.push(name);
        tmp.push(format!(".formfind-{}.tmp", std::process::id()));
        let tmp = target.with_file_name(tmp);
        self.files.push((tmp.clone(), target.to_path_buf()));
        Ok(tmp)
    }

    /// Stages `bytes` for `target`.
    pub fn write(&mut self, target: &Path, bytes: &[u8]) -> Result<(), String> {
        let tmp = self.temp_for(target)?;
        fs::write(&tmp, bytes).map_err(|e| describe(target, e))
    }

    /// Stages an OBJ mesh for `target`, written by the library.
    pub fn write_obj(
        &mut self,
        target: &Path,
        positions: &[[f64; 3]],
        faces: &[[u32; 3]],
    ) -> Result<(), String> {
        let tmp = self.temp_for(target)?;
        voussoir::io::write_obj(&tmp, positions, faces).map_err(|e| describe(target, e))
    }

    /// Stages a mesh for `target` in the format of its extension, written by the library.
    pub fn write_mesh(
        &mut self,
        target: &Path,
        positions: &[[f64; 3]],
        faces: &[[u32; 3]],
    ) -> Result<(), String> {
        let format = voussoir::io::MeshFormat::from_path(target).map_err(|e| e.to_string())?;
        let tmp = self.temp_for(target)?;
        voussoir::io::write_mesh_as(&tmp, format, positions, faces).map_err(|e| describe(target, e))
    }

    /// Renames every staged file into place.
    pub fn commit(mut self) -> Result<(), String> {
        for (tmp, target) in &self.files {
            fs::rename(tmp, target).map_err(|e| describe(target, e))?;
        }
        self.committed = true;
        Ok(())
    }
}

impl Drop for Staging {
    fn drop(&mut self) {
        if self.committed {
            return;
        }
        for (tmp, _) in &self.files {
            // Best effort: a file may not exist if writing it failed early.
            let _ = fs::remove_file(tmp);
        }
        for dir in self.created.iter().rev() {
            // Only removes folders left empty.
            let _ = fs::remove_dir(dir);
        }
    }
}

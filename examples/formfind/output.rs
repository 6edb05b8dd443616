//! All-or-nothing output.
//!
//! Before the run, [`check`] looks at every target: no two name the same file (or one a folder
//! holding the other), none is a folder, a device, a FIFO or an input file, and each one's
//! folder exists or can be created. After the run, [`Staging`] writes every file to a hidden
//! temporary file beside its target (beside the file a symbolic link names: links are written
//! through); only when all are written are they renamed into place, each replaced file first
//! kept under a hidden name. On any failure (or a drop without commit) the temporary files,
//! the folders created for them and the files already renamed are removed and the replaced
//! files restored, so a failed run leaves the file system as it found it.

use std::ffi::OsString;
use std::fs;
use std::path::{Component, Path, PathBuf};

/// An output file and the option that names it (for messages).
pub struct Target {
    pub option: String,
    pub path: PathBuf,
}

fn describe(path: &Path, e: impl std::fmt::Display) -> String {
    format!("{}: {e}", path.display())
}

/// `path` absolute, with `.` and `..` resolved and its longest existing ancestor canonical
/// (symbolic links resolved), so that two spellings of one file compare equal.
fn resolved(path: &Path) -> PathBuf {
    let absolute = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let mut lexical = PathBuf::new();
    for c in absolute.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                lexical.pop();
            }
            other => lexical.push(other),
        }
    }
    let mut rest = Vec::new();
    let mut base = lexical.as_path();
    loop {
        if let Ok(canonical) = fs::canonicalize(base) {
            return rest.iter().rev().fold(canonical, |p, c| p.join(c));
        }
        match (base.parent(), base.file_name()) {
            (Some(parent), Some(name)) => {
                rest.push(name.to_os_string());
                base = parent;
            }
            _ => return lexical,
        }
    }
}

/// The nearest ancestor of `path` that exists (`path` itself excluded).
fn existing_ancestor(path: &Path) -> Option<&Path> {
    path.ancestors()
        .skip(1)
        .find(|p| p.as_os_str().is_empty() || fs::symlink_metadata(p).is_ok())
}

/// The file a target's write replaces (through symbolic links), spelt so that two names of one
/// file compare equal.
fn file_key(path: &Path) -> PathBuf {
    resolved(&voussoir::io::output_target(path).unwrap_or_else(|_| path.to_path_buf()))
}

/// Whether `a` and `b` are one existing file (two hard links, or two spellings of its path).
fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if let (Ok(x), Ok(y)) = (fs::metadata(a), fs::metadata(b)) {
            return (x.dev(), x.ino()) == (y.dev(), y.ino());
        }
    }
    resolved(a) == resolved(b)
}

/// Checks every target before anything is computed or written: each names a regular file or
/// none yet (symbolic links are written through: see [`voussoir::io::output_target`]), in a
/// folder that exists or can be created; no two name the same file (or one a folder holding
/// the other); none names one of `inputs` (an option or argument and its path).
pub fn check(targets: &[Target], inputs: &[(&str, &Path)]) -> Result<(), String> {
    for t in targets {
        let shown = t.path.display();
        if t.path.file_name().is_none() {
            return Err(format!("{}: `{shown}` is not a file path", t.option));
        }
        if t.path.is_dir() {
            return Err(format!(
                "{}: `{shown}` is a folder; name a file to write",
                t.option
            ));
        }
        voussoir::io::output_target(&t.path).map_err(|e| format!("{}: {e}", t.option))?;
        if let Some(dir) = existing_ancestor(&t.path) {
            if !dir.as_os_str().is_empty() && !dir.is_dir() {
                return Err(format!(
                    "{}: `{}` is not a folder, so `{shown}` cannot be written",
                    t.option,
                    dir.display()
                ));
            }
        }
        let target = voussoir::io::output_target(&t.path).unwrap_or_else(|_| t.path.clone());
        if let Some((input, _)) = inputs.iter().find(|(_, p)| same_file(&target, p)) {
            return Err(format!(
                "{} `{shown}` names the input file of {input}: writing it would destroy the \
                 input; give the output another path",
                t.option
            ));
        }
    }
    check_distinct(targets)
}

/// No two targets name the same file, and none lies inside another.
fn check_distinct(targets: &[Target]) -> Result<(), String> {
    let keys: Vec<PathBuf> = targets.iter().map(|t| file_key(&t.path)).collect();
    for (i, a) in targets.iter().enumerate() {
        for (j, b) in targets.iter().enumerate().skip(i + 1) {
            let (ka, kb) = (&keys[i], &keys[j]);
            if ka == kb {
                return Err(format!(
                    "{} and {} name the same file `{}`; give each output its own path",
                    a.option,
                    b.option,
                    b.path.display()
                ));
            }
            let (outer, inner) = match (kb.starts_with(ka), ka.starts_with(kb)) {
                (true, _) => (a, b),
                (_, true) => (b, a),
                _ => continue,
            };
            return Err(format!(
                "{} `{}` and {} `{}` clash: the first would have to be a folder",
                outer.option,
                outer.path.display(),
                inner.option,
                inner.path.display()
            ));
        }
    }
    Ok(())
}

/// A hidden name beside `target`: `.NAME.formfind-PID.SUFFIX`.
fn hidden_beside(target: &Path, suffix: &str) -> Result<PathBuf, String> {
    let name = target
        .file_name()
        .ok_or_else(|| describe(target, "not a file path"))?;
    let mut hidden = OsString::from(".");
    hidden.push(name);
    hidden.push(format!(".formfind-{}.{suffix}", std::process::id()));
    Ok(target.with_file_name(hidden))
}

#[derive(Default)]
pub struct Staging {
    /// (temporary, final) paths of the files written so far.
    files: Vec<(PathBuf, PathBuf)>,
    /// Folders this run created, outermost first.
    created: Vec<PathBuf>,
    /// (kept copy, target) of the files a commit is replacing.
    kept: Vec<(PathBuf, PathBuf)>,
    /// Targets a commit has renamed into place.
    placed: Vec<PathBuf>,
    committed: bool,
}

impl Staging {
    /// Creates `dir` and its missing ancestors, remembering which ones were new.
    fn ensure_dir(&mut self, dir: &Path) -> Result<(), String> {
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

    /// A temporary path beside the file `target` names (through symbolic links; in the same
    /// folder, so renaming it is atomic).
    fn temp_for(&mut self, target: &Path) -> Result<PathBuf, String> {
        let real = voussoir::io::output_target(target).map_err(|e| e.to_string())?;
        let tmp = hidden_beside(&real, "tmp")?;
        self.ensure_dir(real.parent().unwrap_or(Path::new("")))?;
        self.files.push((tmp.clone(), real));
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

    /// Stages a mesh for `target` in the format of its extension (STL and PLY as ASCII text
    /// when `ascii`), written by the library.
    pub fn write_mesh(
        &mut self,
        target: &Path,
        positions: &[[f64; 3]],
        faces: &[[u32; 3]],
        ascii: bool,
    ) -> Result<(), String> {
        let mut format = voussoir::io::MeshFormat::from_path(target).map_err(|e| e.to_string())?;
        if ascii {
            format = format.ascii();
        }
        let tmp = self.temp_for(target)?;
        voussoir::io::write_mesh_as(&tmp, format, positions, faces).map_err(|e| describe(target, e))
    }

    /// Keeps a copy of every file about to be replaced (a second link to it, or a copy where
    /// the file system has no links), then renames every staged file into place.
    pub fn commit(mut self) -> Result<(), String> {
        let targets: Vec<PathBuf> = self.files.iter().map(|(_, t)| t.clone()).collect();
        for target in targets.iter().filter(|t| fs::symlink_metadata(t).is_ok()) {
            let kept = hidden_beside(target, "old")?;
            fs::hard_link(target, &kept)
                .or_else(|_| fs::copy(target, &kept).map(|_| ()))
                .map_err(|e| describe(target, e))?;
            self.kept.push((kept, target.clone()));
        }
        for (tmp, target) in &self.files {
            fs::rename(tmp, target).map_err(|e| describe(target, e))?;
            self.placed.push(target.clone());
        }
        for (kept, _) in &self.kept {
            // The new files are in place; a kept copy left behind is only clutter.
            let _ = fs::remove_file(kept);
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
        // Best effort throughout: a step that failed may have left some of these missing.
        for target in &self.placed {
            match self.kept.iter().find(|(_, t)| t == target) {
                Some((kept, _)) => drop(fs::rename(kept, target)),
                None => drop(fs::remove_file(target)),
            }
        }
        for (kept, target) in &self.kept {
            if !self.placed.contains(target) {
                // The target still holds the file itself.
                let _ = fs::remove_file(kept);
            }
        }
        for (tmp, _) in &self.files {
            let _ = fs::remove_file(tmp);
        }
        for dir in self.created.iter().rev() {
            // Only removes folders left empty.
            let _ = fs::remove_dir(dir);
        }
    }
}

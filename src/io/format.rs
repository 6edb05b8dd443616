//! One entry point for every mesh format, chosen by the file name's extension.

use std::fs;
use std::path::Path;

use super::{io_error, obj, off, ply, stl, threemf, write_obj, RawMesh};
use crate::{Error, Result};

/// A mesh file format. [`MeshFormat::from_path`] picks it from the extension
/// (case-insensitive): `.obj`, `.off`, `.stl`, `.ply`, `.3mf`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum MeshFormat {
    /// Wavefront OBJ (text).
    Obj,
    /// Object File Format, ASCII, as CGAL and Geomview read and write it.
    Off,
    /// STL, binary (the default for writing) or ASCII. Single precision by definition.
    Stl {
        /// Binary (`true`) or ASCII (`false`); detected when reading.
        binary: bool,
    },
    /// Stanford PLY, binary little-endian (the default for writing) or ASCII, positions as
    /// `double`.
    Ply {
        /// Binary little-endian (`true`) or ASCII (`false`); any encoding is read.
        binary: bool,
    },
    /// 3MF, a zip package of XML: written only, and only for closed meshes such as a
    /// [`crate::Solid`] (3MF holds solids).
    ThreeMf,
}

impl MeshFormat {
    /// The format named by `path`'s extension, with the binary encoding for STL and PLY. An
    /// unknown or missing extension is an [`Error::InvalidArgument`] naming it.
    pub fn from_path(path: &Path) -> Result<MeshFormat> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        match ext.as_deref() {
            Some("obj") => Ok(MeshFormat::Obj),
            Some("off") => Ok(MeshFormat::Off),
            Some("stl") => Ok(MeshFormat::Stl { binary: true }),
            Some("ply") => Ok(MeshFormat::Ply { binary: true }),
            Some("3mf") => Ok(MeshFormat::ThreeMf),
            other => Err(Error::InvalidArgument {
                name: "path",
                reason: format!(
                    "{}: {}; the mesh formats are .obj, .off, .stl and .ply (and .3mf, \
                     written only)",
                    path.display(),
                    match other {
                        Some(e) => format!("unknown extension `.{e}`"),
                        None => "no extension".to_string(),
                    }
                ),
            }),
        }
    }

    /// The same format with ASCII text instead of binary (STL and PLY; OBJ and OFF are text).
    pub fn ascii(self) -> MeshFormat {
        match self {
            MeshFormat::Stl { .. } => MeshFormat::Stl { binary: false },
            MeshFormat::Ply { .. } => MeshFormat::Ply { binary: false },
            other => other,
        }
    }

    /// Whether the format stores positions in single precision (STL), so that a written
    /// mesh reads back rounded to `f32`.
    pub fn is_single_precision(self) -> bool {
        matches!(self, MeshFormat::Stl { .. })
    }
}

/// Reads the vertices and triangles of a mesh file in the format of its extension (see
/// [`MeshFormat::from_path`]); polygons are split into fans `(p0, p[i], p[i+1])`.
///
/// The vertices are those of the file, in its order: an STL file has three per triangle
/// (vertex `3t + k` is corner `k` of triangle `t`), so STL input needs [`super::weld`]
/// before it makes a mesh. Errors name the line (text) or the element (binary) at fault:
/// truncated files, garbage, counts that disagree with the content, indices out of range,
/// NaN or infinite coordinates.
pub fn read_mesh(path: &Path) -> Result<RawMesh> {
    read_mesh_with_diagonals(path).map(|(mesh, _)| mesh)
}

/// [`read_mesh`], plus the diagonals that split the file's polygons into triangles, as vertex
/// pairs (none for STL): edges of the triangulation that are not edges of the model.
pub fn read_mesh_with_diagonals(path: &Path) -> Result<(RawMesh, Vec<[u32; 2]>)> {
    let format = MeshFormat::from_path(path)?;
    match format {
        MeshFormat::Obj => return obj::read_obj_split(path),
        MeshFormat::ThreeMf => {
            return Err(Error::InvalidArgument {
                name: "path",
                reason: format!(
                    "{}: 3MF is written, not read; read .obj, .off, .stl or .ply",
                    path.display()
                ),
            })
        }
        _ => {}
    }
    let bytes = fs::read(path).map_err(|e| io_error(path, &e))?;
    let label = path.display().to_string();
    match format {
        MeshFormat::Off => off::parse_off_split(&bytes, &label),
        MeshFormat::Stl { .. } => Ok((stl::parse_stl(&bytes, &label)?, Vec::new())),
        _ => ply::parse_ply_split(&bytes, &label),
    }
}

/// Writes `positions` and `faces` (0-based) in the format of `path`'s extension (see
/// [`MeshFormat::from_path`]; STL and PLY binary), all or nothing, as [`write_mesh_as`].
pub fn write_mesh(path: &Path, positions: &[[f64; 3]], faces: &[[u32; 3]]) -> Result<()> {
    write_mesh_as(path, MeshFormat::from_path(path)?, positions, faces)
}

/// Writes `positions` and `faces` (0-based) to `path` in `format`, whatever its extension.
///
/// Text formats write each coordinate as the shortest decimal that reads back to the same
/// `f64` (at most 17 significant digits), and PLY binary as `double`, so OBJ, OFF and PLY
/// keep positions bit for bit. STL stores `f32` by definition: positions are rounded to
/// single precision (about 7 significant digits), enough to look at or print a shape but
/// not to keep its equilibrium. 3MF writes shortest decimals too, and needs a closed mesh
/// (every edge shared by two faces in opposite directions). The file is written to a
/// temporary file in the same folder and renamed over `path`, so a failure never leaves a
/// half-written file; a symbolic link is written through (the file it leads to is replaced,
/// the link kept), and a target that is not a regular file (a device, a FIFO, a folder) is
/// refused ([`super::output_target`]). A face index `>= positions.len()` or a non-finite
/// coordinate is an [`Error::InvalidArgument`].
pub fn write_mesh_as(
    path: &Path,
    format: MeshFormat,
    positions: &[[f64; 3]],
    faces: &[[u32; 3]],
) -> Result<()> {
    super::atomic::check_face_indices(positions.len(), faces)?;
    super::atomic::check_positions_finite(positions)?;
    match format {
        MeshFormat::Obj => write_obj(path, positions, faces),
        MeshFormat::Off => off::write_off(path, positions, faces),
        MeshFormat::Stl { binary } => stl::write_stl(path, positions, faces, binary),
        MeshFormat::Ply { binary } => ply::write_ply(path, positions, faces, binary),
        MeshFormat::ThreeMf => threemf::write_3mf(path, positions, faces),
    }
}

//! Mesh files (OBJ, OFF, STL, PLY, chosen by extension through [`read_mesh`] and
//! [`write_mesh`]; 3MF for closed solids, written only), welding of duplicated vertices
//! ([`weld`]), a JSON sidecar listing the anchored (support) vertices, and [`read_model`],
//! which makes a [`crate::Problem`] of a file: the read path of every layer. An assessment's
//! other files: [`read_surface`] (intrados, extrados) and [`read_load_pattern`].
//!
//! ```no_run
//! use voussoir::io::{read_model, ReadOptions, Supports};
//! let options = ReadOptions::new(Supports::Boundary).with_weld_tolerance(Some(1e-6));
//! let model = read_model("models/hex.stl".as_ref(), &options)?;
//! let mesh = &model.problem.mesh;
//! println!("{} vertices, {} holes", mesh.n_vertices(), mesh.holes().count());
//! # Ok::<(), voussoir::Error>(())
//! ```

mod assessment;
mod atomic;
mod format;
#[cfg(test)]
mod format_tests;
mod model;
mod obj;
mod off;
mod ply;
mod ply_data;
mod ply_header;
mod stl;
mod supports;
#[cfg(test)]
mod tests;
mod threemf;
mod weld;
#[cfg(test)]
mod weld_tests;

use std::path::Path;

use crate::{Problem, Result};

pub use assessment::{read_load_pattern, read_surface};
pub use atomic::output_target;
pub use format::{read_mesh, read_mesh_with_diagonals, write_mesh, write_mesh_as, MeshFormat};
pub use model::{read_model, Model, ReadOptions, Supports, UpAxis, WeldSummary};
pub use obj::{parse_obj, read_obj, write_obj, IGNORED_KEYWORDS};
pub use off::parse_off;
pub use ply::parse_ply;
pub use stl::parse_stl;
pub use supports::{parse_supports, read_supports};
pub use weld::{weld, Welded, DEFAULT_WELD_TOLERANCE};

/// Vertex positions (x, y plan; z height) and triangles (0-based vertex ids), as read from a
/// file, before validation by [`crate::Mesh::new`].
pub type RawMesh = (Vec<[f64; 3]>, Vec<[u32; 3]>);

/// A [`RawMesh`] and the diagonals that split its polygons (vertex pairs).
type SplitMesh = (RawMesh, Vec<[u32; 2]>);

/// Appends the fan `(p0, p[i], p[i+1])` of `polygon` to `faces` and the diagonals `(p0, p[i])`,
/// 2 ≤ i ≤ n − 2, that the split adds to `diagonals`.
fn split_fan(polygon: &[u32], faces: &mut Vec<[u32; 3]>, diagonals: &mut Vec<[u32; 2]>) {
    for k in 1..polygon.len() - 1 {
        faces.push([polygon[0], polygon[k], polygon[k + 1]]);
        if k > 1 {
            diagonals.push([polygon[0], polygon[k]]);
        }
    }
}

/// A vertex that `polygon` lists twice, if any (in O(n log n) for long polygons).
fn repeated_vertex(polygon: &[u32]) -> Option<u32> {
    if polygon.len() <= 8 {
        let n = polygon.len();
        return (0..n).find_map(|i| polygon[i + 1..].contains(&polygon[i]).then_some(polygon[i]));
    }
    let mut sorted = polygon.to_vec();
    sorted.sort_unstable();
    sorted.windows(2).find(|w| w[0] == w[1]).map(|w| w[0])
}

/// Why a face that lists `vertex` twice is refused (as the file numbers it).
fn repeated_vertex_message(vertex: impl std::fmt::Display) -> String {
    format!(
        "lists vertex {vertex} twice: each corner of a face is a different vertex (remove the \
         repeated one, or the face if it has fewer than 3 vertices left)"
    )
}

/// At most 40 characters of `text`, control and invisible characters escaped, with `…`
/// where it is cut: what an error message quotes of a line or token.
fn excerpt(text: &str) -> String {
    const MAX: usize = 40;
    let mut out = String::new();
    for (k, c) in text.chars().enumerate() {
        if k == MAX {
            out.push('…');
            break;
        }
        let invisible = matches!(c, '\u{200b}'..='\u{200f}' | '\u{2060}' | '\u{feff}');
        if c.is_control() || invisible {
            out.extend(c.escape_unicode());
        } else {
            out.push(c);
        }
    }
    out
}

/// [`read_model`] of a mesh file (any format) with its JSON supports file and the default
/// options: the problem alone.
pub fn load_model(mesh: &Path, supports: &Path) -> Result<Problem> {
    let options = ReadOptions::new(Supports::File(supports.to_path_buf()));
    read_model(mesh, &options).map(|m| m.problem)
}

/// A crate's error message on one line (some span several, with tabs).
fn one_line(e: &dyn std::fmt::Display) -> String {
    e.to_string()
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
}

/// The `Error::Io` for `path`.
fn io_error(path: &Path, err: &std::io::Error) -> crate::Error {
    crate::Error::Io {
        path: path.display().to_string(),
        reason: err.to_string(),
    }
}

//! Wavefront OBJ: `v x y z` vertices and `f` faces (triangulated as a fan).

use std::fs;
use std::path::Path;

use super::{excerpt, io_error, repeated_vertex, repeated_vertex_message, split_fan, RawMesh};
use crate::{Error, Result};

/// Reads the vertices and faces of an OBJ file (see [`parse_obj`]). Bytes that are not
/// UTF-8 are replaced (they can only occur in comments or malformed lines).
pub fn read_obj(path: &Path) -> Result<RawMesh> {
    read_obj_split(path).map(|(mesh, _)| mesh)
}

/// [`read_obj`], plus the diagonals that split its polygons.
pub(crate) fn read_obj_split(path: &Path) -> Result<(RawMesh, Vec<[u32; 2]>)> {
    let bytes = fs::read(path).map_err(|e| io_error(path, &e))?;
    parse_obj_split(
        &String::from_utf8_lossy(&bytes),
        &path.display().to_string(),
    )
}

/// OBJ statements that carry nothing the solver uses: skipped by [`parse_obj`] (as are
/// comments and blank lines).
pub const IGNORED_KEYWORDS: [&str; 9] = ["vn", "vt", "vp", "g", "o", "s", "usemtl", "mtllib", "l"];

/// Parses OBJ text (lines ending in LF, CR LF or CR): `v x y z` lines give vertices (up to
/// four numbers after them, `w` or colours `r g b`, are ignored), `f` lines give faces with 1-based indices, in any of the forms `i`, `i/t`,
/// `i//n`, `i/t/n`; negative indices count back from the last vertex read so far. Polygons
/// are split into a fan of triangles `(p0, p[i], p[i+1])`. Blank lines, comments (`#`) and
/// the statements in [`IGNORED_KEYWORDS`] (normals, texture coordinates, groups, materials,
/// lines) are ignored; a byte-order mark at the start of the text is skipped.
///
/// Errors are [`Error::Parse`] with `path_label` and the 1-based line: any other statement
/// (a misspelt `F`, `f,`, a keyword behind an invisible character: skipping it would drop a
/// face or a vertex unseen), a vertex with fewer than 3 coordinates, a bad number, or anything but up to four numbers
/// after its coordinates (`v 0 0 0 v 1 0 0`: statements run together), a face
/// with fewer than 3 vertices or with a vertex listed twice (`f 1 2 2`: a face without area,
/// which a mesh cannot hold; the message says to remove the repeated vertex), an index that is
/// not an integer, is 0, or refers past the last vertex of the file (or, when negative, before
/// the first vertex).
pub fn parse_obj(text: &str, path_label: &str) -> Result<RawMesh> {
    parse_obj_split(text, path_label).map(|(mesh, _)| mesh)
}

/// [`parse_obj`], plus the diagonals that split its polygons (vertex pairs).
pub(crate) fn parse_obj_split(text: &str, path_label: &str) -> Result<(RawMesh, Vec<[u32; 2]>)> {
    let err = |line: usize, reason: String| Error::Parse {
        path: path_label.to_string(),
        line,
        reason,
    };
    let mut positions: Vec<[f64; 3]> = Vec::new();
    let mut faces: Vec<[u32; 3]> = Vec::new();
    // Faces referring to vertices not yet read: (line, largest 0-based index), checked at the end.
    let mut forward_refs: Vec<(usize, u64)> = Vec::new();
    let mut polygon: Vec<u32> = Vec::new();
    let mut diagonals: Vec<[u32; 2]> = Vec::new();

    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    // Classic Mac OS ends lines with CR alone: read as one line, its vertices would be lost.
    let text: std::borrow::Cow<str> = if text.contains('\r') {
        text.replace("\r\n", "\n").replace('\r', "\n").into()
    } else {
        text.into()
    };
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let content = raw.split('#').next().unwrap_or("");
        let mut tokens = content.split_whitespace();
        match tokens.next() {
            Some("v") => {
                let mut p = [0.0; 3];
                for (k, c) in p.iter_mut().enumerate() {
                    let Some(tok) = tokens.next() else {
                        return Err(err(
                            line,
                            format!("vertex has {k} coordinates, 3 are needed (v x y z)"),
                        ));
                    };
                    *c = tok.parse::<f64>().map_err(|_| {
                        err(line, format!("bad number `{}` in vertex", excerpt(tok)))
                    })?;
                }
                check_vertex_extras(tokens).map_err(|r| err(line, r))?;
                positions.push(p);
            }
            Some("f") => {
                polygon.clear();
                let mut largest = 0u64;
                for tok in tokens {
                    let index = resolve_index(tok, positions.len()).map_err(|r| err(line, r))?;
                    largest = largest.max(u64::from(index));
                    polygon.push(index);
                }
                if polygon.len() < 3 {
                    return Err(err(
                        line,
                        format!("face has {} vertices, at least 3 are needed", polygon.len()),
                    ));
                }
                if let Some(v) = repeated_vertex(&polygon) {
                    let reason = format!("face {}", repeated_vertex_message(u64::from(v) + 1));
                    return Err(err(line, reason));
                }
                if largest >= positions.len() as u64 {
                    forward_refs.push((line, largest));
                }
                split_fan(&polygon, &mut faces, &mut diagonals);
            }
            Some(keyword) if IGNORED_KEYWORDS.contains(&keyword) => {}
            Some(keyword) => {
                return Err(err(
                    line,
                    format!(
                        "unknown statement `{}`: only v and f are read, and {} are skipped",
                        excerpt(keyword),
                        IGNORED_KEYWORDS.join(", ")
                    ),
                ))
            }
            None => {}
        }
    }
    let n = positions.len() as u64;
    if let Some(&(line, index)) = forward_refs.iter().find(|(_, index)| *index >= n) {
        return Err(err(
            line,
            format!(
                "face refers to vertex {}, but the file has only {n} vertices",
                index + 1
            ),
        ));
    }
    Ok(((positions, faces), diagonals))
}

/// The tokens after a vertex's x y z: at most four numbers (`w`, colours `r g b`), ignored;
/// anything else is statements run together on one line, whose vertices would be lost.
fn check_vertex_extras<'a>(
    tokens: impl Iterator<Item = &'a str>,
) -> std::result::Result<(), String> {
    for (k, tok) in tokens.enumerate() {
        if k >= 4 || tok.parse::<f64>().is_err() {
            return Err(format!(
                "`{}` after the vertex's coordinates: only up to four numbers (w, or colours \
                 r g b) may follow x y z, one statement per line",
                excerpt(tok)
            ));
        }
    }
    Ok(())
}

/// The 0-based vertex index of one face token (`i`, `i/t`, `i//n`, `i/t/n`), given the
/// number of vertices read so far (for negative, relative indices).
fn resolve_index(token: &str, n_so_far: usize) -> std::result::Result<u32, String> {
    let text = token.split('/').next().unwrap_or("");
    let value: i64 = text
        .parse()
        .map_err(|_| format!("bad vertex index `{}` in face", excerpt(token)))?;
    let index = match value {
        0 => return Err("vertex index 0 in face (OBJ indices start at 1)".to_string()),
        v if v > 0 => v - 1,
        v => {
            let resolved = n_so_far as i64 + v;
            if resolved < 0 {
                return Err(format!(
                    "relative vertex index {v} in face, but only {n_so_far} vertices are read so far"
                ));
            }
            resolved
        }
    };
    u32::try_from(index).map_err(|_| format!("vertex index {value} in face is too large"))
}

/// Writes vertices and faces (1-based) as OBJ. Coordinates are written with Rust's shortest
/// round-trip formatting, so [`read_obj`] gives back the same bits. The file is written as
/// [`super::write_mesh_as`] writes it: all or nothing, through symbolic links, never over a
/// device, FIFO or folder. A face index `>= positions.len()` is an [`Error::InvalidArgument`].
pub fn write_obj(path: &Path, positions: &[[f64; 3]], faces: &[[u32; 3]]) -> Result<()> {
    super::atomic::check_face_indices(positions.len(), faces)?;
    super::atomic::write_atomically(path, |out| {
        writeln!(out, "# {} vertices, {} faces", positions.len(), faces.len())?;
        for p in positions {
            writeln!(out, "v {:?} {:?} {:?}", p[0], p[1], p[2])?;
        }
        for f in faces {
            let [a, b, c] = f.map(|i| u64::from(i) + 1);
            writeln!(out, "f {a} {b} {c}")?;
        }
        Ok(())
    })
}

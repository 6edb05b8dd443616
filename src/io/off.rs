//! Object File Format, ASCII, as CGAL and Geomview write it: an `OFF` keyword, the counts
//! `nv nf [ne]`, one vertex `x y z` per line, then one face `n i0 ... i(n-1)` per line.

use std::path::Path;

use super::atomic::write_atomically;
use super::{excerpt, repeated_vertex, repeated_vertex_message, split_fan, RawMesh};
use crate::{Error, Result};

/// Parses OFF text. The keyword is `OFF` with the optional prefixes `ST` (texture
/// coordinates), `C` (colours) and `N` (normals), or absent; the counts may follow it on its
/// line. Values after `x y z` on a vertex line and after the indices on a face line (colours,
/// normals) are ignored; `#` starts a comment; blank lines are skipped. Face indices are
/// 0-based; polygons are split into fans.
///
/// Errors are [`Error::Parse`] with `path_label` and the 1-based line: binary or 4D OFF, a bad
/// or missing count, a vertex with fewer than 3 numbers or a NaN or infinite one, a face with
/// fewer than 3 vertices, fewer indices than it declares, a vertex listed twice or an index
/// out of range, a file that ends before the declared vertices and faces, or content after
/// them.
pub fn parse_off(bytes: &[u8], path_label: &str) -> Result<RawMesh> {
    parse_off_split(bytes, path_label).map(|(mesh, _)| mesh)
}

/// [`parse_off`], plus the diagonals that split its polygons (vertex pairs).
pub(crate) fn parse_off_split(bytes: &[u8], path_label: &str) -> Result<(RawMesh, Vec<[u32; 2]>)> {
    let text = String::from_utf8_lossy(bytes);
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, raw)| (i + 1, raw.split('#').next().unwrap_or("")))
        .filter(|(_, content)| !content.trim().is_empty());
    let err = |line: usize, reason: String| Error::Parse {
        path: path_label.to_string(),
        line,
        reason,
    };
    let last_line = text.lines().count();
    let eof = |what: String| err(last_line.max(1), format!("the file ends before {what}"));

    let (n_vertices, n_faces) = read_header(&mut lines, &err, &eof)?;
    let mut positions = Vec::new();
    for v in 0..n_vertices {
        let Some((line, content)) = lines.next() else {
            return Err(eof(format!("vertex {v} (it declares {n_vertices})")));
        };
        positions.push(parse_vertex(content, v).map_err(|r| err(line, r))?);
    }
    let (mut faces, mut diagonals) = (Vec::new(), Vec::new());
    for f in 0..n_faces {
        let Some((line, content)) = lines.next() else {
            return Err(eof(format!("face {f} (it declares {n_faces})")));
        };
        let polygon = parse_face(content, f, n_vertices).map_err(|r| err(line, r))?;
        split_fan(&polygon, &mut faces, &mut diagonals);
    }
    if let Some((line, _)) = lines.next() {
        return Err(err(
            line,
            format!(
                "content after the {n_vertices} vertices and {n_faces} faces the file declares"
            ),
        ));
    }
    Ok(((positions, faces), diagonals))
}

type Lines<'a> = dyn Iterator<Item = (usize, &'a str)> + 'a;

/// The keyword and the counts `nv nf [ne]`.
fn read_header<'a>(
    lines: &mut Lines<'a>,
    err: &dyn Fn(usize, String) -> Error,
    eof: &dyn Fn(String) -> Error,
) -> Result<(usize, usize)> {
    let Some((line, first)) = lines.next() else {
        return Err(eof("the OFF header".to_string()));
    };
    let mut tokens: Vec<&str> = first.split_whitespace().collect();
    let mut counts_line = line;
    if let Some(keyword) = tokens.first().copied().filter(|t| t.ends_with("OFF")) {
        check_keyword(keyword, tokens.get(1).copied()).map_err(|r| err(line, r))?;
        tokens.remove(0);
        if tokens.is_empty() {
            let Some((line, next)) = lines.next() else {
                return Err(eof("the counts line (vertices faces edges)".to_string()));
            };
            tokens = next.split_whitespace().collect();
            counts_line = line;
        }
    }
    let count = |k: usize, what: &str| -> Result<usize> {
        let tok = tokens.get(k).ok_or_else(|| {
            err(
                counts_line,
                format!("missing {what} count (expected `vertices faces [edges]`)"),
            )
        })?;
        tok.parse::<u32>().map(|n| n as usize).map_err(|_| {
            err(
                counts_line,
                format!(
                    "bad {what} count `{}` (expected `vertices faces [edges]`)",
                    excerpt(tok)
                ),
            )
        })
    };
    let n_vertices = count(0, "vertex")?;
    let n_faces = count(1, "face")?;
    if tokens.len() > 2 {
        count(2, "edge")?;
    }
    Ok((n_vertices, n_faces))
}

/// Accepts `[ST][C][N]OFF`; rejects the 4D, n-dimensional and binary variants by name.
fn check_keyword(keyword: &str, next: Option<&str>) -> std::result::Result<(), String> {
    let prefix = &keyword[..keyword.len() - 3];
    let rest = prefix.strip_prefix("ST").unwrap_or(prefix);
    let rest = rest.strip_prefix('C').unwrap_or(rest);
    let rest = rest.strip_prefix('N').unwrap_or(rest);
    if !rest.is_empty() {
        return Err(format!(
            "`{}` is not a supported OFF variant (3D [ST][C][N]OFF only)",
            excerpt(keyword)
        ));
    }
    if next == Some("BINARY") {
        return Err("binary OFF is not supported: write it as ASCII OFF".to_string());
    }
    Ok(())
}

fn parse_vertex(content: &str, v: usize) -> std::result::Result<[f64; 3], String> {
    let mut tokens = content.split_whitespace();
    let mut p = [0.0; 3];
    for (k, c) in p.iter_mut().enumerate() {
        let tok = tokens
            .next()
            .ok_or_else(|| format!("vertex {v} has {k} coordinates, 3 are needed"))?;
        *c = tok
            .parse::<f64>()
            .map_err(|_| format!("vertex {v}: bad number `{}`", excerpt(tok)))?;
        if !c.is_finite() {
            return Err(format!(
                "vertex {v}: coordinate `{}` is not finite",
                excerpt(tok)
            ));
        }
    }
    Ok(p)
}

/// The vertex ids of face `f`.
fn parse_face(content: &str, f: usize, n_vertices: usize) -> std::result::Result<Vec<u32>, String> {
    let mut tokens = content.split_whitespace();
    let first = tokens.next().unwrap_or("");
    let n: usize = first
        .parse()
        .map_err(|_| format!("face {f}: bad vertex count `{}`", excerpt(first)))?;
    if n < 3 {
        return Err(format!("face {f} has {n} vertices, at least 3 are needed"));
    }
    let mut polygon = Vec::with_capacity(n.min(64));
    for k in 0..n {
        let tok = tokens
            .next()
            .ok_or_else(|| format!("face {f} declares {n} vertices but lists {k}"))?;
        let index: u32 = tok
            .parse()
            .map_err(|_| format!("face {f}: bad vertex index `{}`", excerpt(tok)))?;
        if index as usize >= n_vertices {
            return Err(format!(
                "face {f} refers to vertex {index}, but the file has only {n_vertices} vertices"
            ));
        }
        polygon.push(index);
    }
    if let Some(v) = repeated_vertex(&polygon) {
        return Err(format!("face {f} {}", repeated_vertex_message(v)));
    }
    Ok(polygon)
}

/// Writes `OFF`, the counts, one `x y z` line per vertex (shortest round-trip decimals) and
/// one `3 a b c` line per face; CGAL's `read_polygon_mesh` reads it back exactly.
pub(crate) fn write_off(path: &Path, positions: &[[f64; 3]], faces: &[[u32; 3]]) -> Result<()> {
    write_atomically(path, |out| {
        writeln!(out, "OFF")?;
        writeln!(out, "{} {} 0", positions.len(), faces.len())?;
        for p in positions {
            writeln!(out, "{:?} {:?} {:?}", p[0], p[1], p[2])?;
        }
        for [a, b, c] in faces {
            writeln!(out, "3 {a} {b} {c}")?;
        }
        Ok(())
    })
}

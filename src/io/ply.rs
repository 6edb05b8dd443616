//! Stanford PLY, ASCII and binary: `vertex` elements with `x y z` and `face` elements with a
//! `vertex_indices` (or `vertex_index`) list. Read by the header and data readers of this
//! module's siblings (`ply_header`, `ply_data`), written by hand.

use std::path::Path;

use super::atomic::write_atomically;
use super::ply_data::{read_ascii, read_binary, Value};
use super::ply_header::{read_header, Element, Encoding, Header, Kind};
use super::{repeated_vertex, repeated_vertex_message, split_fan, RawMesh, SplitMesh};
use crate::{Error, Result};

/// Parses a PLY file in any of its encodings (ASCII, binary little- or big-endian). The
/// `vertex` element gives positions from its `x`, `y`, `z` properties (any numeric type;
/// other properties ignored); the `face` element gives polygons from its `vertex_indices`
/// or `vertex_index` list (any integer type, 0-based), split into fans. Other elements are
/// read and ignored. An ASCII line holds one element, with exactly the numbers its
/// properties take (a list: its count, then as many items).
///
/// Errors name the line (header and ASCII data, [`Error::Parse`]) or the element (binary data,
/// [`Error::Malformed`]): a malformed header (an unknown line or type, a count that is not a
/// whole number or does not fit in 64 bits), missing `x y z` or face list, a truncated file,
/// a bad or out-of-range number, a line with more or fewer numbers than its element takes, a
/// NaN or infinite coordinate, a face with fewer than 3 vertices, a repeated vertex or an
/// index out of range, content after the declared elements.
pub fn parse_ply(bytes: &[u8], path_label: &str) -> Result<RawMesh> {
    parse_ply_split(bytes, path_label).map(|(mesh, _)| mesh)
}

/// [`parse_ply`], plus the diagonals that split its polygons (vertex pairs).
pub(crate) fn parse_ply_split(bytes: &[u8], path_label: &str) -> Result<(RawMesh, Vec<[u32; 2]>)> {
    let parse_err = |(line, reason): (usize, String)| Error::Parse {
        path: path_label.to_string(),
        line,
        reason,
    };
    let malformed = |(element, reason): (String, String)| Error::Malformed {
        path: path_label.to_string(),
        element,
        reason,
    };
    let header = read_header(bytes).map_err(parse_err)?;
    let mut mesh = PlyMesh::new(&header).map_err(parse_err)?;
    let body = &bytes[header.len..];
    let mut take = |def: &Element, index: u64, values: &[Value]| mesh.add(def, index, values);
    match header.encoding {
        Encoding::Ascii => {
            read_ascii(&header.elements, body, header.lines + 1, &mut take).map_err(parse_err)?
        }
        encoding => read_binary(&header.elements, encoding, body, &mut take).map_err(malformed)?,
    }
    mesh.finish().map_err(malformed)
}

/// Positions and polygons gathered element by element, with where each face came from.
struct PlyMesh {
    /// The indices of `x`, `y`, `z` among the vertex element's properties.
    xyz: [usize; 3],
    /// The index of the face element's vertex list among its properties.
    list: Option<usize>,
    positions: Vec<[f64; 3]>,
    polygons: Vec<(u64, Vec<i64>)>,
}

impl PlyMesh {
    /// Finds the properties the mesh needs; errors are (line, reason).
    fn new(header: &Header) -> std::result::Result<PlyMesh, (usize, String)> {
        let find = |name: &str| header.elements.iter().find(|e| e.name == name);
        let Some(vertex) = find("vertex") else {
            return Err((header.lines, "bad header: no `vertex` element".into()));
        };
        let mut xyz = [0; 3];
        for (slot, name) in xyz.iter_mut().zip(["x", "y", "z"]) {
            *slot = vertex
                .properties
                .iter()
                .position(|p| p.name == name && matches!(p.kind, Kind::Scalar(_)))
                .ok_or_else(|| {
                    let reason = format!("bad header: element `vertex` has no number `{name}`");
                    (vertex.line, reason)
                })?;
        }
        let list = match find("face") {
            None => None,
            Some(face) => Some(
                face.properties
                    .iter()
                    .position(|p| {
                        ["vertex_indices", "vertex_index"].contains(&p.name.as_str())
                            && matches!(p.kind, Kind::List(_, item) if item.is_integer())
                    })
                    .ok_or_else(|| {
                        let reason = "bad header: element `face` has no integer list \
                                      `vertex_indices`"
                            .to_string();
                        (face.line, reason)
                    })?,
            ),
        };
        Ok(PlyMesh {
            xyz,
            list,
            positions: Vec::new(),
            polygons: Vec::new(),
        })
    }

    /// Takes what the mesh needs from one element (`index` within its kind).
    fn add(
        &mut self,
        def: &Element,
        index: u64,
        values: &[Value],
    ) -> std::result::Result<(), String> {
        match def.name.as_str() {
            "vertex" => {
                let mut p = [0.0; 3];
                for ((c, &k), name) in p.iter_mut().zip(&self.xyz).zip(["x", "y", "z"]) {
                    if let Value::Number(x) = values[k] {
                        *c = x;
                    }
                    if !c.is_finite() {
                        return Err(format!("vertex {index}: `{name}` is {c}, not finite"));
                    }
                }
                self.positions.push(p);
            }
            "face" => {
                if let Some(Value::List(items)) = self.list.map(|k| &values[k]) {
                    let list = items.iter().map(|&i| i as i64).collect();
                    self.polygons.push((index, list));
                }
            }
            _ => {}
        }
        Ok(())
    }

    /// Checks the polygons against the vertex count and splits them into fans.
    fn finish(self) -> std::result::Result<SplitMesh, (String, String)> {
        let n = self.positions.len();
        let (mut faces, mut diagonals) = (Vec::new(), Vec::new());
        let mut polygon = Vec::new();
        for (index, list) in &self.polygons {
            let name = || format!("face {index}");
            if list.len() < 3 {
                return Err((
                    name(),
                    format!("{} vertices, at least 3 are needed", list.len()),
                ));
            }
            if let Some(&i) = list.iter().find(|&&i| i < 0 || i as u64 >= n as u64) {
                return Err((
                    name(),
                    format!("refers to vertex {i}, but the file has {n} vertices"),
                ));
            }
            polygon.clear();
            polygon.extend(list.iter().map(|&i| i as u32));
            if let Some(v) = repeated_vertex(&polygon) {
                return Err((name(), repeated_vertex_message(v)));
            }
            split_fan(&polygon, &mut faces, &mut diagonals);
        }
        Ok(((self.positions, faces), diagonals))
    }
}

/// Writes PLY, binary little-endian or ASCII, with `double` positions (shortest round-trip
/// decimals in ASCII) and `uint` indices, so positions read back bit for bit. Written by hand:
/// the binary writer of `ply-rs-bw` 2.0 writes the element count as every list's length.
pub(crate) fn write_ply(
    path: &Path,
    positions: &[[f64; 3]],
    faces: &[[u32; 3]],
    binary: bool,
) -> Result<()> {
    let encoding = if binary {
        "binary_little_endian"
    } else {
        "ascii"
    };
    write_atomically(path, |out| {
        write!(
            out,
            "ply\nformat {encoding} 1.0\ncomment written by voussoir\n\
             element vertex {}\nproperty double x\nproperty double y\nproperty double z\n\
             element face {}\nproperty list uchar uint vertex_indices\nend_header\n",
            positions.len(),
            faces.len()
        )?;
        if binary {
            for p in positions {
                for c in p {
                    out.write_all(&c.to_le_bytes())?;
                }
            }
            for f in faces {
                out.write_all(&[3])?;
                for i in f {
                    out.write_all(&i.to_le_bytes())?;
                }
            }
        } else {
            for p in positions {
                writeln!(out, "{:?} {:?} {:?}", p[0], p[1], p[2])?;
            }
            for [a, b, c] in faces {
                writeln!(out, "3 {a} {b} {c}")?;
            }
        }
        Ok(())
    })
}

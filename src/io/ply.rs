//! Stanford PLY, ASCII and binary, through the `ply-rs-bw` crate: `vertex` elements with `x y
//! z` and `face` elements with a `vertex_indices` (or `vertex_index`) list.

use std::io::{BufRead, Cursor, Read};
use std::path::Path;

use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{DefaultElement, ElementDef, Encoding, Header, Property};

use super::atomic::write_atomically;
use super::{one_line, split_fan, RawMesh, SplitMesh};
use crate::{Error, Result};

/// Parses a PLY file in any of its encodings (ASCII, binary little- or big-endian). The
/// `vertex` element gives positions from its `x`, `y`, `z` properties (any numeric type;
/// other properties ignored); the `face` element gives polygons from its `vertex_indices`
/// or `vertex_index` list (any integer type, 0-based), split into fans. Other elements are
/// read and ignored.
///
/// Errors name the line (header and ASCII data, [`Error::Parse`]) or the element (binary data,
/// [`Error::Malformed`]): a malformed header, missing `x y z` or face list, a truncated file,
/// a bad number, a NaN or infinite coordinate, a face with fewer than 3 vertices or an index
/// out of range, content after the declared elements.
pub fn parse_ply(bytes: &[u8], path_label: &str) -> Result<RawMesh> {
    parse_ply_split(bytes, path_label).map(|(mesh, _)| mesh)
}

/// [`parse_ply`], plus the diagonals that split its polygons (vertex pairs).
pub(crate) fn parse_ply_split(bytes: &[u8], path_label: &str) -> Result<(RawMesh, Vec<[u32; 2]>)> {
    let parse_err = |line: usize, reason: String| Error::Parse {
        path: path_label.to_string(),
        line,
        reason,
    };
    let (header_end, header_lines) = find_header_end(bytes)
        .ok_or_else(|| parse_err(1, "not a PLY file: no `ply` ... `end_header` header".into()))?;
    let parser = Parser::<DefaultElement>::new();
    let header = parser
        .read_header(&mut Cursor::new(&bytes[..header_end]))
        .map_err(|e| parse_err(header_lines, format!("bad header: {}", one_line(&e))))?;
    let body = &bytes[header_end..];
    let mut mesh = PlyMesh::default();
    match header.encoding {
        Encoding::Ascii => read_ascii(&parser, &header, body, header_lines, &mut mesh)
            .map_err(|(line, reason)| parse_err(line, reason))?,
        encoding => read_binary(&parser, &header, encoding, body, &mut mesh).map_err(
            |(element, reason)| Error::Malformed {
                path: path_label.to_string(),
                element,
                reason,
            },
        )?,
    }
    mesh.finish(&header)
        .map_err(|(element, reason)| Error::Malformed {
            path: path_label.to_string(),
            element,
            reason,
        })
}

/// The byte offset just after the `end_header` line and the number of header lines.
fn find_header_end(bytes: &[u8]) -> Option<(usize, usize)> {
    if !bytes.starts_with(b"ply") {
        return None;
    }
    let mut offset = 0;
    for (i, line) in bytes.split_inclusive(|&b| b == b'\n').enumerate() {
        offset += line.len();
        if line.trim_ascii() == b"end_header" {
            return Some((offset, i + 1));
        }
    }
    None
}

/// Positions and polygons gathered element by element, with where each face came from.
#[derive(Default)]
struct PlyMesh {
    positions: Vec<[f64; 3]>,
    polygons: Vec<(String, Vec<i64>)>,
}

impl PlyMesh {
    /// Takes what the mesh needs from one element (`index` within its kind).
    fn add(
        &mut self,
        def: &ElementDef,
        element: &DefaultElement,
        index: usize,
    ) -> std::result::Result<(), String> {
        match def.name.as_str() {
            "vertex" => {
                let mut p = [0.0; 3];
                for (c, name) in p.iter_mut().zip(["x", "y", "z"]) {
                    *c = element.get(name).and_then(scalar).ok_or_else(|| {
                        format!("vertex {index} has no numeric `{name}` property")
                    })?;
                    if !c.is_finite() {
                        return Err(format!("vertex {index}: `{name}` is {c}, not finite"));
                    }
                }
                self.positions.push(p);
            }
            "face" => {
                let list = ["vertex_indices", "vertex_index"]
                    .iter()
                    .find_map(|name| element.get(*name))
                    .and_then(integer_list)
                    .ok_or_else(|| format!("face {index} has no integer `vertex_indices` list"))?;
                self.polygons.push((format!("face {index}"), list));
            }
            _ => {}
        }
        Ok(())
    }

    /// Checks the polygons against the vertex count and splits them into fans.
    fn finish(self, header: &Header) -> std::result::Result<SplitMesh, (String, String)> {
        if !header.elements.contains_key("vertex") {
            return Err(("header".into(), "no `vertex` element".into()));
        }
        let n = self.positions.len();
        let (mut faces, mut diagonals) = (Vec::new(), Vec::new());
        for (name, list) in &self.polygons {
            if list.len() < 3 {
                return Err((
                    name.clone(),
                    format!("{} vertices, at least 3 are needed", list.len()),
                ));
            }
            if let Some(&i) = list.iter().find(|&&i| i < 0 || i as usize >= n) {
                return Err((
                    name.clone(),
                    format!("refers to vertex {i}, but the file has {n} vertices"),
                ));
            }
            let polygon: Vec<u32> = list.iter().map(|&i| i as u32).collect();
            split_fan(&polygon, &mut faces, &mut diagonals);
        }
        Ok(((self.positions, faces), diagonals))
    }
}

fn scalar(p: &Property) -> Option<f64> {
    Some(match *p {
        Property::Char(x) => f64::from(x),
        Property::UChar(x) => f64::from(x),
        Property::Short(x) => f64::from(x),
        Property::UShort(x) => f64::from(x),
        Property::Int(x) => f64::from(x),
        Property::UInt(x) => f64::from(x),
        Property::Float(x) => f64::from(x),
        Property::Double(x) => x,
        _ => return None,
    })
}

fn integer_list(p: &Property) -> Option<Vec<i64>> {
    fn widen<T: Copy + Into<i64>>(list: &[T]) -> Vec<i64> {
        list.iter().map(|&x| x.into()).collect()
    }
    Some(match p {
        Property::ListChar(l) => widen(l),
        Property::ListUChar(l) => widen(l),
        Property::ListShort(l) => widen(l),
        Property::ListUShort(l) => widen(l),
        Property::ListInt(l) => widen(l),
        Property::ListUInt(l) => widen(l),
        _ => return None,
    })
}

/// One element per line; errors are (line, reason).
fn read_ascii(
    parser: &Parser<DefaultElement>,
    header: &Header,
    body: &[u8],
    header_lines: usize,
    mesh: &mut PlyMesh,
) -> std::result::Result<(), (usize, String)> {
    let mut lines = body.lines().enumerate();
    let mut last = header_lines;
    for def in header.elements.values() {
        for index in 0..def.count {
            let Some((i, line)) = lines.next() else {
                return Err((
                    last,
                    format!(
                        "the file ends before {} {index} (it declares {})",
                        def.name, def.count
                    ),
                ));
            };
            last = header_lines + i + 1;
            let line = line.map_err(|e| (last, one_line(&e)))?;
            let element = parser
                .read_ascii_element(&line, def)
                .map_err(|e| (last, format!("{} {index}: {}", def.name, one_line(&e))))?;
            mesh.add(def, &element, index).map_err(|r| (last, r))?;
        }
    }
    if let Some((i, _)) = lines.find(|(_, l)| l.as_ref().map_or(true, |l| !l.trim().is_empty())) {
        return Err((
            header_lines + i + 1,
            "content after the declared elements".into(),
        ));
    }
    Ok(())
}

/// Elements one after another; errors are (element, reason).
fn read_binary(
    parser: &Parser<DefaultElement>,
    header: &Header,
    encoding: Encoding,
    body: &[u8],
    mesh: &mut PlyMesh,
) -> std::result::Result<(), (String, String)> {
    let mut cursor = Cursor::new(body);
    for def in header.elements.values() {
        for index in 0..def.count {
            let name = || format!("{} {index}", def.name);
            if def.properties.is_empty() {
                // An element without properties takes no bytes.
                break;
            }
            if cursor.position() as usize >= body.len() {
                let reason = format!("the file ends before it (it declares {})", def.count);
                return Err((name(), reason));
            }
            let element = match encoding {
                Encoding::BinaryBigEndian => parser.read_big_endian_element(&mut cursor, def),
                _ => parser.read_little_endian_element(&mut cursor, def),
            }
            .map_err(|e| {
                (
                    name(),
                    format!(
                        "the file ends inside it or it is malformed: {}",
                        one_line(&e)
                    ),
                )
            })?;
            mesh.add(def, &element, index).map_err(|r| (name(), r))?;
        }
    }
    let rest = cursor.bytes().count();
    if rest > 0 {
        return Err((
            "end".into(),
            format!("{rest} bytes after the declared elements"),
        ));
    }
    Ok(())
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

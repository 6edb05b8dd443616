//! STL, binary and ASCII, through the `stl_io` crate: a soup of triangles in single precision.

use std::io::Cursor;
use std::path::Path;

use super::atomic::write_atomically;
use super::{excerpt, one_line, RawMesh};
use crate::{Error, Result};

/// Bytes of the binary header and triangle count, and of one binary triangle record.
const BINARY_HEADER: usize = 84;
const BINARY_TRIANGLE: usize = 50;

/// Parses an STL file, binary or ASCII: binary when its size is exactly that of the triangle
/// count in its header (whatever the header's first bytes say, since many binary exporters
/// begin it with `solid`), else ASCII when it begins with `solid`. Every triangle gives three
/// vertices, in order (vertex `3t + k` is corner `k` of triangle `t`); see [`super::weld`].
/// An ASCII file may hold several solids, read one after another; nothing but another solid
/// may follow an `endsolid`.
///
/// Errors name the triangle at fault in a binary file ([`Error::Malformed`]: truncated or
/// overlong, a NaN or infinite coordinate) and the line in an ASCII file ([`Error::Parse`]: a
/// statement out of place, a bad number, a NaN or infinite coordinate, content after
/// `endsolid`, a file that ends inside a solid), quoting at most a short excerpt of it.
pub fn parse_stl(bytes: &[u8], path_label: &str) -> Result<RawMesh> {
    let triangles = match binary_count(bytes) {
        Some(Ok(_)) => read_binary(bytes, path_label)?,
        Some(Err(reason)) if !starts_with_solid(bytes) => {
            return Err(malformed(path_label, "header", reason))
        }
        _ if starts_with_solid(bytes) => read_ascii(bytes, path_label)?,
        _ => {
            return Err(malformed(
                path_label,
                "header",
                format!(
                    "neither ASCII STL (it does not begin with `solid`) nor binary STL \
                     ({} bytes, fewer than the {BINARY_HEADER}-byte header)",
                    bytes.len()
                ),
            ))
        }
    };
    let mut positions = Vec::with_capacity(3 * triangles.len());
    for (t, triangle) in triangles.iter().enumerate() {
        for (k, v) in triangle.vertices.iter().enumerate() {
            if v.0.iter().any(|c| !c.is_finite()) {
                return Err(malformed(
                    path_label,
                    &format!("triangle {t}"),
                    format!("corner {k} has a NaN or infinite coordinate"),
                ));
            }
            positions.push(v.0.map(f64::from));
        }
    }
    let n = u32::try_from(triangles.len())
        .ok()
        .filter(|n| n.checked_mul(3).is_some())
        .ok_or_else(|| malformed(path_label, "header", "too many triangles".to_string()))?;
    let faces = (0..n).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect();
    Ok((positions, faces))
}

fn malformed(path_label: &str, element: &str, reason: String) -> Error {
    Error::Malformed {
        path: path_label.to_string(),
        element: element.to_string(),
        reason,
    }
}

fn starts_with_solid(bytes: &[u8]) -> bool {
    let start = bytes.iter().position(|b| !b.is_ascii_whitespace());
    start.is_some_and(|s| bytes[s..].starts_with(b"solid"))
}

/// `None` when shorter than a binary header; else the declared triangle count when the size
/// agrees with it, or why not.
fn binary_count(bytes: &[u8]) -> Option<std::result::Result<usize, String>> {
    let count_bytes: [u8; 4] = bytes.get(80..BINARY_HEADER)?.try_into().ok()?;
    let count = u32::from_le_bytes(count_bytes) as usize;
    let expected = BINARY_HEADER as u64 + BINARY_TRIANGLE as u64 * count as u64;
    Some(if expected == bytes.len() as u64 {
        Ok(count)
    } else {
        Err(format!(
            "binary STL declaring {count} triangles has {expected} bytes, this file has {} bytes",
            bytes.len()
        ))
    })
}

fn read_binary(bytes: &[u8], path_label: &str) -> Result<Vec<stl_io::Triangle>> {
    // stl_io takes a file beginning with `solid ` for ASCII: the header carries no data.
    let mut copy = bytes.to_vec();
    copy[..80].fill(0);
    read_triangles(&copy, path_label, 0)
}

/// The triangles of an ASCII file: one or more `solid` ... `endsolid` blocks of facets, read
/// line by line so that every fault names its line. Keywords are read in any case.
fn read_ascii(bytes: &[u8], path_label: &str) -> Result<Vec<stl_io::Triangle>> {
    let text = String::from_utf8_lossy(bytes);
    let mut reader = AsciiReader::default();
    let mut last = 0;
    for (i, line) in text.lines().enumerate() {
        last = i + 1;
        let tokens: Vec<&str> = line.split_ascii_whitespace().collect();
        if tokens.is_empty() {
            continue;
        }
        reader.line(&tokens).map_err(|reason| Error::Parse {
            path: path_label.to_string(),
            line: last,
            reason: format!("{reason} (`{}`)", excerpt(line.trim())),
        })?;
    }
    if let Some(expected) = reader.expected() {
        return Err(Error::Parse {
            path: path_label.to_string(),
            line: last.max(1),
            reason: format!("the file ends where {expected} is expected"),
        });
    }
    Ok(reader.triangles)
}

/// Where an ASCII STL reader stands: the statement it expects next.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
enum Expect {
    /// `solid` (the first line, or after `endsolid`).
    #[default]
    Solid,
    /// `facet normal` or `endsolid`.
    Facet,
    OuterLoop,
    /// The `k`th `vertex` line.
    Vertex(usize),
    EndLoop,
    EndFacet,
}

#[derive(Default)]
struct AsciiReader {
    expect: Expect,
    corners: [stl_io::Vertex; 3],
    triangles: Vec<stl_io::Triangle>,
}

impl AsciiReader {
    /// What the file must still hold, if it cannot end here.
    fn expected(&self) -> Option<String> {
        // A file read at all began with `solid`: at `Solid`, every solid has ended.
        match self.expect {
            Expect::Solid => None,
            other => Some(self.describe(other)),
        }
    }

    fn describe(&self, expect: Expect) -> String {
        let t = self.triangles.len();
        match expect {
            Expect::Solid => "`solid` (after `endsolid`, only another solid may follow)".into(),
            Expect::Facet => format!("`facet normal` for triangle {t} or `endsolid`"),
            Expect::OuterLoop => format!("`outer loop` of triangle {t}"),
            Expect::Vertex(k) => format!("`vertex x y z` for corner {k} of triangle {t}"),
            Expect::EndLoop => format!("`endloop` of triangle {t}"),
            Expect::EndFacet => format!("`endfacet` of triangle {t}"),
        }
    }

    /// Reads one non-blank line, split into tokens.
    fn line(&mut self, tokens: &[&str]) -> std::result::Result<(), String> {
        let is = |k: usize, word: &str| tokens.get(k).is_some_and(|t| t.eq_ignore_ascii_case(word));
        let wrong = |this: &Self| Err(format!("expected {}", this.describe(this.expect)));
        self.expect = match self.expect {
            Expect::Solid if is(0, "solid") => Expect::Facet,
            Expect::Facet if is(0, "endsolid") => Expect::Solid,
            Expect::Facet if is(0, "facet") && is(1, "normal") && tokens.len() == 5 => {
                for token in &tokens[2..] {
                    self.number("normal", token)?;
                }
                Expect::OuterLoop
            }
            Expect::OuterLoop if is(0, "outer") && is(1, "loop") && tokens.len() == 2 => {
                Expect::Vertex(0)
            }
            Expect::Vertex(k) if is(0, "vertex") && tokens.len() == 4 => {
                let mut p = [0f32; 3];
                for (c, token) in p.iter_mut().zip(&tokens[1..]) {
                    *c = self.number(&format!("corner {k}"), token)?;
                }
                if p.iter().any(|c| !c.is_finite()) {
                    return Err(format!(
                        "triangle {}: corner {k} has a NaN or infinite coordinate (in single \
                         precision)",
                        self.triangles.len()
                    ));
                }
                self.corners[k] = stl_io::Vertex::new(p);
                if k < 2 {
                    Expect::Vertex(k + 1)
                } else {
                    Expect::EndLoop
                }
            }
            Expect::EndLoop if is(0, "endloop") && tokens.len() == 1 => Expect::EndFacet,
            Expect::EndFacet if is(0, "endfacet") && tokens.len() == 1 => {
                self.triangles.push(stl_io::Triangle {
                    normal: stl_io::Normal::new([0.0; 3]),
                    vertices: self.corners,
                });
                Expect::Facet
            }
            _ => return wrong(self),
        };
        Ok(())
    }

    fn number(&self, what: &str, token: &str) -> std::result::Result<f32, String> {
        token.parse().map_err(|_| {
            format!(
                "triangle {}: {what}: `{}` is not a number",
                self.triangles.len(),
                excerpt(token)
            )
        })
    }
}

/// The triangles of one binary file or one ASCII solid; `first` numbers them in messages.
fn read_triangles(bytes: &[u8], path_label: &str, first: usize) -> Result<Vec<stl_io::Triangle>> {
    let mut cursor = Cursor::new(bytes);
    let reader = stl_io::create_stl_reader(&mut cursor)
        .map_err(|e| malformed(path_label, "header", one_line(&e)))?;
    let mut triangles = Vec::new();
    for (t, triangle) in reader.enumerate() {
        let triangle = triangle
            .map_err(|e| malformed(path_label, &format!("triangle {}", first + t), one_line(&e)))?;
        triangles.push(triangle);
    }
    Ok(triangles)
}

/// Writes binary STL (through `stl_io`) or ASCII STL; positions rounded to `f32`, normals
/// from the triangles' corners (zero for a degenerate triangle).
pub(crate) fn write_stl(
    path: &Path,
    positions: &[[f64; 3]],
    faces: &[[u32; 3]],
    binary: bool,
) -> Result<()> {
    let too_large = positions
        .iter()
        .position(|p| p.iter().any(|c| c.abs() > f64::from(f32::MAX)));
    if let Some(v) = too_large {
        return Err(Error::InvalidArgument {
            name: "positions",
            reason: format!("vertex {v} is beyond single precision, which STL stores"),
        });
    }
    let triangles: Vec<stl_io::Triangle> = faces
        .iter()
        .map(|f| triangle(f.map(|i| positions[i as usize])))
        .collect();
    write_atomically(path, |mut out| {
        if binary {
            return stl_io::write_stl(&mut out, triangles.iter());
        }
        writeln!(out, "solid voussoir")?;
        for t in &triangles {
            let [nx, ny, nz] = t.normal.0;
            writeln!(out, "facet normal {nx:?} {ny:?} {nz:?}")?;
            writeln!(out, "  outer loop")?;
            for v in &t.vertices {
                writeln!(out, "    vertex {:?} {:?} {:?}", v.0[0], v.0[1], v.0[2])?;
            }
            writeln!(out, "  endloop")?;
            writeln!(out, "endfacet")?;
        }
        writeln!(out, "endsolid voussoir")
    })
}

fn triangle([a, b, c]: [[f64; 3]; 3]) -> stl_io::Triangle {
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let n = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    let normal = if len > 0.0 {
        n.map(|x| (x / len) as f32)
    } else {
        [0.0; 3]
    };
    stl_io::Triangle {
        normal: stl_io::Normal::new(normal),
        vertices: [a, b, c].map(|p| stl_io::Vertex::new(p.map(|x| x as f32))),
    }
}

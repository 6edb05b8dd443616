//! A shared model written as PLY (ASCII or binary), OFF, STL (ASCII or binary) or OBJ, with one
//! of its header counts or face lines set to a value at a limit: each such file is invalid.

use super::{Model, Rng};

/// Values at the limits of the integer types of counts and indices, as text.
const LIMITS: [&str; 12] = [
    "0",
    "-1",
    "2147483647",
    "2147483648",
    "4294967295",
    "4294967296",
    "9223372036854775807",
    "9223372036854775808",
    "18446744073709551615",
    "18446744073709551616",
    "99999999999999999999999",
    "-9223372036854775809",
];

/// The model's vertices (coordinates as written) and faces (0-based).
fn parts(model: &Model) -> (Vec<[String; 3]>, Vec<[usize; 3]>) {
    let (mut vertices, mut faces) = (Vec::new(), Vec::new());
    for line in &model.lines {
        let t: Vec<&str> = line.split_whitespace().collect();
        match t.first() {
            Some(&"v") => vertices.push([t[1], t[2], t[3]].map(String::from)),
            Some(&"f") => {
                let ids: Vec<usize> = t[1..]
                    .iter()
                    .map(|i| i.parse::<usize>().unwrap() - 1)
                    .collect();
                faces.push([ids[0], ids[1], ids[2]]);
            }
            _ => {}
        }
    }
    (vertices, faces)
}

/// A count at a limit other than `actual`: one off either way, or a value from [`LIMITS`].
fn count_other_than(actual: usize, rng: &mut Rng) -> String {
    let candidates: Vec<String> = [actual + 1, actual.saturating_sub(1)]
        .iter()
        .map(usize::to_string)
        .chain(LIMITS.iter().map(|s| s.to_string()))
        .filter(|c| *c != actual.to_string())
        .collect();
    rng.pick(&candidates).clone()
}

/// A face index out of range for `n` vertices (0-based; `one_based` adds 1 where it matters).
fn bad_index(n: usize, one_based: bool, rng: &mut Rng) -> String {
    let past = if one_based { n + 1 } else { n };
    let mut candidates: Vec<String> = vec![past.to_string(), format!("-{}", n + 1)];
    candidates.extend(LIMITS.iter().map(|s| s.to_string()));
    // 0 is a valid 0-based index; -1 a valid relative OBJ index (the last vertex).
    candidates.retain(|c| c != if one_based { "-1" } else { "0" });
    rng.pick(&candidates).clone()
}

/// A file name, its bytes and what was done to it.
pub fn mutated(model: &Model, rng: &mut Rng) -> (String, Vec<u8>, String) {
    let (vertices, faces) = parts(model);
    match rng.below(6) {
        0 => ply_ascii(&vertices, &faces, rng),
        1 => ply_binary(&vertices, &faces, rng),
        2 => off(&vertices, &faces, rng),
        3 => stl_ascii(&vertices, &faces, rng),
        4 => stl_binary(&vertices, &faces, rng),
        _ => obj(&vertices, &faces, rng),
    }
}

/// Face rows as text tokens, with one row, the row count or a header count changed.
struct TextModel {
    vertex_count: String,
    face_count: String,
    rows: Vec<Vec<String>>,
}

impl TextModel {
    fn new(vertices: usize, faces: &[[usize; 3]], prefix: &str) -> TextModel {
        let rows = faces
            .iter()
            .map(|f| {
                let mut row = vec![prefix.to_string()];
                row.extend(f.iter().map(|i| i.to_string()));
                row
            })
            .collect();
        TextModel {
            vertex_count: vertices.to_string(),
            face_count: faces.len().to_string(),
            rows,
        }
    }

    /// Changes one face row, its count token (`counted`) or an index, or merges two rows.
    fn mutate_row(&mut self, n: usize, counted: bool, one_based: bool, rng: &mut Rng) -> String {
        let r = rng.below(self.rows.len() - 1);
        match rng.below(if counted { 4 } else { 2 }) {
            0 => {
                let k = 1 + rng.below(3);
                self.rows[r][k] = bad_index(n, one_based, rng);
                format!("face {r}: index {}", self.rows[r][k])
            }
            1 => {
                let next = self.rows.remove(r + 1);
                self.rows[r].extend(next);
                format!("faces {r} and {} on one line", r + 1)
            }
            2 => {
                self.rows[r][0] = rng.pick(&["2", "4", "255", "256", "-3"]).to_string();
                format!("face {r}: count {}", self.rows[r][0])
            }
            _ => {
                let extra = self.rows[r][1].clone();
                self.rows[r].push(extra);
                format!("face {r}: one index more than its count")
            }
        }
    }

    fn mutate(&mut self, n: usize, counted: bool, one_based: bool, rng: &mut Rng) -> String {
        match rng.below(4) {
            0 => {
                self.vertex_count = count_other_than(n, rng);
                format!("vertex count {}", self.vertex_count)
            }
            1 => {
                self.face_count = count_other_than(self.rows.len(), rng);
                format!("face count {}", self.face_count)
            }
            _ => self.mutate_row(n, counted, one_based, rng),
        }
    }

    fn rows_text(&self) -> String {
        self.rows.iter().map(|r| r.join(" ") + "\n").collect()
    }
}

fn vertex_lines(vertices: &[[String; 3]], prefix: &str) -> String {
    vertices
        .iter()
        .map(|v| format!("{prefix}{} {} {}\n", v[0], v[1], v[2]))
        .collect()
}

fn ply_header(format: &str, vertex_count: &str, face_count: &str) -> String {
    format!(
        "ply\nformat {format} 1.0\nelement vertex {vertex_count}\nproperty double x\n\
         property double y\nproperty double z\nelement face {face_count}\n\
         property list uchar int vertex_indices\nend_header\n"
    )
}

fn ply_ascii(
    vertices: &[[String; 3]],
    faces: &[[usize; 3]],
    rng: &mut Rng,
) -> (String, Vec<u8>, String) {
    let mut m = TextModel::new(vertices.len(), faces, "3");
    let what = m.mutate(vertices.len(), true, false, rng);
    let text = ply_header("ascii", &m.vertex_count, &m.face_count)
        + &vertex_lines(vertices, "")
        + &m.rows_text();
    ("m.ply".into(), text.into_bytes(), what)
}

fn off(vertices: &[[String; 3]], faces: &[[usize; 3]], rng: &mut Rng) -> (String, Vec<u8>, String) {
    let mut m = TextModel::new(vertices.len(), faces, "3");
    // OFF reads values after a face's indices as its colour: an extra index is no error there.
    let what = loop {
        let before = m.rows.clone();
        let what = m.mutate(vertices.len(), true, false, rng);
        if !what.contains("one index more") {
            break what;
        }
        m.rows = before;
    };
    let text = format!("OFF\n{} {} 0\n", m.vertex_count, m.face_count)
        + &vertex_lines(vertices, "")
        + &m.rows_text();
    ("m.off".into(), text.into_bytes(), what)
}

fn obj(vertices: &[[String; 3]], faces: &[[usize; 3]], rng: &mut Rng) -> (String, Vec<u8>, String) {
    let mut m = TextModel::new(vertices.len(), faces, "f");
    for row in &mut m.rows {
        for token in &mut row[1..] {
            *token = (token.parse::<usize>().unwrap() + 1).to_string();
        }
    }
    // OBJ has no counts: a face line gets an index at a limit, a repeated vertex or the next
    // face appended (its `f` is no index).
    let r = rng.below(m.rows.len() - 1);
    let what = match rng.below(3) {
        0 => {
            let k = 1 + rng.below(3);
            m.rows[r][k] = bad_index(vertices.len(), true, rng);
            format!("face {r}: index {}", m.rows[r][k])
        }
        1 => {
            let first = m.rows[r][1].clone();
            m.rows[r].push(first);
            format!("face {r}: its first vertex again")
        }
        _ => {
            let next = m.rows.remove(r + 1);
            m.rows[r].extend(next);
            format!("faces {r} and {} on one line", r + 1)
        }
    };
    let text = vertex_lines(vertices, "v ") + &m.rows_text();
    ("m.obj".into(), text.into_bytes(), what)
}

fn ply_binary(
    vertices: &[[String; 3]],
    faces: &[[usize; 3]],
    rng: &mut Rng,
) -> (String, Vec<u8>, String) {
    let (n, f) = (vertices.len(), faces.len());
    let (mut vertex_count, mut face_count) = (n.to_string(), f.to_string());
    let mut rows: Vec<(u8, Vec<i64>)> = faces
        .iter()
        .map(|t| (3, t.iter().map(|&i| i as i64).collect()))
        .collect();
    let what = match rng.below(4) {
        // More vertices than the file holds, or a count beyond 64 bits.
        0 => {
            vertex_count = rng
                .pick(&[
                    (n + 1).to_string(),
                    LIMITS[4].into(),
                    LIMITS[9].into(),
                    LIMITS[10].into(),
                ])
                .clone();
            format!("vertex count {vertex_count}")
        }
        1 => {
            face_count = rng
                .pick(&[
                    (f + 1).to_string(),
                    (f - 1).to_string(),
                    LIMITS[0].into(),
                    LIMITS[9].into(),
                ])
                .clone();
            format!("face count {face_count}")
        }
        2 => {
            let r = rng.below(f);
            rows[r].1[rng.below(3)] = *rng.pick(&[-1, n as i64, i64::from(i32::MAX)]);
            format!("face {r}: indices {:?}", rows[r].1)
        }
        _ => {
            let r = rng.below(f);
            rows[r].0 = *rng.pick(&[0u8, 2, 4, 255]);
            format!("face {r}: count byte {}", rows[r].0)
        }
    };
    let mut bytes = ply_header("binary_little_endian", &vertex_count, &face_count).into_bytes();
    for v in vertices {
        for c in v {
            bytes.extend(c.parse::<f64>().unwrap().to_le_bytes());
        }
    }
    for (count, ids) in rows {
        bytes.push(count);
        for i in ids {
            bytes.extend((i as i32).to_le_bytes());
        }
    }
    ("m.ply".into(), bytes, what)
}

fn facets(vertices: &[[String; 3]], faces: &[[usize; 3]]) -> Vec<Vec<String>> {
    faces
        .iter()
        .map(|t| {
            let mut lines = vec!["facet normal 0 0 1".to_string(), "  outer loop".into()];
            lines.extend(
                t.iter()
                    .map(|&i| format!("    vertex {}", vertices[i].join(" "))),
            );
            lines.extend(["  endloop".to_string(), "endfacet".into()]);
            lines
        })
        .collect()
}

fn stl_ascii(
    vertices: &[[String; 3]],
    faces: &[[usize; 3]],
    rng: &mut Rng,
) -> (String, Vec<u8>, String) {
    let mut facets = facets(vertices, faces);
    let mut tail = "endsolid m\n".to_string();
    let t = rng.below(facets.len());
    let what = match rng.below(6) {
        0 => {
            facets[t].remove(2 + rng.below(3));
            format!("triangle {t}: two vertices")
        }
        1 => {
            let again = facets[t][2].clone();
            facets[t].insert(3, again);
            format!("triangle {t}: four vertices")
        }
        2 => {
            let bad = *rng.pick(&["1e39", "-1e39", "nan", "inf", "1e", "0x1"]);
            facets[t][2 + rng.below(3)] = format!("    vertex {bad} 0 0");
            format!("triangle {t}: coordinate {bad}")
        }
        3 => {
            let after: &[&str] = &["junk\n", "endsolid m\n", "facet normal 0 0 1\n"];
            let junk: &&str = rng.pick(after);
            tail.push_str(junk);
            "content after endsolid".into()
        }
        4 => {
            tail.clear();
            "no endsolid".into()
        }
        _ => {
            facets[t].remove(rng.pick(&[1usize, 5, 6]).to_owned());
            format!("triangle {t}: a keyword line missing")
        }
    };
    let body: String = facets.iter().flatten().map(|l| l.clone() + "\n").collect();
    (
        "m.stl".into(),
        format!("solid m\n{body}{tail}").into_bytes(),
        what,
    )
}

fn stl_binary(
    vertices: &[[String; 3]],
    faces: &[[usize; 3]],
    rng: &mut Rng,
) -> (String, Vec<u8>, String) {
    let mut bytes = vec![0u8; 80];
    bytes.extend((faces.len() as u32).to_le_bytes());
    for t in faces {
        bytes.extend([0u8; 12]);
        for &i in t {
            for c in &vertices[i] {
                bytes.extend(c.parse::<f32>().unwrap().to_le_bytes());
            }
        }
        bytes.extend([0u8; 2]);
    }
    let what = match rng.below(4) {
        0 => {
            let n = faces.len() as u32;
            let count = *rng.pick(&[0, n - 1, n + 1, u32::MAX]);
            bytes[80..84].copy_from_slice(&count.to_le_bytes());
            format!("triangle count {count}")
        }
        1 => {
            bytes.pop();
            "one byte short".into()
        }
        2 => {
            bytes.push(0);
            "one byte over".into()
        }
        _ => {
            let t = rng.below(faces.len());
            let at = 84 + 50 * t + 12 + 4 * rng.below(9);
            let bad = *rng.pick(&[f32::NAN, f32::INFINITY, f32::NEG_INFINITY]);
            bytes[at..at + 4].copy_from_slice(&bad.to_le_bytes());
            format!("triangle {t}: coordinate {bad}")
        }
    };
    ("m.stl".into(), bytes, what)
}

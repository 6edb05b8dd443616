//! The files of an assessment besides the model: an intrados or extrados surface and a live
//! load pattern, read here for both command lines (and any caller) alike.

use std::path::Path;

use serde_json::Value;

use super::{read_mesh, RawMesh, UpAxis};
use crate::error::{Error, Result};

/// A mesh file of an envelope's intrados or extrados (any format [`read_mesh`] reads) in the
/// Z-up frame, `up` being the file's up axis: its positions and triangles as read, neither
/// welded nor validated (`Envelope::from_surfaces` samples any triangulation).
pub fn read_surface(path: &Path, up: UpAxis) -> Result<RawMesh> {
    let (positions, faces) = read_mesh(path)?;
    Ok((
        positions.into_iter().map(|p| up.to_z_up(p)).collect(),
        faces,
    ))
}

/// A live load pattern (for `Objective::MaxLoad`) from a JSON file: `[..]` or
/// `{"loads": [..]}`, one load per vertex of the file the model was read from, or
/// `{"loads": {"ID": load, ..}}` by file vertex id (absent ids carry none). Returns a load per
/// mesh vertex, `welded_ids` mapping file vertices to mesh vertices
/// ([`super::Model::welded_ids`]); the loads of file vertices welded into one add up.
///
/// Errors: `InvalidArgument` named `load_pattern`, its reason starting with the path: an
/// unreadable file, not JSON, another shape, a list of the wrong length, an id that is not a
/// file vertex, or a load that is not a finite number.
pub fn read_load_pattern(path: &Path, welded_ids: &[u32], n_vertices: usize) -> Result<Vec<f64>> {
    let fail = |e: String| Error::InvalidArgument {
        name: "load_pattern",
        reason: format!("{}: {e}", path.display()),
    };
    let text = std::fs::read_to_string(path).map_err(|e| fail(e.to_string()))?;
    let mut loads = vec![0.0; n_vertices];
    for (v, x) in pattern_entries(&text, welded_ids.len()).map_err(fail)? {
        match welded_ids.get(v).and_then(|&w| loads.get_mut(w as usize)) {
            Some(load) => *load += x,
            None => return Err(fail(format!("vertex {v} has no mesh vertex"))),
        }
    }
    Ok(loads)
}

const SHAPES: &str = "expected {\"loads\": [..]}, [..] or {\"loads\": {\"ID\": load, ..}}";

/// The loads of a pattern file's text as (file vertex, load) pairs.
fn pattern_entries(text: &str, n_input: usize) -> std::result::Result<Vec<(usize, f64)>, String> {
    let json: Value = serde_json::from_str(text).map_err(|e| format!("not JSON: {e}"))?;
    let loads = match &json {
        Value::Object(map) => map.get("loads").ok_or(SHAPES.to_string())?,
        other => other,
    };
    let number = |v: usize, x: &Value| match x.as_f64() {
        Some(x) if x.is_finite() => Ok((v, x)),
        _ => Err(format!(
            "the load of vertex {v} is {x}, not a finite number"
        )),
    };
    match loads {
        Value::Array(list) => {
            if list.len() != n_input {
                return Err(format!(
                    "has {} loads, expected one per vertex of MESH ({n_input}, ids before welding)",
                    list.len()
                ));
            }
            list.iter().enumerate().map(|(v, x)| number(v, x)).collect()
        }
        Value::Object(map) => map
            .iter()
            .map(|(id, x)| {
                let v = id.trim().parse::<usize>().ok().filter(|&v| v < n_input);
                let v = v.ok_or(format!(
                    "`{id}` is not a vertex id of MESH (0 to {}, ids before welding)",
                    n_input.saturating_sub(1)
                ))?;
                number(v, x)
            })
            .collect(),
        _ => Err(SHAPES.into()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pattern(text: &str, welded: &[u32], n: usize) -> Result<Vec<f64>> {
        let dir = std::env::temp_dir().join(format!("vsr-pattern-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(format!("p{}.json", text.len()));
        std::fs::write(&path, text).unwrap();
        let r = read_load_pattern(&path, welded, n);
        std::fs::remove_file(&path).unwrap();
        r
    }

    fn reason(r: Result<Vec<f64>>) -> String {
        match r {
            Err(Error::InvalidArgument { name, reason }) => {
                assert_eq!(name, "load_pattern");
                reason
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn loads_of_welded_vertices_add_and_bad_files_are_named() {
        let welded = [0, 1, 1, 2];
        assert_eq!(
            pattern("[1, 2, 3, 4]", &welded, 3).unwrap(),
            [1.0, 5.0, 4.0]
        );
        let by_id = r#"{"loads": {"2": 0.5, " 0 ": 1}}"#;
        assert_eq!(pattern(by_id, &welded, 3).unwrap(), [1.0, 0.5, 0.0]);
        let cases = [
            (
                "[1, 2]",
                "has 2 loads, expected one per vertex of MESH (4, ids before welding)",
            ),
            (
                r#"{"loads": {"9": 1}}"#,
                "`9` is not a vertex id of MESH (0 to 3",
            ),
            (
                "[1, 2, null, 4]",
                "the load of vertex 2 is null, not a finite number",
            ),
            (r#"{"load": []}"#, SHAPES),
            ("3", SHAPES),
            ("[1, 2", "not JSON: "),
        ];
        for (text, expected) in cases {
            let r = reason(pattern(text, &welded, 3));
            assert!(r.contains(expected), "{text}: {r}");
            assert!(r.contains("p") && r.contains(".json: "), "{r}");
        }
        let missing = reason(read_load_pattern(
            Path::new("/nonexistent/p.json"),
            &welded,
            3,
        ));
        assert!(missing.starts_with("/nonexistent/p.json: "), "{missing}");
    }

    #[test]
    fn a_y_up_surface_is_turned_z_up() {
        let dir = std::env::temp_dir().join(format!("vsr-surface-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("s.obj");
        std::fs::write(&path, "v 0 0 0\nv 1 0 0\nv 0 2 3\nf 1 2 3\n").unwrap();
        let (p, f) = read_surface(&path, UpAxis::Y).unwrap();
        assert_eq!(p[2], [0.0, -3.0, 2.0]);
        assert_eq!(f, [[0, 1, 2]]);
        assert_eq!(
            read_surface(&path, UpAxis::Z).unwrap().0[2],
            [0.0, 2.0, 3.0]
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

//! Welding a generated vault whose patches each carry their own copy of the seam vertices.

use super::*;
use crate::{Error, Mesh};

const N: u32 = 8;

/// A grid of `(N+1)²` vertices over the unit square, lifted into a bump, in two triangles per
/// cell, and the same surface cut into four patches that each list their own vertices (the
/// seams duplicated as exporters write them). The patch vertex of grid vertex `g` first
/// met in patch order gets the smallest welded id.
fn grid_and_patches() -> (RawMesh, RawMesh) {
    let id = |i: u32, j: u32| j * (N + 1) + i;
    let position = |g: u32| {
        let (x, y) = (f64::from(g % (N + 1)) / 8.0, f64::from(g / (N + 1)) / 8.0);
        [x, y, 0.3 + x * (1.0 - x) * y * (1.0 - y)]
    };
    let mut faces = Vec::new();
    for j in 0..N {
        for i in 0..N {
            faces.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            faces.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    let positions: Vec<[f64; 3]> = (0..(N + 1) * (N + 1)).map(position).collect();
    // Patch k holds the cells of quadrant k; each patch renumbers its own vertices.
    let (mut soup_positions, mut soup_faces) = (Vec::new(), Vec::new());
    for quadrant in 0..4 {
        let (qi, qj) = (quadrant % 2, quadrant / 2);
        let mut local = std::collections::HashMap::new();
        for (t, f) in faces.iter().enumerate() {
            let cell = t as u32 / 2;
            if (cell % N) / (N / 2) != qi || (cell / N) / (N / 2) != qj {
                continue;
            }
            soup_faces.push(f.map(|g| {
                *local.entry(g).or_insert_with(|| {
                    soup_positions.push(position(g));
                    soup_positions.len() as u32 - 1
                })
            }));
        }
    }
    ((positions, faces), (soup_positions, soup_faces))
}

#[test]
fn duplicated_seams_weld_back_into_one_surface() {
    let ((positions, faces), (soup, soup_faces)) = grid_and_patches();
    // Four 5x5 patches: 100 vertices for 81, the 19 seam copies merged.
    assert_eq!(soup.len(), 100);
    let welded = weld(&soup, &soup_faces, DEFAULT_WELD_TOLERANCE).unwrap();
    assert_eq!(welded.positions.len(), positions.len());
    assert_eq!(welded.merged, 19);
    assert!(welded.collapsed_faces.is_empty());
    // Same surface: every welded face is the grid face at the same index, relabelled, and
    // welded ids follow first occurrence.
    let mut grid_of = vec![u32::MAX; welded.positions.len()];
    let mut order = Vec::new();
    for (w, s) in welded.faces.iter().zip(&soup_faces) {
        for k in 0..3 {
            assert_eq!(w[k], welded.welded_id[s[k] as usize]);
            if !order.contains(&w[k]) {
                order.push(w[k]);
            }
        }
    }
    assert_eq!(
        order,
        (0..welded.positions.len() as u32).collect::<Vec<_>>()
    );
    for (w, v) in welded.positions.iter().zip(0..) {
        grid_of[v] = positions.iter().position(|p| p == w).unwrap() as u32;
    }
    let mut relabelled: Vec<[u32; 3]> = welded
        .faces
        .iter()
        .map(|f| f.map(|w| grid_of[w as usize]))
        .collect();
    let mut expected = faces.clone();
    relabelled.sort();
    expected.sort();
    assert_eq!(relabelled, expected);
    // Without welding the seams are slits: the patches are separate components.
    let corners: Vec<u32> = (0..soup.len() as u32)
        .filter(|&v| soup[v as usize][0] == 0.0 && soup[v as usize][1] == 0.0)
        .collect();
    assert!(matches!(
        Mesh::new(soup.clone(), soup_faces.clone(), &corners),
        Err(Error::UnsupportedComponent { .. })
    ));
    // Supports given on input ids land on welded ids: the four corners of the square, one
    // of them listed twice through two seam copies of a vertex.
    let on_corner = |v: &u32| {
        let p = soup[*v as usize];
        (p[0] == 0.0 || p[0] == 1.0) && (p[1] == 0.0 || p[1] == 1.0)
    };
    let mut input_ids: Vec<u32> = (0..soup.len() as u32).filter(on_corner).collect();
    let centre = soup
        .iter()
        .position(|p| p[0] == 0.5 && p[1] == 0.5)
        .unwrap() as u32;
    let centre_copy = soup
        .iter()
        .rposition(|p| p[0] == 0.5 && p[1] == 0.5)
        .unwrap() as u32;
    assert_ne!(centre, centre_copy);
    input_ids.extend([centre, centre_copy]);
    let anchored = welded.map_ids(&input_ids).unwrap();
    assert_eq!(anchored.len(), 5);
    let mesh = Mesh::new(welded.positions.clone(), welded.faces.clone(), &anchored).unwrap();
    assert_eq!(mesh.n_vertices(), 81);
    assert!(matches!(
        welded.map_ids(&[100]),
        Err(Error::InvalidAnchor { index: 100, .. })
    ));
}

#[test]
fn tolerance_is_relative_to_the_bounding_box() {
    let ((_, _), (mut soup, soup_faces)) = grid_and_patches();
    // Nudge the k-th later copy of every seam vertex by k·1e-11 (the diagonal is about 1.41).
    let mut copies = std::collections::HashMap::new();
    for p in soup.iter_mut() {
        let k = copies.entry(p.map(f64::to_bits)).or_insert(0);
        p[0] += f64::from(*k) * 1e-11;
        *k += 1;
    }
    assert_eq!(weld(&soup, &soup_faces, 1e-9).unwrap().merged, 19);
    assert_eq!(weld(&soup, &soup_faces, 0.0).unwrap().merged, 0);
    assert_eq!(weld(&soup, &soup_faces, 1e-12).unwrap().merged, 0);
    // Scaled by 1e6, the same relative tolerance still merges them.
    let scaled: Vec<[f64; 3]> = soup.iter().map(|p| p.map(|c| c * 1e6)).collect();
    let welded = weld(&scaled, &soup_faces, 1e-9).unwrap();
    assert_eq!(welded.merged, 19);
    // Diagonal of [0, 1] x [0, 1] x [0.3, 0.3 + 1/16], scaled.
    let diagonal = 1e6 * (2.0f64 + 0.0625f64.powi(2)).sqrt();
    assert!((welded.tolerance / (1e-9 * diagonal) - 1.0).abs() < 1e-9);
    for bad in [-1.0, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            weld(&soup, &soup_faces, bad),
            Err(Error::InvalidArgument {
                name: "weld_tolerance",
                ..
            })
        ));
    }
}

#[test]
fn faces_whose_corners_merge_are_dropped_and_listed() {
    let positions = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1e-12, 0.0],
    ];
    let welded = weld(&positions, &[[0, 1, 2], [1, 3, 2]], 1e-9).unwrap();
    assert_eq!(welded.welded_id, vec![0, 1, 2, 1]);
    assert_eq!(welded.faces, vec![[0, 1, 2]]);
    assert_eq!(welded.collapsed_faces, vec![1]);
    assert_eq!(welded.positions[1], [1.0, 0.0, 0.0]);
}

/// Issue 48: welding that collapsed every face left an "empty mesh", which named the wrong
/// cause.
#[test]
fn welding_every_face_away_names_the_tolerance() {
    let positions = vec![
        [0.0; 3],
        [1e-12, 0.0, 0.0],
        [0.0, 1e-12, 0.0],
        [1e3, 1e3, 0.0],
    ];
    let err = weld(&positions, &[[0, 1, 2]], 1e-9).unwrap_err();
    assert!(
        matches!(&err, Error::InvalidArgument { name: "weld_tolerance", reason }
            if reason.contains("every face (1 in all)")),
        "{err}"
    );
    // Exact welding keeps the face; no faces at all are left for the mesh to call empty.
    assert_eq!(weld(&positions, &[[0, 1, 2]], 0.0).unwrap().faces.len(), 1);
    assert!(weld(&positions, &[], 1e-9).unwrap().faces.is_empty());
}

//! Plan repair on generated vaults: slivers of 1e-9 of the median area (some inverted) mended
//! by flips, slivers on the boundary and a nearly vertical strip mended by nudges; the
//! repaired meshes validate and form-find; real folds are left alone.

use super::repair::*;
use crate::{form_find, Error, FormFindSettings, Mesh, Problem, Termination};

const N: u32 = 8;

/// An N×N grid over the unit square lifted into a dome, its boundary anchored.
fn grid() -> (Vec<[f64; 3]>, Vec<[u32; 3]>, Vec<u32>) {
    let id = |i: u32, j: u32| j * (N + 1) + i;
    let mut positions = Vec::new();
    for j in 0..=N {
        for i in 0..=N {
            let (x, y) = (f64::from(i) / f64::from(N), f64::from(j) / f64::from(N));
            positions.push([x, y, 0.6 - (x - 0.5).powi(2) - (y - 0.5).powi(2)]);
        }
    }
    let mut faces = Vec::new();
    for j in 0..N {
        for i in 0..N {
            faces.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            faces.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    let boundary = (0..=N)
        .flat_map(|j| (0..=N).map(move |i| (i, j)))
        .filter(|&(i, j)| i == 0 || j == 0 || i == N || j == N)
        .map(|(i, j)| id(i, j))
        .collect();
    (positions, faces, boundary)
}

/// Splits face `t` = (a, b, c) with a new vertex at the middle of its edge (a, b), moved by
/// `offset` (in plan, towards c when positive): the sliver (a, b, m) has area ~ offset/16.
fn add_sliver(
    positions: &mut Vec<[f64; 3]>,
    faces: &mut Vec<[u32; 3]>,
    t: usize,
    offset: f64,
) -> usize {
    let [a, b, c] = faces[t];
    let (pa, pb, pc) = (
        positions[a as usize],
        positions[b as usize],
        positions[c as usize],
    );
    let mid = [
        (pa[0] + pb[0]) / 2.0,
        (pa[1] + pb[1]) / 2.0,
        (pa[2] + pb[2]) / 2.0,
    ];
    let towards = [pc[0] - mid[0], pc[1] - mid[1]];
    let length = towards[0].hypot(towards[1]);
    let m = positions.len() as u32;
    positions.push([
        mid[0] + offset * towards[0] / length,
        mid[1] + offset * towards[1] / length,
        mid[2],
    ]);
    faces[t] = [a, m, c];
    faces.push([m, b, c]);
    faces.push([a, b, m]);
    faces.len() - 1
}

fn converges(positions: Vec<[f64; 3]>, faces: Vec<[u32; 3]>, anchored: &[u32]) {
    let mesh = Mesh::new(positions, faces, anchored).unwrap();
    let found = form_find(&Problem::new(mesh), &FormFindSettings::default(), None).unwrap();
    assert_eq!(found.termination, Termination::Converged);
}

#[test]
fn interior_slivers_are_mended_by_flips() {
    let (mut positions, mut faces, anchored) = grid();
    // Median area 1/128; offsets of ±1.25e-10 give areas of about ±1e-9 of it.
    let slivers = [
        add_sliver(&mut positions, &mut faces, 20, 1.25e-10),
        add_sliver(&mut positions, &mut faces, 45, -1.25e-10),
        add_sliver(&mut positions, &mut faces, 90, 0.0),
    ];
    let rejected = Mesh::new(positions.clone(), faces.clone(), &anchored).unwrap_err();
    assert!(
        matches!(
            rejected,
            Error::DegenerateFaces { .. } | Error::FlippedFaces { .. }
        ),
        "{rejected}"
    );
    let before = positions.clone();
    let repairs = repair_plan(
        &mut positions,
        &mut faces,
        &anchored,
        DEFAULT_REPAIR_TOLERANCE,
    )
    .unwrap();
    assert_eq!(repairs.len(), 3, "{repairs:?}");
    for (r, sliver) in repairs.iter().zip(slivers) {
        match r {
            PlanRepair::Flip { faces: pair, .. } => assert!(pair.contains(&sliver), "{r}"),
            other => panic!("expected a flip, got {other}"),
        }
    }
    assert_eq!(positions, before, "flips move no vertex");
    converges(positions, faces, &anchored);
}

#[test]
fn boundary_slivers_and_a_nearly_vertical_strip_are_mended_by_nudges() {
    let (mut positions, mut faces, anchored) = grid();
    // Face 1 = (0, 10, 9) has the boundary edge (9, 0); its sliver cannot be flipped there.
    faces[1] = [faces[1][2], faces[1][0], faces[1][1]];
    let [a, b, _] = faces[1];
    assert!(anchored.contains(&a) && anchored.contains(&b));
    let sliver = add_sliver(&mut positions, &mut faces, 1, -1e-10);
    // A nearly vertical strip: row j = 4 pushed to within 1e-9 of row j = 3 in plan.
    for i in 1..N {
        positions[(4 * (N + 1) + i) as usize][1] = 3.0 / 8.0 + 1e-9;
    }
    let bad_before: Vec<usize> = (0..faces.len())
        .filter(|&t| {
            let [p, q, r] = faces[t].map(|v| positions[v as usize]);
            (0.5 * ((q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]))).abs() < 1e-8
        })
        .collect();
    assert!(
        bad_before.contains(&sliver) && bad_before.len() > 10,
        "{bad_before:?}"
    );
    assert!(Mesh::new(positions.clone(), faces.clone(), &anchored).is_err());
    let before = positions.clone();
    let repairs = repair_plan(
        &mut positions,
        &mut faces,
        &anchored,
        DEFAULT_REPAIR_TOLERANCE,
    )
    .unwrap();
    let nudges: Vec<&PlanRepair> = repairs
        .iter()
        .filter(|r| matches!(r, PlanRepair::Nudge { .. }))
        .collect();
    println!("{} repairs, {} nudges", repairs.len(), nudges.len());
    assert!(!nudges.is_empty(), "{repairs:?}");
    for r in &nudges {
        let PlanRepair::Nudge {
            vertex, from, to, ..
        } = r
        else {
            unreachable!()
        };
        assert!(!anchored.contains(vertex), "{r}");
        // Small moves that keep the height.
        assert!((to[0] - from[0]).hypot(to[1] - from[1]) < 1e-4, "{r}");
        assert_eq!(positions[*vertex as usize][2], before[*vertex as usize][2]);
    }
    converges(positions, faces, &anchored);
}

#[test]
fn real_folds_and_valid_meshes_are_left_alone() {
    let (mut positions, mut faces, anchored) = grid();
    let original = (positions.clone(), faces.clone());
    assert!(repair_plan(
        &mut positions,
        &mut faces,
        &anchored,
        DEFAULT_REPAIR_TOLERANCE
    )
    .unwrap()
    .is_empty());
    assert_eq!((positions.clone(), faces.clone()), original);
    // An interior vertex pulled across its neighbours: a fold of large inverted triangles.
    let v = (4 * (N + 1) + 4) as usize;
    positions[v][0] += 0.2;
    let folded = positions.clone();
    let repairs = repair_plan(
        &mut positions,
        &mut faces,
        &anchored,
        DEFAULT_REPAIR_TOLERANCE,
    )
    .unwrap();
    assert!(repairs.is_empty(), "{repairs:?}");
    assert_eq!(positions, folded);
    assert!(matches!(
        Mesh::new(positions, faces, &anchored),
        Err(Error::FlippedFaces { .. })
    ));
    for bad in [-1.0, f64::NAN] {
        assert!(repair_plan(&mut grid().0, &mut grid().1, &[], bad).is_err());
    }
}

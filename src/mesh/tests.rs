//! A table of deliberately bad meshes (one per error, in validation order) and invariant
//! checks on generated good ones.

use super::build::plan_area;
use super::Mesh;
use crate::Error;

type Positions = Vec<[f64; 3]>;
type Faces = Vec<[u32; 3]>;

/// (nx + 1) × (ny + 1) unit grid, vertex (i, j) = j (nx + 1) + i, z = i j / 10; each square
/// (i, j) gives the counter-clockwise faces 2 (j nx + i) = (a, b, c) and 2 (j nx + i) + 1 =
/// (a, c, d) with a = (i, j), b = (i + 1, j), c = (i + 1, j + 1), d = (i, j + 1).
fn grid(nx: u32, ny: u32) -> (Positions, Faces) {
    let mut positions = Vec::new();
    for j in 0..=ny {
        for i in 0..=nx {
            positions.push([f64::from(i), f64::from(j), f64::from(i * j) / 10.0]);
        }
    }
    let mut faces = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let a = j * (nx + 1) + i;
            let (b, d) = (a + 1, a + nx + 1);
            let c = d + 1;
            faces.push([a, b, c]);
            faces.push([a, c, d]);
        }
    }
    (positions, faces)
}

fn reversed(faces: &[[u32; 3]]) -> Faces {
    faces.iter().map(|f| [f[0], f[2], f[1]]).collect()
}

fn plan(xy: &[[f64; 2]]) -> Positions {
    xy.iter().map(|p| [p[0], p[1], 0.0]).collect()
}

struct Case {
    name: &'static str,
    positions: Positions,
    faces: Faces,
    anchored: Vec<u32>,
    expected: Error,
    /// Substrings the Display message must contain (the offending ids).
    needles: Vec<&'static str>,
}

fn bad_meshes() -> Vec<Case> {
    [
        input_cases(),
        topology_cases(),
        plan_cases(),
        support_cases(),
    ]
    .into_iter()
    .flatten()
    .collect()
}

/// Empty meshes, indices out of range, non-finite coordinates.
fn input_cases() -> Vec<Case> {
    let (gp, gf) = grid(2, 2);
    let tri = plan(&[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
    let mut cases = vec![
        Case {
            name: "empty",
            positions: vec![],
            faces: vec![],
            anchored: vec![],
            expected: Error::EmptyMesh,
            needles: vec!["empty mesh"],
        },
        Case {
            name: "vertices but no faces",
            positions: tri.clone(),
            faces: vec![],
            anchored: vec![0],
            expected: Error::EmptyMesh,
            needles: vec!["empty mesh"],
        },
        Case {
            name: "index out of range",
            positions: tri.clone(),
            faces: vec![[0, 1, 2], [0, 2, 7], [9, 1, 2]],
            anchored: vec![0],
            expected: Error::IndexOutOfRange {
                face: 1,
                index: 7,
                n_vertices: 3,
            },
            needles: vec!["face 1", "vertex 7", "only 3"],
        },
        Case {
            name: "anchor out of range",
            positions: gp.clone(),
            faces: gf.clone(),
            anchored: vec![0, 99, 0],
            expected: Error::InvalidAnchor {
                index: 99,
                reason: "out of range",
            },
            needles: vec!["anchored vertex 99", "out of range"],
        },
        Case {
            name: "anchor listed twice",
            positions: gp.clone(),
            faces: gf.clone(),
            anchored: vec![4, 0, 4],
            expected: Error::InvalidAnchor {
                index: 4,
                reason: "listed twice",
            },
            needles: vec!["anchored vertex 4", "twice"],
        },
    ];

    let mut nan = gp.clone();
    nan[5][2] = f64::NAN;
    nan[7][0] = f64::INFINITY;
    cases.push(Case {
        name: "NaN and inf coordinates",
        positions: nan,
        faces: gf.clone(),
        anchored: vec![0],
        expected: Error::NonFiniteCoordinate { vertex: 5 },
        needles: vec!["vertex 5"],
    });
    cases
}

/// Faces that do not make an oriented manifold surface.
fn topology_cases() -> Vec<Case> {
    let mut cases = Vec::new();
    let quad = plan(&[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]);
    cases.push(Case {
        name: "repeated vertex in a face",
        positions: quad.clone(),
        faces: vec![[0, 1, 2], [0, 2, 3], [2, 3, 2]],
        anchored: vec![0],
        expected: Error::RepeatedVertexInFace { face: 2 },
        needles: vec!["face 2"],
    });
    cases.push(Case {
        name: "duplicate face in reversed order",
        positions: quad.clone(),
        faces: vec![[0, 1, 2], [0, 2, 3], [2, 1, 0]],
        anchored: vec![0],
        expected: Error::DuplicateFace { face: 2, first: 0 },
        needles: vec!["face 2", "face 0"],
    });

    // Face 1 = (2, 1, 3) lies on the plan line x + y = 1, though its heights differ.
    let mut collinear = plan(&[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [2.0, -1.0]]);
    collinear[3][2] = 7.0;
    collinear[2][2] = -3.0;
    cases.push(Case {
        name: "zero plan area (collinear in plan, different z)",
        positions: collinear,
        faces: vec![[0, 1, 2], [2, 1, 3]],
        anchored: vec![0],
        expected: Error::DegenerateFaces { faces: vec![1] },
        needles: vec!["zero plan area: 1"],
    });

    cases.push(Case {
        name: "three faces on one edge",
        positions: plan(&[[0.0, 0.0], [1.0, 0.0], [0.5, 1.0], [0.5, -1.0], [0.5, 2.0]]),
        faces: vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]],
        anchored: vec![0],
        expected: Error::NonManifoldEdge {
            edge: [0, 1],
            faces: vec![0, 1, 2],
        },
        needles: vec!["(0, 1)", "0, 1, 2"],
    });

    // Face 2 of a 2 × 1 grid written clockwise: it runs 1→5 like face 3.
    let (p21, mut f21) = grid(2, 1);
    f21[2] = [f21[2][0], f21[2][2], f21[2][1]];
    cases.push(Case {
        name: "inconsistent orientation",
        positions: p21,
        faces: f21,
        anchored: vec![0],
        expected: Error::InconsistentOrientation {
            edge: [1, 5],
            faces: [2, 3],
        },
        needles: vec!["faces 2 and 3", "(1, 5)"],
    });

    cases.push(Case {
        name: "bow-tie vertex",
        positions: plan(&[
            [1.0, 0.0],
            [1.0, 1.0],
            [0.0, 0.0],
            [-1.0, 0.0],
            [-1.0, -1.0],
        ]),
        faces: vec![[2, 0, 1], [2, 3, 4]],
        anchored: vec![0, 3],
        expected: Error::NonManifoldVertex { vertex: 2 },
        needles: vec!["vertex 2"],
    });

    cases
}

/// Plans that fold over or overlap themselves.
fn plan_cases() -> Vec<Case> {
    let quad = plan(&[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]);
    let mut cases = Vec::new();
    // Interior vertex 12 = (2, 2) of a 4 × 4 grid pulled past its neighbour 13 = (3, 2).
    let (mut fold, gf44) = grid(4, 4);
    fold[12] = [3.5, 2.25, 0.0];
    cases.push(Case {
        name: "folded plan (flipped faces)",
        positions: fold.clone(),
        faces: gf44.clone(),
        anchored: vec![0],
        expected: Error::FlippedFaces {
            faces: vec![13, 20],
        },
        needles: vec!["13, 20"],
    });
    cases.push(Case {
        name: "folded plan, clockwise input",
        positions: fold,
        faces: reversed(&gf44),
        anchored: vec![0],
        expected: Error::FlippedFaces {
            faces: vec![13, 20],
        },
        needles: vec!["13, 20"],
    });

    cases.push(Case {
        name: "fan wrapping twice around an interior vertex",
        positions: double_fan().0,
        faces: double_fan().1,
        anchored: vec![1],
        expected: Error::OverlappingPlan { vertices: vec![0] },
        needles: vec!["around vertices 0"],
    });
    cases.push(Case {
        name: "open fan wrapping 1.5 times around a boundary vertex",
        positions: open_fan().0,
        faces: open_fan().1,
        anchored: vec![1],
        expected: Error::OverlappingPlan { vertices: vec![0] },
        needles: vec!["around vertices 0"],
    });
    cases.push(Case {
        name: "helical strip of 1.6 turns (no interior vertex, no flipped face)",
        positions: helix().0,
        faces: helix().1,
        anchored: vec![0, 1],
        expected: Error::OverlappingFaces { faces: [0, 20] },
        needles: vec!["faces 0 and 20 overlap"],
    });
    let mut stacked = quad.clone();
    stacked.extend(quad.iter().map(|p| [p[0] + 0.5, p[1] + 0.5, 1.0]));
    cases.push(Case {
        name: "two squares stacked in plan",
        positions: stacked,
        faces: vec![[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]],
        anchored: vec![0, 4],
        expected: Error::OverlappingFaces { faces: [0, 2] },
        needles: vec!["faces 0 and 2 overlap"],
    });

    cases
}

/// Meshes with a part that nothing holds up.
fn support_cases() -> Vec<Case> {
    let (gp, gf) = grid(2, 2);
    let tri = plan(&[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
    let mut cases = Vec::new();
    let mut two = tri.clone();
    two.extend(plan(&[[3.0, 0.0], [4.0, 0.0], [3.0, 1.0]]));
    cases.push(Case {
        name: "component without support",
        positions: two,
        faces: vec![[0, 1, 2], [3, 4, 5]],
        anchored: vec![0],
        expected: Error::UnsupportedComponent {
            component: 1,
            vertices: vec![3, 4, 5],
        },
        needles: vec!["component 1", "3, 4, 5"],
    });
    cases.push(Case {
        name: "no supports",
        positions: gp.clone(),
        faces: gf.clone(),
        anchored: vec![],
        expected: Error::NoSupports,
        needles: vec!["no vertex is anchored"],
    });
    let mut lonely = gp.clone();
    lonely.push([5.0, 5.0, 0.0]);
    cases.push(Case {
        name: "only an unreferenced vertex anchored",
        positions: lonely,
        faces: gf.clone(),
        anchored: vec![9],
        expected: Error::NoSupports,
        needles: vec!["no vertex is anchored"],
    });
    cases
}

/// Vertex 0 at the origin, ring vertices 1..=8 going around it twice (radius 1 then 2, a
/// quarter turn each), faces (0, i, i + 1): counter-clockwise, manifold, angle sum 4π.
fn double_fan() -> (Positions, Faces) {
    let mut positions = vec![[0.0, 0.0, 1.0]];
    for i in 0..8u32 {
        let angle = std::f64::consts::FRAC_PI_2 * f64::from(i % 4) + 0.1;
        let r = 1.0 + f64::from(i / 4);
        positions.push([r * angle.cos(), r * angle.sin(), 0.0]);
    }
    let faces = (1..=8u32).map(|i| [0, i, i % 8 + 1]).collect();
    (positions, faces)
}

/// Vertex 0 at the origin, vertices 1..=7 around it a quarter turn apart (radius growing),
/// faces (0, i, i + 1): an open fan of six quarter turns, so vertex 0 is on the boundary.
fn open_fan() -> (Positions, Faces) {
    let mut positions = vec![[0.0, 0.0, 1.0]];
    for i in 0..7u32 {
        let angle = std::f64::consts::FRAC_PI_2 * f64::from(i) + 0.1;
        let r = 1.0 + 0.2 * f64::from(i);
        positions.push([r * angle.cos(), r * angle.sin(), 0.0]);
    }
    let faces = (1..=6u32).map(|i| [0, i, i + 1]).collect();
    (positions, faces)
}

/// A strip between radii 1 and 2 rising as it winds 1.6 turns, ten segments a turn: inner
/// vertex 2s and outer 2s + 1 at angle 36° s; segment s has the counter-clockwise faces 2s
/// (inner s, outer s, outer s + 1) and 2s + 1 (inner s, outer s + 1, inner s + 1). Segment
/// 10 lies on segment 0 in plan, face 20 on face 0.
fn helix() -> (Positions, Faces) {
    let mut positions = Vec::new();
    for s in 0..=16u32 {
        let angle = std::f64::consts::TAU * f64::from(s) / 10.0;
        let z = 0.1 * f64::from(s);
        for r in [1.0, 2.0] {
            positions.push([r * angle.cos(), r * angle.sin(), z]);
        }
    }
    let mut faces = Vec::new();
    for s in 0..16u32 {
        let (i0, o0, i1, o1) = (2 * s, 2 * s + 1, 2 * s + 2, 2 * s + 3);
        faces.push([i0, o0, o1]);
        faces.push([i0, o1, i1]);
    }
    (positions, faces)
}

#[test]
fn bad_meshes_give_exact_errors_naming_ids() {
    for case in bad_meshes() {
        let got = Mesh::new(case.positions, case.faces, &case.anchored);
        let err = match got {
            Ok(_) => panic!("{}: accepted, expected {:?}", case.name, case.expected),
            Err(e) => e,
        };
        assert_eq!(err, case.expected, "case {}", case.name);
        let message = err.to_string();
        for needle in &case.needles {
            assert!(
                message.contains(needle),
                "case {}: message {message:?} lacks {needle:?}",
                case.name
            );
        }
    }
}

#[test]
fn first_error_in_order_wins() {
    // NaN (4) comes before the duplicate face (6) and the missing supports (12).
    let (mut p, mut f) = grid(2, 2);
    p[3][1] = f64::NAN;
    f.push([4, 3, 0]);
    f.push(f[0]);
    assert_eq!(
        Mesh::new(p, f, &[]).unwrap_err(),
        Error::NonFiniteCoordinate { vertex: 3 }
    );
    // Several duplicates: the one with the smallest later face id.
    let (p, mut f) = grid(2, 2);
    f.push(f[5]); // face 8
    f.push([f[1][2], f[1][0], f[1][1]]); // face 9
    f.swap(8, 9);
    assert_eq!(
        Mesh::new(p, f, &[0]).unwrap_err(),
        Error::DuplicateFace { face: 8, first: 1 }
    );
}

#[test]
fn unreferenced_nan_vertex_is_ignored() {
    let (mut p, f) = grid(2, 2);
    p.insert(0, [f64::NAN, f64::INFINITY, 0.0]);
    let f: Faces = f.iter().map(|t| t.map(|i| i + 1)).collect();
    let mesh = Mesh::new(p, f, &[1]).expect("valid");
    assert_eq!(mesh.unreferenced, vec![0]);
    assert!(!mesh.referenced[0]);
    assert_eq!(mesh.vertex_component[0], u32::MAX);
    assert!(!mesh.is_free_boundary(0) && !mesh.is_non_anchored(0));
    assert!(mesh.edges_at(0).is_empty());
    check_invariants(&mesh);
}

/// New heights keep the plan's connectivity; wrong lengths, NaN or huge heights of referenced
/// vertices are refused with the vertex named; an unreferenced vertex's height is free.
#[test]
fn with_heights_changes_only_heights_and_checks_them() {
    let (mut p, f) = grid(3, 2);
    p.insert(0, [f64::NAN, 0.0, 0.0]);
    let f: Faces = f.iter().map(|t| t.map(|i| i + 1)).collect();
    let mesh = Mesh::new(p, f, &[1, 4]).expect("valid");
    let z: Vec<f64> = (0..mesh.n_vertices()).map(|v| v as f64 / 7.0).collect();
    let lifted = mesh.clone().with_heights(&z).expect("finite heights");
    for (v, (a, b)) in mesh.positions().iter().zip(lifted.positions()).enumerate() {
        assert_eq!([a[0], a[1], z[v]].map(f64::to_bits), b.map(f64::to_bits));
    }
    assert_eq!(lifted.edges(), mesh.edges());
    assert_eq!(lifted.loops(), mesh.loops());
    assert_eq!(lifted.anchored_ids(), [1, 4]);
    let mut nan_unused = z.clone();
    nan_unused[0] = f64::NAN;
    assert!(mesh.clone().with_heights(&nan_unused).is_ok());
    let message = |z: &[f64]| mesh.clone().with_heights(z).unwrap_err().to_string();
    assert!(message(&z[1..]).contains("12 heights for 13 vertices"));
    let mut bad = z.clone();
    bad[5] = f64::INFINITY;
    assert_eq!(
        mesh.clone().with_heights(&bad).unwrap_err(),
        Error::NonFiniteCoordinate { vertex: 5 }
    );
    bad[5] = 1e200;
    let text = message(&bad);
    assert!(
        text.contains("heights") && text.contains("vertex 5"),
        "{text}"
    );
}

/// Invariants every valid mesh satisfies.
fn check_invariants(mesh: &Mesh) {
    let n = mesh.n_vertices();
    for (t, f) in mesh.faces.iter().enumerate() {
        assert!(plan_area(&mesh.positions, f) > 0.0, "face {t} not CCW");
        for k in 0..3 {
            let e = mesh.face_edges[t][k] as usize;
            let (a, b) = (f[k], f[(k + 1) % 3]);
            assert_eq!(mesh.edge_between(a, b), Some(e));
            let edge = mesh.edges[e];
            let side = if a < b { edge.left } else { edge.right };
            let side = side.expect("face side");
            assert_eq!(side.face as usize, t);
            assert_eq!(side.opposite, f[(k + 2) % 3]);
        }
        assert_eq!(mesh.face_component[t], mesh.vertex_component[f[0] as usize]);
    }
    assert!(mesh.edges.windows(2).all(|w| w[0].v < w[1].v));
    let mut boundary_edges = 0;
    for (e, edge) in mesh.edges.iter().enumerate() {
        assert!(edge.v[0] < edge.v[1]);
        assert!(edge.left.is_some() || edge.right.is_some());
        boundary_edges += usize::from(edge.is_boundary());
        // The left face's opposite vertex is to the left of v0→v1 in plan.
        if let Some(side) = edge.left {
            let tri = [edge.v[0], edge.v[1], side.opposite];
            assert!(plan_area(&mesh.positions, &tri) > 0.0, "edge {e}");
        }
        if let Some(side) = edge.right {
            let tri = [edge.v[1], edge.v[0], side.opposite];
            assert!(plan_area(&mesh.positions, &tri) > 0.0, "edge {e}");
        }
        for v in edge.v {
            assert!(mesh.edges_at(v as usize).contains(&(e as u32)));
            assert!(mesh.on_boundary[v as usize] || !edge.is_boundary());
        }
    }
    // Each face has 3 edges; interior edges are counted twice: 2E = 3F + B.
    assert_eq!(2 * mesh.edges.len(), 3 * mesh.faces.len() + boundary_edges);
    assert_eq!(mesh.vertex_edge_start.len(), n + 1);
    assert_eq!(mesh.vertex_edges.len(), 2 * mesh.edges.len());
    let loop_len: usize = mesh.loops.iter().map(|l| l.vertices.len()).sum();
    assert_eq!(loop_len, boundary_edges);
    for l in &mesh.loops {
        for (i, &a) in l.vertices.iter().enumerate() {
            let b = l.vertices[(i + 1) % l.vertices.len()];
            let e = mesh.edge_between(a, b).expect("loop edge");
            let edge = mesh.edges[e];
            assert!(edge.is_boundary());
            // Surface on the left of a→b.
            assert_eq!(a < b, edge.left.is_some());
            assert_eq!(mesh.vertex_component[a as usize], l.component);
        }
        assert_eq!(l.is_outer, l.signed_area > 0.0);
    }
    for c in 0..mesh.n_components as u32 {
        let outer = mesh.loops.iter().filter(|l| l.component == c && l.is_outer);
        assert_eq!(outer.count(), 1, "component {c}");
    }
    for v in 0..n {
        assert_eq!(mesh.referenced[v], !mesh.unreferenced.contains(&(v as u32)));
        assert_eq!(
            mesh.is_free_boundary(v),
            mesh.referenced[v] && mesh.on_boundary[v] && !mesh.anchored[v]
        );
    }
}

#[test]
fn grid_counts_and_loop() {
    let (p, f) = grid(4, 3);
    let mesh = Mesh::new(p, f, &[0, 4]).expect("valid grid");
    check_invariants(&mesh);
    let (nv, nf, boundary) = (20, 24, 14);
    assert_eq!(mesh.n_vertices(), nv);
    assert_eq!(mesh.n_faces(), nf);
    assert_eq!(mesh.n_edges(), 3 * nf / 2 + boundary / 2);
    assert_eq!(
        nv + nf,
        mesh.n_edges() + 1,
        "Euler characteristic of a disk"
    );
    assert!(!mesh.reversed);
    assert_eq!(mesh.n_components, 1);
    assert_eq!(mesh.loops.len(), 1);
    let outer = &mesh.loops[0];
    assert!(outer.is_outer);
    assert_eq!(outer.vertices.len(), boundary);
    assert_eq!(outer.vertices[..6], [0, 1, 2, 3, 4, 9]);
    assert!((outer.signed_area - 12.0).abs() < 1e-12);
    assert_eq!(mesh.holes().count(), 0);
    assert!(mesh.unreferenced.is_empty());
    assert_eq!(mesh.on_boundary.iter().filter(|&&b| b).count(), boundary);
    assert!(mesh.is_free_boundary(1) && !mesh.is_free_boundary(0) && !mesh.is_free_boundary(6));
    assert!(mesh.is_non_anchored(6) && !mesh.is_non_anchored(4));
    assert_eq!(
        mesh.edge_between(6, 0),
        Some(mesh.edge_between(0, 6).unwrap())
    );
    assert_eq!(mesh.edge_between(0, 7), None);
    assert_eq!(mesh.edge_between(0, 99), None);
    assert_eq!(mesh.edges_at(6).len(), 6);
    assert!(mesh.edges_at(1000).is_empty());
}

#[test]
fn grid_with_hole() {
    // Remove square (1, 1) of a 4 × 4 grid: faces 2 (4 + 1) and 2 (4 + 1) + 1.
    let (p, mut f) = grid(4, 4);
    f.drain(10..12);
    let mesh = Mesh::new(p, f, &[0]).expect("valid");
    check_invariants(&mesh);
    assert_eq!(mesh.loops.len(), 2);
    let holes: Vec<usize> = mesh.holes().collect();
    assert_eq!(holes.len(), 1);
    let hole = &mesh.loops[holes[0]];
    // Corners (1,1)=6, (2,1)=7, (2,2)=12, (1,2)=11, clockwise with the surface on the left.
    assert_eq!(hole.vertices, vec![6, 11, 12, 7]);
    assert!((hole.signed_area + 1.0).abs() < 1e-12);
    let outer = mesh.loops.iter().find(|l| l.is_outer).unwrap();
    assert!((outer.signed_area - 16.0).abs() < 1e-12);
    assert!(mesh.on_boundary[6] && !mesh.on_boundary[18]);
}

#[test]
fn clockwise_input_is_reversed() {
    let (p, f) = grid(3, 2);
    let cw = reversed(&f);
    let mesh = Mesh::new(p, cw.clone(), &[0]).expect("valid");
    assert!(mesh.reversed);
    assert_eq!(mesh.faces, f, "faces come back counter-clockwise");
    check_invariants(&mesh);
    assert!(mesh.loops[0].signed_area > 0.0);
    // Reversing the winding of one face only breaks the orientation consistency.
    let (p, mut f) = grid(3, 2);
    f[0] = [f[0][0], f[0][2], f[0][1]];
    let err = Mesh::new(p, f, &[0]).unwrap_err();
    assert!(
        matches!(err, Error::InconsistentOrientation { .. }),
        "{err}"
    );
}

#[test]
fn interior_anchored_vertex_accepted() {
    let (p, f) = grid(2, 2);
    let mesh = Mesh::new(p, f, &[4]).expect("valid");
    check_invariants(&mesh);
    assert!(mesh.anchored[4] && !mesh.on_boundary[4]);
    assert!(!mesh.is_non_anchored(4));
    assert!((0..9).filter(|&v| v != 4).all(|v| mesh.is_free_boundary(v)));
}

#[test]
fn two_supported_components() {
    let (mut p, mut f) = grid(2, 2);
    let (p2, f2) = grid(1, 1);
    let offset = p.len() as u32;
    p.extend(p2.iter().map(|q| [q[0] + 5.0, q[1], q[2]]));
    f.extend(f2.iter().map(|t| t.map(|i| i + offset)));
    let mesh = Mesh::new(p, f, &[10, 0]).expect("valid");
    check_invariants(&mesh);
    assert_eq!(mesh.n_components, 2);
    assert_eq!(mesh.loops.len(), 2);
    assert!(mesh.loops.iter().all(|l| l.is_outer));
    assert_eq!(mesh.vertex_component[..9], [0; 9]);
    assert_eq!(mesh.vertex_component[9..], [1; 4]);
    assert_eq!(mesh.face_component[8..], [1, 1]);
    assert_eq!(mesh.loops[1].component, 1);
    // Unsupported second component when only the first is anchored.
    let err = Mesh::new(mesh.positions.clone(), mesh.faces.clone(), &[0]).unwrap_err();
    assert_eq!(
        err,
        Error::UnsupportedComponent {
            component: 1,
            vertices: vec![9, 10, 11, 12]
        }
    );
}

#[test]
fn single_triangle() {
    let mesh = Mesh::new(
        plan(&[[0.0, 0.0], [0.0, 1.0], [1.0, 0.0]]),
        vec![[0, 1, 2]],
        &[1],
    )
    .expect("valid");
    assert!(mesh.reversed);
    assert_eq!(mesh.faces, vec![[0, 2, 1]]);
    check_invariants(&mesh);
}

#[test]
fn large_grid() {
    // About 100k vertices: the build is O(n log n); this only checks it completes and counts.
    let (p, f) = grid(320, 310);
    let (nv, nf) = (p.len(), f.len());
    let mesh = Mesh::new(p, f, &[0]).expect("valid");
    assert_eq!(nv, 321 * 311);
    assert_eq!(mesh.n_edges(), 3 * nf / 2 + (320 + 310));
    assert_eq!(mesh.loops.len(), 1);
    assert_eq!(mesh.loops[0].vertices.len(), 2 * (320 + 310));
}

/// xorshift64*: a tiny deterministic generator for the randomized tests.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[test]
fn mutated_grids_never_panic_and_valid_ones_satisfy_invariants() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let mut accepted = 0;
    for round in 0..2000 {
        let (mut p, mut f) = grid(5, 4);
        let n = p.len() as u64;
        // Drop faces: holes, bow-ties, separate components.
        let drop = rng.below(4);
        f.retain(|_| drop == 0 || rng.below(10) >= drop);
        // Jitter the plan: folds and overlaps when large.
        let amp = [0.0, 0.1, 0.45, 1.5][rng.below(4) as usize];
        for q in &mut p {
            q[0] += amp * (rng.unit() - 0.5);
            q[1] += amp * (rng.unit() - 0.5);
        }
        // Relabel vertices and faces; sometimes reverse everything.
        let mut perm: Vec<u32> = (0..n as u32).collect();
        for i in (1..perm.len()).rev() {
            perm.swap(i, rng.below(i as u64 + 1) as usize);
        }
        let mut q = vec![[0.0; 3]; p.len()];
        for (v, &to) in perm.iter().enumerate() {
            q[to as usize] = p[v];
        }
        let reverse = rng.below(2) == 0;
        let mut f: Faces = f
            .iter()
            .map(|t| {
                let t = t.map(|i| perm[i as usize]);
                if reverse {
                    [t[0], t[2], t[1]]
                } else {
                    t
                }
            })
            .collect();
        for i in (1..f.len()).rev() {
            f.swap(i, rng.below(i as u64 + 1) as usize);
        }
        // Occasional hostile edits.
        match rng.below(12) {
            0 if !f.is_empty() => f[0][1] = f[0][0],
            1 if !f.is_empty() => f.push([f[0][1], f[0][2], f[0][0]]),
            2 if !f.is_empty() => f[0][2] = n as u32 + 3,
            3 => q[rng.below(n) as usize][2] = f64::NAN,
            4 if f.len() > 2 => f[1] = [f[1][0], f[1][2], f[1][1]],
            _ => {}
        }
        let anchored: Vec<u32> = (0..n as u32).filter(|_| rng.below(8) == 0).collect();
        match Mesh::new(q, f, &anchored) {
            Ok(mesh) => {
                accepted += 1;
                assert_eq!(mesh.reversed, reverse, "round {round}");
                check_invariants(&mesh);
            }
            Err(e) => assert!(!e.to_string().is_empty()),
        }
    }
    assert!(accepted > 100, "only {accepted} meshes accepted");
}

//! One read path: the same mesh file read by the Rust API (`io::read_model`), the C ABI
//! (`vsr_mesh_read`) and the formfind command line gives the same mesh, supports and stress,
//! bit for bit, in every format and for every shared model; and `read_model`'s own choices
//! (supports, welding, up axis, diagonals) as documented.

mod capi_support;
mod formfind_support;

use std::ffi::CString;
use std::fs;
use std::path::Path;
use std::ptr::{null, null_mut};

use capi_support::{assert_ok, settings, snapshot, Snapshot};
use formfind_support::{models_dir, read_json, run, Scratch, MODELS};
use serde_json::Value;
use voussoir::capi::*;
use voussoir::io::{self, read_model, ReadOptions, Supports, UpAxis};
use voussoir::{analyse, Problem, StressResult, StressSettings};

/// Every format `read_mesh` reads: its extension, and `-ascii` for the text variant of a
/// binary one (3MF is written only).
const FORMATS: [&str; 6] = ["obj", "off", "ply", "ply-ascii", "stl", "stl-ascii"];

fn c(path: &Path) -> CString {
    CString::new(path.to_str().unwrap()).unwrap()
}

/// The model `name` written in `format` (one of [`FORMATS`]) into `dir`.
fn model_file(models: &Path, dir: &Scratch, name: &str, format: &str) -> std::path::PathBuf {
    let (positions, faces) = io::read_mesh(&models.join(format!("{name}.obj"))).unwrap();
    let (extension, ascii) = match format.strip_suffix("-ascii") {
        Some(e) => (e, true),
        None => (format, false),
    };
    let path = dir.path(&format!("{name}-{format}.{extension}"));
    let kind = io::MeshFormat::from_path(&path).unwrap();
    let kind = if ascii { kind.ascii() } else { kind };
    io::write_mesh_as(&path, kind, &positions, &faces).unwrap();
    if format != "obj" && format != "off" {
        assert_eq!(fs::read(&path).unwrap().is_ascii(), ascii, "{format}");
    }
    path
}

/// `vsr_mesh_read` of `path` with the supports file `json` and the default tolerances, then
/// `vsr_analyse` with default settings: the result's snapshot and the welded ids.
fn through_c(path: &Path, json: &Path) -> (Snapshot, Vec<u32>) {
    let (path, json) = (c(path), c(json));
    let mut mesh = null_mut();
    let status = unsafe {
        vsr_mesh_read(
            path.as_ptr(),
            json.as_ptr(),
            null(),
            0,
            io::DEFAULT_WELD_TOLERANCE,
            voussoir::DEFAULT_REPAIR_TOLERANCE,
            null_mut(),
            &mut mesh,
        )
    };
    assert_ok(status);
    let s = settings();
    let mut result = null_mut();
    assert_ok(unsafe { vsr_analyse(mesh, s, &mut result) });
    let snap = snapshot(result);
    let mut n = 0;
    assert_ok(unsafe { vsr_mesh_welded_ids(mesh, null_mut(), 0, &mut n) });
    let mut ids = vec![0u32; n];
    assert_ok(unsafe { vsr_mesh_welded_ids(mesh, ids.as_mut_ptr(), n, &mut n) });
    unsafe {
        vsr_result_destroy(result);
        vsr_settings_destroy(s);
        vsr_mesh_destroy(mesh);
    }
    (snap, ids)
}

/// The arrays of `snapshot` (in its order) computed from the Rust API's answer.
fn rust_snapshot(problem: &Problem, s: &StressResult) -> Vec<Vec<u64>> {
    let flat2 = |rows: &[[f64; 2]]| rows.iter().flatten().map(|x| x.to_bits()).collect();
    let flat = |xs: &[f64]| xs.iter().map(|x| x.to_bits()).collect();
    let positions: Vec<u64> = (problem.mesh.positions().iter())
        .flatten()
        .map(|x| x.to_bits())
        .collect();
    let segments: Vec<u64> = (s.force_diagram.segments.iter())
        .flatten()
        .flat_map(|[a, b]| [a[0], a[1], b[0], b[1]])
        .map(f64::to_bits)
        .collect();
    vec![
        positions,
        flat(&s.force_densities),
        flat(&s.airy),
        flat(&s.weights),
        flat(&s.tau),
        flat2(&s.external_horizontal),
        flat(&s.loads),
        flat(&s.residuals),
        flat2(&s.horizontal_imbalance),
        flat2(&s.force_diagram.centres),
        segments,
    ]
}

#[test]
fn rust_and_c_read_every_format_of_every_shared_model_alike() {
    let Some(models) = models_dir() else { return };
    let dir = Scratch::new("read-model-c");
    for name in MODELS {
        let json = models.join(format!("{name}.json"));
        for format in FORMATS {
            let path = model_file(&models, &dir, name, format);
            let options = ReadOptions::new(Supports::File(json.clone()));
            let model = read_model(&path, &options).unwrap_or_else(|e| panic!("{name}: {e}"));
            let (snap, welded_ids) = through_c(&path, &json);
            assert_eq!(welded_ids, model.welded_ids, "{name}.{format}");
            // Analyses are the costly part: every model as OBJ and STL (whose single
            // precision makes another mesh), the small ones in every format.
            if format == "obj" || format == "stl" || model.problem.mesh.n_vertices() < 400 {
                let s = analyse(&model.problem, &StressSettings::default()).unwrap();
                let mine = rust_snapshot(&model.problem, &s);
                assert!(mine == snap.arrays, "{name}.{format}: C and Rust differ");
            }
        }
    }
}

#[test]
fn load_model_is_read_model_with_a_supports_file() {
    let Some(models) = models_dir() else { return };
    for name in MODELS {
        let (obj, json) = (
            models.join(format!("{name}.obj")),
            models.join(format!("{name}.json")),
        );
        let problem = io::load_model(&obj, &json).unwrap();
        let model = read_model(&obj, &ReadOptions::new(Supports::File(json))).unwrap();
        assert_eq!(
            problem.mesh.positions(),
            model.problem.mesh.positions(),
            "{name}"
        );
        assert_eq!(problem.mesh.faces(), model.problem.mesh.faces(), "{name}");
        assert_eq!(
            problem.mesh.anchored(),
            model.problem.mesh.anchored(),
            "{name}"
        );
        // The shared models are clean triangle meshes: nothing is welded or mended, so the
        // problem is the file's mesh as it is.
        let (positions, faces) = io::read_mesh(&obj).unwrap();
        assert_eq!(model.weld.as_ref().unwrap().merged, 0, "{name}");
        assert!(model.repairs.is_empty(), "{name}");
        assert!(model.diagonals.is_empty(), "{name}");
        assert_eq!(problem.mesh.positions(), positions, "{name}");
        assert_eq!(problem.mesh.input_faces(), faces, "{name}");
    }
}

/// The JSON value of `value` as the report's parser reads it (the same lossy parse on both
/// sides: equal values mean equal shortest decimals, so equal bits).
fn as_report<T: serde::Serialize>(value: &T) -> Value {
    serde_json::from_str(&serde_json::to_string(value).unwrap()).unwrap()
}

/// formfind `--stress-only` on `args` in `dir`: its report.
fn cli_stress(dir: &Scratch, args: &[&str]) -> Value {
    let report = dir.path("r.json");
    let mut all = args.to_vec();
    all.extend([
        "--stress-only",
        "--out",
        "out.obj",
        "--report",
        report.to_str().unwrap(),
        "--pictures",
        "pics",
    ]);
    let out = run(&dir.0, &all);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    read_json(&report)
}

/// Asserts that a formfind report holds the Rust API's analysis of `model`.
fn assert_report_is(report: &Value, model: &io::Model, what: &str) {
    let p = &model.problem;
    let s = analyse(p, &StressSettings::default()).unwrap();
    let anchored: Vec<usize> = (0..p.mesh.n_vertices())
        .filter(|&v| p.mesh.anchored()[v])
        .collect();
    let edges: Vec<[u32; 2]> = p.mesh.edges().iter().map(|e| e.v).collect();
    let q: Vec<f64> = s.force_densities.iter().map(|q| q + 0.0).collect();
    assert_eq!(report["anchored"], as_report(&anchored), "{what}");
    assert_eq!(report["edges"], as_report(&edges), "{what}");
    assert_eq!(report["force_densities"], as_report(&q), "{what}");
    assert_eq!(report["residuals"], as_report(&s.residuals), "{what}");
}

#[test]
fn the_command_line_reads_every_format_as_the_library_does() {
    let Some(models) = models_dir() else { return };
    let dir = Scratch::new("read-model-cli");
    let json = models.join("neumunster.json");
    for format in FORMATS {
        let path = model_file(&models, &dir, "neumunster", format);
        let args = [path.to_str().unwrap(), "--supports", json.to_str().unwrap()];
        let report = cli_stress(&dir, &args);
        let model = read_model(&path, &ReadOptions::new(Supports::File(json.clone()))).unwrap();
        assert_report_is(&report, &model, format);
        // The input positions come back as read (the form-found mesh of --stress-only).
        let (out, _) = io::read_mesh(&dir.path("out.obj")).unwrap();
        assert_eq!(out, model.problem.mesh.positions(), "{format}");
    }
    // Supports chosen by the library: the boundary, the lowest vertices.
    let obj = models.join("free_vault.obj");
    for (flags, supports) in [
        (vec!["--anchor-boundary"], Supports::Boundary),
        (
            vec!["--anchor-lowest", "0.02"],
            Supports::Lowest {
                tolerance: 0.02,
                absolute: false,
            },
        ),
    ] {
        let mut args = vec![obj.to_str().unwrap()];
        args.extend(flags.iter().copied());
        let report = cli_stress(&dir, &args);
        let model = read_model(&obj, &ReadOptions::new(supports)).unwrap();
        assert_report_is(&report, &model, &flags.join(" "));
    }
}

/// A 3 × 3 grid of quads over the unit square, each split by the OBJ reader along one
/// diagonal, heights of a dome; written Y-up when `y_up`. The outer ring is its boundary.
fn quad_grid(y_up: bool) -> String {
    let mut text = String::new();
    for j in 0..4 {
        for i in 0..4 {
            let (x, y) = (f64::from(i) / 3.0, f64::from(j) / 3.0);
            let z = 0.5 - (x - 0.5).powi(2) - (y - 0.5).powi(2);
            let p = if y_up { [x, z, -y] } else { [x, y, z] };
            text += &format!("v {} {} {}\n", p[0], p[1], p[2]);
        }
    }
    for j in 0..3 {
        for i in 0..3 {
            let v = |a: i32, b: i32| 4 * (j + b) + i + a + 1;
            text += &format!("f {} {} {} {}\n", v(0, 0), v(1, 0), v(1, 1), v(0, 1));
        }
    }
    text
}

#[test]
fn read_model_chooses_supports_turns_y_up_and_marks_diagonals() {
    let dir = Scratch::new("read-model-own");
    let (z, y) = (dir.path("z.obj"), dir.path("y.obj"));
    fs::write(&z, quad_grid(false)).unwrap();
    fs::write(&y, quad_grid(true)).unwrap();
    let boundary = ReadOptions::new(Supports::Boundary);
    let model = read_model(&z, &boundary).unwrap();
    let mesh = &model.problem.mesh;
    let anchored: Vec<u32> = (0..16).filter(|&v| mesh.anchored()[v as usize]).collect();
    assert_eq!(anchored, [0, 1, 2, 3, 4, 7, 8, 11, 12, 13, 14, 15]);
    // Nine quads, nine diagonals, all interior edges, all marked.
    assert_eq!(model.diagonals.len(), 9);
    let marked = model
        .problem
        .polygon_diagonal
        .iter()
        .filter(|d| **d)
        .count();
    assert_eq!(marked, 9);
    // The lowest vertices of the dome: its four corners.
    let lowest = ReadOptions::new(Supports::Lowest {
        tolerance: 1e-9,
        absolute: true,
    });
    let corners = read_model(&z, &lowest).unwrap().problem.mesh.anchored_ids();
    assert_eq!(corners, [0, 3, 12, 15]);
    // Y-up: refused as it stands (a vertical plan), the same mesh with `up` y.
    assert!(read_model(&y, &boundary).is_err());
    let turned = read_model(&y, &boundary.clone().with_up(UpAxis::Y)).unwrap();
    for (a, b) in turned.problem.mesh.positions().iter().zip(mesh.positions()) {
        for k in 0..3 {
            assert!((a[k] - b[k]).abs() < 1e-15, "{a:?} {b:?}");
        }
    }
    assert_eq!(turned.options.up, UpAxis::Y);
    let p = [1.0, 2.0, 3.0];
    assert_eq!(UpAxis::Y.to_file(UpAxis::Y.to_z_up(p)), p);
}

#[test]
fn read_model_welds_unless_told_not_to_and_checks_its_options() {
    let dir = Scratch::new("read-model-weld");
    let path = dir.path("z.obj");
    // The grid with vertex 5 given twice, the copy (vertex 16) used by the middle quad.
    let text = quad_grid(false);
    let v5 = text.lines().nth(5).unwrap().to_string();
    let text = format!("{text}{v5}\n").replace("f 6 7 11 10\n", "f 17 7 11 10\n");
    assert!(text.contains("f 17 7 11 10"));
    fs::write(&path, &text).unwrap();
    let welded = read_model(&path, &ReadOptions::new(Supports::Boundary)).unwrap();
    let weld = welded.weld.as_ref().unwrap();
    assert_eq!((weld.input_vertices, weld.merged), (17, 1));
    assert_eq!(welded.welded_ids[16], 5);
    assert!(welded.problem.mesh.unreferenced().is_empty());
    // Unwelded, the copy is a vertex of its own and vertex 5 a boundary vertex.
    let kept = ReadOptions::new(Supports::Boundary).with_weld_tolerance(None);
    let unwelded = read_model(&path, &kept);
    assert!(unwelded.is_err() || unwelded.unwrap().weld.is_none());
    for (options, name) in [
        (
            ReadOptions::new(Supports::Boundary).with_weld_tolerance(Some(f64::NAN)),
            "weld_tolerance",
        ),
        (
            ReadOptions::new(Supports::Boundary).with_repair_tolerance(-1.0),
            "repair_tolerance",
        ),
        (
            ReadOptions::new(Supports::Lowest {
                tolerance: f64::INFINITY,
                absolute: true,
            }),
            "anchor_lowest",
        ),
    ] {
        match read_model(&path, &options) {
            Err(voussoir::Error::InvalidArgument { name: n, .. }) => assert_eq!(n, name),
            other => panic!("{name}: {other:?}"),
        }
    }
    // Errors of the supports file are told apart from the mesh file's.
    let missing = ReadOptions::new(Supports::File(dir.path("none.json")));
    let e = read_model(&path, &missing).unwrap_err();
    assert!(missing.blames_supports_file(&e), "{e}");
    let e = read_model(&dir.path("none.obj"), &missing).unwrap_err();
    assert!(!missing.blames_supports_file(&e), "{e}");
}

/// A file with no vertex, or with vertices but no face, is an empty mesh whatever supports
/// are asked for, not an anchored id out of range.
#[test]
fn an_empty_mesh_file_is_called_empty_before_its_supports_are_read() {
    let dir = Scratch::new("read-model-empty");
    let supports = dir.path("supports.json");
    fs::write(&supports, r#"{"anchored": [0, 1, 2]}"#).unwrap();
    for (name, text) in [("none.obj", ""), ("points.obj", "v 0 0 0\nv 1 0 0\n")] {
        let path = dir.path(name);
        fs::write(&path, text).unwrap();
        for options in [
            ReadOptions::new(Supports::File(supports.clone())),
            ReadOptions::new(Supports::Ids(vec![0, 1, 2])),
            ReadOptions::new(Supports::Boundary),
        ] {
            let e = read_model(&path, &options).unwrap_err();
            assert!(matches!(e, voussoir::Error::EmptyMesh), "{name}: {e}");
        }
    }
}

/// A face of tiny but positive plan area (a near-vertical strip as exporters write it) is
/// mended by default and, with no repair asked for, a degenerate face named: left as drawn
/// it would pass validation and carry force densities many orders of magnitude apart.
#[test]
fn no_repair_rejects_the_slivers_the_default_mends() {
    let dir = Scratch::new("read-model-sliver");
    let path = dir.path("sliver.obj");
    // A unit square split at its centre, with a fifth vertex 1e-7 outside the bottom edge.
    let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 0.3\nv 0.5 -1e-7 0\n\
                f 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\nf 1 6 2\n";
    fs::write(&path, text).unwrap();
    let mended = read_model(&path, &ReadOptions::new(Supports::Boundary)).unwrap();
    assert!(!mended.repairs.is_empty());
    let strict = ReadOptions::new(Supports::Boundary).with_repair_tolerance(0.0);
    match read_model(&path, &strict) {
        Err(voussoir::Error::DegenerateFaces { faces }) => assert_eq!(faces, [4]),
        other => panic!("{other:?}"),
    }
}

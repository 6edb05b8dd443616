//! `formfind --assess`: the thrust surface written as OUT with the report's "assessment",
//! checked from the outputs alone (equilibrium, compression, bounds, thrust) and against the
//! library's `assess` bit for bit; the envelope and load-pattern options; bad input (exit 2,
//! nothing written); and the pictures (the section and the 3-D view).

mod capi_support;
#[allow(unused_imports)] // models_dir: no shared model here
mod formfind_support;

use std::fs;
use std::path::Path;

use capi_support::Dome;
use formfind_support::views::{match_faces, view_polygons};
use formfind_support::xml::{parse_xml, Element};
use formfind_support::*;
use serde_json::Value;
use voussoir::io::{read_model, ReadOptions, Supports};
use voussoir::report::AssessmentReport;
use voussoir::{assess, AssessSettings, Envelope, Mesh, Objective, Problem, Thickness};

/// The 60° dome of the C ABI tests: 37 vertices, the rim (12) anchored.
fn dome() -> Dome {
    Dome::new(3, 12)
}

fn obj_text(positions: &[f64], triangles: &[u32]) -> String {
    let mut text = String::new();
    for p in positions.chunks_exact(3) {
        text += &format!("v {:?} {:?} {:?}\n", p[0], p[1], p[2]);
    }
    for t in triangles.chunks_exact(3) {
        text += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    text
}

fn library_mesh(d: &Dome) -> Mesh {
    let positions = d
        .positions
        .chunks_exact(3)
        .map(|p| [p[0], p[1], p[2]])
        .collect();
    let faces = d
        .triangles
        .chunks_exact(3)
        .map(|t| [t[0], t[1], t[2]])
        .collect();
    Mesh::new(positions, faces, &d.anchored).unwrap()
}

/// Runs formfind in `dir` and returns (exit code, stderr).
fn formfind_in(dir: &Scratch, args: &[&str]) -> (i32, String) {
    let out = run(&dir.0, args);
    let code = out.status.code().expect("exit code");
    (code, String::from_utf8_lossy(&out.stderr).into_owned())
}

/// A scratch folder with the dome as `dome.obj`.
fn with_dome(name: &str) -> Scratch {
    with_mesh(name, &dome())
}

/// A scratch directory holding `d` as dome.obj.
fn with_mesh(name: &str, d: &Dome) -> Scratch {
    let dir = Scratch::new(name);
    fs::write(dir.path("dome.obj"), obj_text(&d.positions, &d.triangles)).unwrap();
    dir
}

fn run_dome(dir: &Scratch, extra: &[&str]) -> (i32, String) {
    let mut args = vec![
        "dome.obj",
        "--anchor-boundary",
        "--out",
        "t.obj",
        "--report",
        "r.json",
        "--pictures",
        "pics",
    ];
    args.extend_from_slice(extra);
    formfind_in(dir, &args)
}

fn edges_of(r: &Value) -> Vec<[usize; 2]> {
    (r["edges"].as_array().unwrap().iter())
        .map(|e| [0, 1].map(|k| e[k].as_u64().unwrap() as usize))
        .collect()
}

/// Recomputes the certificate from OUT and the report alone: vertical equilibrium (ε∞ below
/// 1e-6 and equal to the reported one), horizontal equilibrium, q ≥ 0, every height within the
/// reported bounds (1e-9 of the plan diagonal), and the horizontal thrust Σ |H_a| over the
/// supports. Returns the recomputed thrust.
fn check_certificate(out: &Path, r: &Value) -> f64 {
    let (pos, faces) = read_obj(out);
    let a = &r["assessment"];
    assert_eq!(a["feasible"], true, "{a}");
    let n = pos.len();
    let (edges, q, p) = (
        edges_of(r),
        numbers(&r["force_densities"]),
        numbers(&r["loads"]),
    );
    let (lower, upper) = (
        numbers(&a["bounds"]["lower"]),
        numbers(&a["bounds"]["upper"]),
    );
    assert_eq!((q.len(), p.len(), lower.len()), (edges.len(), n, n));
    let mut anchored = vec![false; n];
    for v in r["anchored"].as_array().unwrap() {
        anchored[v.as_u64().unwrap() as usize] = true;
    }
    let q_max = q.iter().fold(0.0f64, |m, &x| m.max(x));
    assert!(q.iter().all(|&x| x >= -1e-12 * q_max), "tension");
    let mut vertical = p.iter().map(|x| -x).collect::<Vec<f64>>();
    let mut horizontal = vec![[0.0; 2]; n];
    let mut reaction = vec![[0.0; 2]; n];
    for (&[i, j], &qe) in edges.iter().zip(&q) {
        for (a, b) in [(i, j), (j, i)] {
            vertical[a] += qe * (pos[a][2] - pos[b][2]);
            for d in 0..2 {
                horizontal[a][d] += qe * (pos[a][d] - pos[b][d]);
                if anchored[a] && !anchored[b] {
                    reaction[a][d] += qe * (pos[a][d] - pos[b][d]);
                }
            }
        }
    }
    let free: Vec<usize> = (0..n).filter(|&v| !anchored[v]).collect();
    let mean = free.iter().map(|&v| p[v]).sum::<f64>() / free.len() as f64;
    let worst = free.iter().map(|&v| vertical[v].abs()).fold(0.0, f64::max);
    let eps = worst / mean;
    assert!(eps < 1e-6, "recomputed ε∞ = {eps:e}");
    // The library divides by the mean self-weight, without the live load of max-load.
    let pattern = match a["load_pattern"].as_array() {
        Some(_) => numbers(&a["load_pattern"]),
        None => vec![0.0; n],
    };
    let lambda = a["load_factor"].as_f64().unwrap();
    let dead = free
        .iter()
        .map(|&v| p[v] - lambda * pattern[v])
        .sum::<f64>()
        / free.len() as f64;
    let reported = a["eps_inf"].as_f64().unwrap();
    assert!(
        [eps, worst / dead]
            .iter()
            .any(|e| (e - reported).abs() <= 1e-12 + 1e-6 * reported),
        "{eps} vs {reported}"
    );
    for &v in &free {
        let h = horizontal[v][0].hypot(horizontal[v][1]);
        assert!(h <= 1e-9 * mean, "vertex {v}: horizontal imbalance {h:e}");
    }
    let (lo, hi) = plan_box(&pos, &faces);
    let slack = 1e-9 * (hi[0] - lo[0]).hypot(hi[1] - lo[1]);
    for v in 0..n {
        let z = pos[v][2];
        assert!(
            z >= lower[v] - slack && z <= upper[v] + slack,
            "vertex {v}: {z} outside [{}, {}]",
            lower[v],
            upper[v]
        );
    }
    let thrust: f64 = (0..n)
        .filter(|&v| anchored[v])
        .map(|v| reaction[v][0].hypot(reaction[v][1]))
        .sum();
    let reported = a["thrust_horizontal"].as_f64().unwrap();
    assert!(
        (thrust - reported).abs() <= 1e-9 * reported,
        "thrust {thrust} vs {reported}"
    );
    thrust
}

fn plan_box(pos: &[[f64; 3]], faces: &[[usize; 3]]) -> ([f64; 2], [f64; 2]) {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for &v in faces.iter().flatten() {
        for d in 0..2 {
            lo[d] = lo[d].min(pos[v][d]);
            hi[d] = hi[d].max(pos[v][d]);
        }
    }
    (lo, hi)
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

#[test]
fn fit_writes_the_librarys_certified_thrust_surface() {
    let dir = with_dome("assess-fit");
    let (code, err) = run_dome(&dir, &["--assess", "fit", "--thickness", "0.1"]);
    assert_eq!(code, 0, "{err}");
    let r = read_json(&dir.path("r.json"));
    let a = &r["assessment"];
    for key in [
        "objective",
        "feasible",
        "thickness_min",
        "thickness_scale",
        "safety_factor",
        "thrust_horizontal",
        "load_factor",
        "bounds",
        "eps_inf",
        "horizontal_imbalance",
        "worst_bound",
        "termination",
        "iterations",
        "seconds",
    ] {
        assert!(a.get(key).is_some(), "the assessment lacks `{key}`");
    }
    assert_eq!(a["objective"], "fit");
    assert_eq!(a["termination"], "converged");
    assert_eq!(a["thickness_min"], 0.1);
    assert_eq!(a["worst_bound"]["vertex"], Value::Null);
    check_certificate(&dir.path("t.obj"), &r);

    // The library on the same mesh gives the same surface, bit for bit.
    let mesh = library_mesh(&dome());
    let envelope = Envelope::from_thickness(&mesh, &Thickness::Uniform(0.1)).unwrap();
    let settings = AssessSettings::default();
    let lib = assess(&Problem::new(mesh), &envelope, &settings, None).unwrap();
    let (pos, _) = read_obj(&dir.path("t.obj"));
    let z: Vec<f64> = pos.iter().map(|p| p[2]).collect();
    let lib_z: Vec<f64> = lib.positions.iter().map(|p| p[2]).collect();
    assert_eq!(bits(&z), bits(&lib_z));
    assert_eq!(
        bits(&numbers(&r["force_densities"])),
        bits(&lib.force_densities)
    );
    assert_eq!(bits(&numbers(&a["bounds"]["lower"])), bits(&lib.lower));
    assert_eq!(a["thrust_horizontal"].as_f64(), Some(lib.thrust_horizontal));
}

/// The report is the library's `AssessmentReport` of the same run (the one schema of both
/// command lines): every value equal but the wall time.
#[test]
fn the_report_is_the_librarys_assessment_report() {
    let dir = with_dome("assess-report");
    let (code, err) = run_dome(&dir, &["--assess", "min-thickness", "--thickness", "0.1"]);
    assert_eq!(code, 0, "{err}");
    let cli = read_json(&dir.path("r.json"));

    let model = read_model(&dir.path("dome.obj"), &ReadOptions::new(Supports::Boundary)).unwrap();
    let thickness = Thickness::Uniform(0.1);
    let envelope = Envelope::from_thickness(&model.problem.mesh, &thickness).unwrap();
    let settings = AssessSettings::default().with_objective(Objective::MinThickness);
    let r = assess(&model.problem, &envelope, &settings, None).unwrap();
    let report = AssessmentReport::new(&model, &envelope, &settings, &r, Some(0.1));
    let lib: Value = serde_json::from_str(&report.to_json()).unwrap();

    let comparable = |mut v: Value| {
        v["assessment"]["seconds"] = Value::Null;
        v["settings"]["mesh"] = Value::Null;
        v
    };
    assert_eq!(comparable(cli.clone()), comparable(lib));
    assert_eq!(cli["settings"]["mesh"], "dome.obj");
    assert_eq!(cli["settings"]["objective"], "min-thickness");
    assert_eq!(cli["settings"]["load_rule"], "barycentric");
    assert_eq!(cli["assessment"]["termination"], "converged");
}

#[test]
fn the_envelope_of_a_thickness_is_read_along_the_normals_and_loads_its_weight() {
    let dir = with_dome("assess-envelope");
    let args = [
        "--assess",
        "fit",
        "--thickness",
        "0.08",
        "--unit-weight",
        "2.5",
    ];
    let (code, err) = run_dome(&dir, &args);
    assert_eq!(code, 0, "{err}");
    let r = read_json(&dir.path("r.json"));
    let (pos, faces) = read_obj(&dir.path("dome.obj"));
    let env = &r["assessment"]["envelope"];
    let (lower, upper) = (numbers(&env["lower"]), numbers(&env["upper"]));
    // Area-weighted vertex normals: half the thickness each way, read vertically.
    let mut normal = vec![[0.0f64; 3]; pos.len()];
    let mut area = 0.0;
    for f in &faces {
        let [a, b, c] = f.map(|v| pos[v]);
        let (u, w) = (
            [0, 1, 2].map(|k| b[k] - a[k]),
            [0, 1, 2].map(|k| c[k] - a[k]),
        );
        let n = [
            u[1] * w[2] - u[2] * w[1],
            u[2] * w[0] - u[0] * w[2],
            u[0] * w[1] - u[1] * w[0],
        ];
        area += (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt() / 2.0;
        for &v in f {
            (0..3).for_each(|k| normal[v][k] += n[k]);
        }
    }
    for (v, n) in normal.iter().enumerate() {
        let nz = n[2] / (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        assert!(
            (upper[v] - lower[v] - 0.08 / nz).abs() < 1e-12,
            "vertex {v}"
        );
        assert!(
            (upper[v] + lower[v] - 2.0 * pos[v][2]).abs() < 1e-12,
            "vertex {v}"
        );
    }
    // Every face's weight (area x thickness x unit weight) reaches the vertices.
    let total: f64 = numbers(&r["loads"]).iter().sum();
    assert!((total - 2.5 * 0.08 * area).abs() < 1e-12 * total, "{total}");
}

/// `--assess min-thickness --thickness 0.1` on `dir`'s dome.obj: exit 0, the report with its
/// surface checked from the outputs.
fn least_thickness_report(dir: &Scratch) -> Value {
    let args = ["--assess", "min-thickness", "--thickness", "0.1"];
    let (code, err) = run_dome(dir, &args);
    assert_eq!(code, 0, "{err}");
    let r = read_json(&dir.path("r.json"));
    check_certificate(&dir.path("t.obj"), &r);
    r
}

/// The dome is self-supporting as it stands (its stress alone balances it), so its least
/// thickness is 0: no safety factor, a null in the report.
#[test]
fn a_self_supporting_middle_surface_needs_no_thickness() {
    let r = least_thickness_report(&with_dome("assess-min-thickness-zero"));
    let a = &r["assessment"];
    assert_eq!(a["thickness_scale"].as_f64(), Some(0.0));
    assert_eq!(a["thickness_min"].as_f64(), Some(0.0));
    assert!(a["safety_factor"].is_null(), "{}", a["safety_factor"]);
}

/// The dome with its crown lowered by 0.03: no longer balanced as it stands, so it needs
/// some of its thickness.
#[test]
fn min_thickness_scales_the_bounds_and_reports_the_safety_factor() {
    let mut d = dome();
    d.positions[2] -= 0.03;
    let r = least_thickness_report(&with_mesh("assess-min-thickness", &d));
    let a = &r["assessment"];
    let s = a["thickness_scale"].as_f64().unwrap();
    assert!(s > 0.0 && s < 1.0, "scale {s}");
    assert_eq!(a["thickness_min"].as_f64(), Some(s * 0.1));
    assert_eq!(a["safety_factor"].as_f64(), Some(1.0 / s));
    let env = &a["envelope"];
    let (lo, hi) = (
        numbers(&a["bounds"]["lower"]),
        numbers(&a["bounds"]["upper"]),
    );
    let (elo, ehi) = (numbers(&env["lower"]), numbers(&env["upper"]));
    for v in 0..lo.len() {
        let span = s * (ehi[v] - elo[v]);
        assert!((hi[v] - lo[v] - span).abs() < 1e-12, "vertex {v}");
    }
}

/// A vault thinner than its least thickness: the least-thickness search scales the envelope
/// up and certifies a surface there, but the vault as given is not shown safe, so the CLI
/// exits 3 and says how much thicker it must be. The least thickness does not depend on the
/// given one (the loads scale with it, which scales the stress, not the surface).
#[test]
fn a_least_thickness_above_the_given_one_exits_3() {
    let mut d = dome();
    d.positions[2] -= 0.03;
    let dir = with_mesh("assess-min-thickness-thin", &d);
    let t_min = least_thickness_report(&dir)["assessment"]["thickness_min"]
        .as_f64()
        .unwrap();
    let thin = format!("{}", t_min / 3.0);
    let (code, err) = run_dome(&dir, &["--assess", "min-thickness", "--thickness", &thin]);
    assert_eq!(code, 3, "{err}");
    assert!(
        err.contains("safety factor") && err.contains("< 1"),
        "{err}"
    );
    let r = read_json(&dir.path("r.json"));
    check_certificate(&dir.path("t.obj"), &r);
    let a = &r["assessment"];
    assert_eq!(a["feasible"], true);
    let s = a["thickness_scale"].as_f64().unwrap();
    assert!((s - 3.0).abs() < 0.03, "scale {s}");
    assert!(a["safety_factor"].as_f64().unwrap() < 1.0, "{a}");
}

/// Free supports from a thickness stand on or above their springing plane, the middle
/// surface's height (docs/method.md §16.1): the greatest thrust raises them, as far as the
/// joint lets the thrust reach the plane.
#[test]
fn fixed_supports_keep_the_mesh_heights_and_free_ones_may_move() {
    let input = obj_text(&dome().positions, &dome().triangles);
    let anchored = dome().anchored;
    let mut moved = Vec::new();
    for fixed in [true, false] {
        let dir = with_dome("assess-fixed");
        let mut args = vec!["--assess", "max-thrust", "--thickness", "0.1"];
        if fixed {
            args.push("--fixed-supports");
        }
        let (code, err) = run_dome(&dir, &args);
        assert_eq!(code, 0, "{err}");
        let r = read_json(&dir.path("r.json"));
        check_certificate(&dir.path("t.obj"), &r);
        fs::write(dir.path("in.obj"), &input).unwrap();
        let (before, _) = read_obj(&dir.path("in.obj"));
        let (after, _) = read_obj(&dir.path("t.obj"));
        let change = anchored
            .iter()
            .map(|&v| (after[v as usize][2] - before[v as usize][2]).abs())
            .fold(0.0, f64::max);
        moved.push(change);
    }
    assert_eq!(moved[0], 0.0, "fixed supports moved");
    assert!(
        moved[1] > 1e-3,
        "free supports stayed at the mesh heights: {moved:?}"
    );
}

#[test]
fn max_load_multiplies_the_pattern_of_the_files_own_vertices() {
    let dir = Scratch::new("assess-max-load");
    // The dome with vertex 5 written twice: the second copy (id 37 of the file) is welded
    // into vertex 5, so its load joins vertex 5's.
    let d = dome();
    let mut positions = d.positions.clone();
    positions.extend_from_slice(&d.positions[15..18]);
    let mut triangles = d.triangles.clone();
    let first = triangles.iter().position(|&v| v == 5).unwrap();
    triangles[first] = 37;
    fs::write(dir.path("dome.obj"), obj_text(&positions, &triangles)).unwrap();
    let mut pattern = vec![0.0; 38];
    pattern[0] = 1.0;
    pattern[5] = 0.25;
    pattern[37] = 0.5;
    let json = serde_json::json!({ "loads": pattern }).to_string();
    fs::write(dir.path("l.json"), json).unwrap();
    let args = [
        "--assess",
        "max-load",
        "--thickness",
        "0.1",
        "--load-pattern",
        "l.json",
    ];
    // Exit 0, or 3 when λ is certified but its optimality not proven.
    let (code, err) = run_dome(&dir, &args);
    assert!(code == 0 || code == 3, "{err}");
    let r = read_json(&dir.path("r.json"));
    check_certificate(&dir.path("t.obj"), &r);
    let a = &r["assessment"];
    let lambda = a["load_factor"].as_f64().unwrap();
    assert!(lambda > 0.0);
    let welded = numbers(&a["load_pattern"]);
    assert_eq!(welded.len(), 37);
    assert_eq!((welded[0], welded[5]), (1.0, 0.75));
    assert!(welded
        .iter()
        .enumerate()
        .all(|(v, &x)| x == 0.0 || v == 0 || v == 5));

    // The same loads but for λ × pattern: those of a fit on the same envelope.
    let fit_dir = with_dome("assess-max-load-fit");
    let (fit_code, err) = run_dome(&fit_dir, &["--assess", "fit", "--thickness", "0.1"]);
    assert_eq!(fit_code, 0, "{err}");
    let dead = numbers(&read_json(&fit_dir.path("r.json"))["loads"]);
    for (v, (&p, &d)) in numbers(&r["loads"]).iter().zip(&dead).enumerate() {
        assert!((p - d - lambda * welded[v]).abs() < 1e-12, "vertex {v}");
    }

    // A sparse pattern of the same loads gives the same answer.
    let sparse = serde_json::json!({ "loads": { "0": 1.0, "5": 0.25, "37": 0.5 } });
    fs::write(dir.path("l.json"), sparse.to_string()).unwrap();
    let (code_again, err) = run_dome(&dir, &args);
    assert_eq!(code_again, code, "{err}");
    let again = read_json(&dir.path("r.json"));
    assert_eq!(again["assessment"]["load_factor"].as_f64(), Some(lambda));
}

/// The dome's heights shifted by `dz`, as an OBJ with a finer ring triangulation of its own.
fn shifted_dome(dz: f64) -> String {
    let d = Dome::new(6, 24);
    let positions: Vec<f64> = (d.positions.chunks_exact(3))
        .flat_map(|p| [p[0] * 1.05, p[1] * 1.05, p[2] + dz])
        .collect();
    obj_text(&positions, &d.triangles)
}

#[test]
fn intrados_and_extrados_files_bound_the_thrust_surface() {
    let dir = with_dome("assess-surfaces");
    fs::write(dir.path("in.obj"), shifted_dome(-0.05)).unwrap();
    fs::write(dir.path("ex.obj"), shifted_dome(0.05)).unwrap();
    let args = [
        "--assess",
        "fit",
        "--intrados",
        "in.obj",
        "--extrados",
        "ex.obj",
    ];
    let (code, err) = run_dome(&dir, &args);
    assert_eq!(code, 0, "{err}");
    let r = read_json(&dir.path("r.json"));
    check_certificate(&dir.path("t.obj"), &r);
    let a = &r["assessment"];
    assert_eq!(a["thickness_min"], Value::Null);
    let (lo, hi) = (
        numbers(&a["bounds"]["lower"]),
        numbers(&a["bounds"]["upper"]),
    );
    // Sampled on the other triangulation: 0.1 apart everywhere.
    assert!(lo.iter().zip(&hi).all(|(l, h)| (h - l - 0.1).abs() < 1e-12));
}

#[test]
fn bad_assessment_input_exits_2_names_the_option_and_writes_nothing() {
    let dir = with_dome("assess-bad");
    fs::write(dir.path("in.obj"), shifted_dome(-0.05)).unwrap();
    fs::write(dir.path("ex.obj"), shifted_dome(0.05)).unwrap();
    let d = Dome::new(6, 24);
    let small: Vec<f64> = (d.positions.chunks_exact(3))
        .flat_map(|p| [p[0] * 0.5, p[1] * 0.5, p[2] + 0.05])
        .collect();
    fs::write(dir.path("small.obj"), obj_text(&small, &d.triangles)).unwrap();
    fs::write(dir.path("short.json"), "{\"loads\": [1, 2, 3]}").unwrap();
    fs::write(dir.path("far.json"), "{\"loads\": {\"99\": 1}}").unwrap();
    assert_eq!(
        dome().anchored[0],
        25,
        "the messages name the first support"
    );
    let cases: [(&[&str], &str); 21] = [
        (
            &["--thickness", "0"],
            "--thickness: expected a thickness > 0",
        ),
        (
            &["--thickness", "-0.1"],
            "--thickness: expected a thickness > 0",
        ),
        (
            &["--thickness", "nan"],
            "--thickness: expected a thickness > 0",
        ),
        (
            &["--thickness", "inf"],
            "--thickness: expected a thickness > 0",
        ),
        (
            &["--intrados", "ex.obj", "--extrados", "in.obj"],
            "--intrados: at vertex 0 the intrados",
        ),
        (
            &["--intrados", "in.obj", "--extrados", "small.obj"],
            "--extrados: does not cover vertex",
        ),
        (&["--intrados", "in.obj"], "--intrados needs --extrados"),
        (
            &[
                "--thickness",
                "0.1",
                "--intrados",
                "in.obj",
                "--extrados",
                "ex.obj",
            ],
            "not both",
        ),
        (&[], "--assess needs the masonry's envelope"),
        (
            &["--thickness", "0.1", "--unit-weight", "-1"],
            "--unit-weight: -1 must be >= 0",
        ),
        (
            &["--thickness", "0.1", "--unit-weight", "0"],
            "--unit-weight: is 0, so the masonry weighs nothing",
        ),
        (
            &["--intrados", "in.obj", "--extrados", "in.obj"],
            "--intrados, --extrados: has no thickness at any face",
        ),
        (
            &["--thickness", "density", "--unit-weight", "0"],
            "--unit-weight: 0 must be > 0 with --thickness density",
        ),
        (
            &["--thickness", "0.1", "--method", "paper"],
            "--method is an option of form",
        ),
        (
            &["--thickness", "0.1", "--section", "x=7"],
            "--section: the plane x = 7",
        ),
        (
            &["--thickness", "0.1", "--load-pattern", "short.json"],
            "goes with --assess max-load",
        ),
        (
            &["--thickness", "density"],
            "--thickness density needs --unit-weight",
        ),
        (
            &["--thickness", "0.1", "--reach", "-1"],
            "--reach: vertex 25 has -1, not a number >= 0",
        ),
        (
            &["--thickness", "0.1", "--reach", "nan"],
            "--reach: expected a length or `inf`",
        ),
        (
            &["--thickness", "0.1", "--springing", "5"],
            "--springing: vertex 25 has 5: it must be finite and at most the upper bound",
        ),
        (
            &["--thickness", "0.1", "--reach", "inf", "--fixed-supports"],
            "--reach sets the joint of free supports: it does not go with --fixed-supports",
        ),
    ];
    let before = dir.snapshot();
    for (extra, message) in cases {
        let mut args = vec!["--assess", "fit"];
        args.extend_from_slice(extra);
        let (code, err) = run_dome(&dir, &args);
        assert_eq!(code, 2, "{extra:?}: {err}");
        assert!(
            err.contains(message),
            "{extra:?}: `{err}` lacks `{message}`"
        );
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(dir.snapshot() == before, "{extra:?} wrote something");
    }
    let max_load: [(&[&str], &str); 3] = [
        (
            &["--load-pattern", "short.json"],
            "has 3 loads, expected one per vertex of MESH (37",
        ),
        (
            &["--load-pattern", "far.json"],
            "`99` is not a vertex id of MESH (0 to 36",
        ),
        (&[], "--assess max-load needs --load-pattern"),
    ];
    for (extra, message) in max_load {
        let mut args = vec!["--assess", "max-load", "--thickness", "0.1"];
        args.extend_from_slice(extra);
        let (code, err) = run_dome(&dir, &args);
        assert_eq!(code, 2, "{extra:?}: {err}");
        assert!(
            err.contains(message),
            "{extra:?}: `{err}` lacks `{message}`"
        );
        assert!(dir.snapshot() == before, "{extra:?} wrote something");
    }
    // Assessment options without --assess.
    let (code, err) = run_dome(&dir, &["--thickness", "0.1"]);
    assert_eq!(code, 2);
    assert!(err.contains("--thickness needs --assess"), "{err}");
}

/// `--springing` and `--reach` set the joint of every free support: the report's joints
/// carry them, and `--reach inf` drops the joints (the supports read vertically).
#[test]
fn springing_and_reach_set_the_joint_of_every_free_support() {
    let supports = dome().anchored.len();
    let joints = |extra: &[&str]| -> Vec<Value> {
        let dir = with_dome("assess-joint");
        let mut args = vec!["--assess", "min-thrust", "--thickness", "0.1"];
        args.extend_from_slice(extra);
        let (code, err) = run_dome(&dir, &args);
        assert_eq!(code, 0, "{extra:?}: {err}");
        let r = read_json(&dir.path("r.json"));
        check_certificate(&dir.path("t.obj"), &r);
        r["assessment"]["joints"]
            .as_array()
            .expect("joints")
            .clone()
    };
    let default = joints(&[]);
    assert_eq!(default.len(), supports);
    let set = joints(&["--springing", "-0.02", "--reach", "0.03"]);
    assert_eq!(set.len(), supports);
    for j in set.iter().chain(&default) {
        assert!(j["offset"].as_f64().expect("offset") <= j["reach"].as_f64().unwrap() + 1e-9);
    }
    for j in &set {
        let (springing, reach) = (j["springing"].as_f64(), j["reach"].as_f64());
        assert!((springing.unwrap() + 0.02).abs() < 1e-12, "{j}");
        assert!((reach.unwrap() - 0.03).abs() < 1e-12, "{j}");
    }
    assert_ne!(default[0]["reach"], set[0]["reach"]);
    assert!(joints(&["--reach", "inf"]).is_empty());
}

/// The dome with its crown vertex pushed below its neighbours: under a downward load no
/// compression-only surface has an inner lowest point, so none fits a thin envelope.
fn dented_dome(dir: &Scratch) {
    let d = dome();
    let mut positions = d.positions.clone();
    positions[2] = 0.2;
    fs::write(dir.path("dome.obj"), obj_text(&positions, &d.triangles)).unwrap();
}

#[test]
fn no_thrust_surface_in_a_dented_dome_exits_3_with_the_outputs() {
    let dir = Scratch::new("assess-dent");
    dented_dome(&dir);
    let (code, err) = run_dome(&dir, &["--assess", "fit", "--thickness", "0.02"]);
    assert_eq!(code, 3, "{err}");
    assert!(
        err.contains("no thrust surface found inside the envelope"),
        "{err}"
    );
    let r = read_json(&dir.path("r.json"));
    let a = &r["assessment"];
    assert_eq!(a["feasible"], false);
    assert!(a["eps_inf"].as_f64().unwrap() > 1e-3, "{a}");
    // No thickness is proven by a surface that is not certified.
    assert_eq!(a["thickness_min"], Value::Null);
    for name in ["plan_forces.svg", "section.svg", "shape_3d.svg"] {
        assert!(dir.path("pics").join(name).is_file(), "{name}");
    }
}

// The section picture.

/// The segments of the path `id` of a picture: (x0, y0, x1, y1) per `M x,y L x,y`.
fn path_segments(elements: &[Element], id: &str) -> Vec<[f64; 4]> {
    let path = (elements.iter())
        .find(|e| e.name == "path" && e.attributes.get("id").map(String::as_str) == Some(id))
        .unwrap_or_else(|| panic!("no path `{id}`"));
    let numbers: Vec<f64> = path.attributes["d"]
        .split(|c: char| c == 'M' || c == 'L' || c == ',' || c.is_whitespace())
        .filter(|t| !t.is_empty())
        .map(|t| t.parse().unwrap())
        .collect();
    assert_eq!(numbers.len() % 4, 0, "{id}: M x,y L x,y pairs");
    numbers
        .chunks_exact(4)
        .map(|c| [c[0], c[1], c[2], c[3]])
        .collect()
}

/// The cut of the surface `pos` by the vertical plane `pos[axis] = at`: per face it crosses,
/// the segment's two points as (coordinate along the plane, height), sorted along it.
/// Crossings closer than 1e-9 of the plan's extent are one.
fn cut(pos: &[[f64; 3]], faces: &[[usize; 3]], axis: usize, at: f64) -> Vec<[[f64; 2]; 2]> {
    let along = 1 - axis;
    let (lo, hi) = plan_box(pos, faces);
    let tolerance = 1e-9 * (hi[0] - lo[0]).max(hi[1] - lo[1]);
    let mut out = Vec::new();
    for f in faces {
        let mut points: Vec<[f64; 2]> = Vec::new();
        for k in 0..3 {
            let (a, b) = (pos[f[k]], pos[f[(k + 1) % 3]]);
            let (da, db) = (a[axis] - at, b[axis] - at);
            let t = if da == 0.0 {
                0.0
            } else if da * db < 0.0 {
                da / (da - db)
            } else {
                continue;
            };
            let point = [0, 1].map(|c| {
                let c = if c == 0 { along } else { 2 };
                (1.0 - t) * a[c] + t * b[c]
            });
            if points.iter().all(|p| (p[0] - point[0]).abs() > tolerance) {
                points.push(point);
            }
        }
        if let [p, q] = points[..] {
            out.push(if p[0] <= q[0] { [p, q] } else { [q, p] });
        }
    }
    out
}

/// Fits the picture's uniform scale and offsets from the extremes of the drawn segments and
/// of `cut`, then finds for every drawn segment its own cut segment (to 0.05 px: the points
/// are rounded to 0.01 px).
fn assert_drawn(drawn: &[[f64; 4]], cut: &[[[f64; 2]; 2]], what: &str) {
    assert_eq!(drawn.len(), cut.len(), "{what}: one segment per face cut");
    let fold = |v: &mut dyn Iterator<Item = f64>| {
        v.fold((f64::MAX, f64::MIN), |(lo, hi), x| (lo.min(x), hi.max(x)))
    };
    let (s_lo, s_hi) = fold(&mut cut.iter().flatten().map(|p| p[0]));
    let (_, z_hi) = fold(&mut cut.iter().flatten().map(|p| p[1]));
    let (x_lo, x_hi) = fold(&mut drawn.iter().flat_map(|d| [d[0], d[2]]));
    let (y_lo, _) = fold(&mut drawn.iter().flat_map(|d| [d[1], d[3]]));
    let scale = (x_hi - x_lo) / (s_hi - s_lo);
    let page = |p: [f64; 2]| [x_lo + scale * (p[0] - s_lo), y_lo + scale * (z_hi - p[1])];
    let mut used = vec![false; cut.len()];
    for d in drawn {
        let close = |c: &[[f64; 2]; 2]| {
            let (a, b) = (page(c[0]), page(c[1]));
            [a[0], a[1], b[0], b[1]]
                .iter()
                .zip(d)
                .all(|(w, g)| (w - g).abs() < 0.05)
        };
        let k = (0..cut.len())
            .find(|&k| !used[k] && close(&cut[k]))
            .unwrap_or_else(|| panic!("{what}: drawn segment {d:?} is no face's cut"));
        used[k] = true;
    }
}

fn section_elements(dir: &Scratch) -> Vec<Element> {
    parse_xml(&fs::read_to_string(dir.path("pics/section.svg")).unwrap())
}

#[test]
fn the_section_draws_each_surface_cut_through_its_triangles() {
    for (section, axis) in [(None, 1), (Some("x=0.3"), 0), (Some("y=-0.45"), 1)] {
        let dir = with_dome("assess-section");
        let mut args = vec!["--assess", "min-thickness", "--thickness", "0.1"];
        if let Some(s) = section {
            args.extend(["--section", s]);
        }
        let (code, err) = run_dome(&dir, &args);
        assert_eq!(code, 0, "{err}");
        let (thrust, faces) = read_obj(&dir.path("t.obj"));
        let at = match section {
            Some(s) => s[2..].parse().unwrap(),
            None => {
                let (lo, hi) = plan_box(&thrust, &faces);
                0.5 * (lo[1] + hi[1])
            }
        };
        let elements = section_elements(&dir);
        let expected = cut(&thrust, &faces, axis, at);
        assert!(
            expected.len() >= 6,
            "{section:?}: the plane cuts {}",
            expected.len()
        );
        assert_drawn(&path_segments(&elements, "thrust"), &expected, "thrust");
        // The bounds at the least thickness hold the thrust surface, touching it (hinges).
        let r = read_json(&dir.path("r.json"));
        let a = &r["assessment"];
        let with = |h: Vec<f64>| -> Vec<[f64; 3]> {
            (thrust.iter().zip(h))
                .map(|(p, z)| [p[0], p[1], z])
                .collect()
        };
        let lower = cut(&with(numbers(&a["bounds"]["lower"])), &faces, axis, at);
        let upper = cut(&with(numbers(&a["bounds"]["upper"])), &faces, axis, at);
        let slack = 1e-6 * 2.0f64.hypot(2.0);
        let mut touching: Vec<f64> = Vec::new();
        for ((t, l), u) in expected.iter().zip(&lower).zip(&upper) {
            for k in 0..2 {
                assert!(l[k][1] - 1e-9 <= t[k][1] && t[k][1] <= u[k][1] + 1e-9);
                let touches =
                    (t[k][1] - l[k][1]).abs() <= slack || (u[k][1] - t[k][1]).abs() <= slack;
                if touches && !touching.contains(&t[k][0]) {
                    touching.push(t[k][0]);
                }
            }
        }
        let envelope = &a["envelope"];
        let intrados = cut(&with(numbers(&envelope["lower"])), &faces, axis, at);
        assert_drawn(&path_segments(&elements, "intrados"), &intrados, "intrados");
        let extrados = cut(&with(numbers(&envelope["upper"])), &faces, axis, at);
        assert_drawn(&path_segments(&elements, "extrados"), &extrados, "extrados");
        let in_group = |id: &str, name: &str| {
            (elements.iter())
                .filter(|e| e.name == name && e.parent_id.as_deref() == Some(id))
                .count()
        };
        // The plane meets the rim (anchored) twice.
        assert_eq!(in_group("supports", "polygon"), 2, "{section:?}");
        assert_eq!(
            in_group("contacts", "circle"),
            touching.len(),
            "{section:?}: hinges"
        );
    }
}

#[test]
fn the_section_of_a_dented_dome_shows_the_dent_and_says_nothing_fits() {
    let dir = Scratch::new("assess-section-dent");
    dented_dome(&dir);
    let (code, err) = run_dome(&dir, &["--assess", "fit", "--thickness", "0.02"]);
    assert_eq!(code, 3, "{err}");
    let text = fs::read_to_string(dir.path("pics/section.svg")).unwrap();
    assert!(text.contains("no thrust surface found inside the envelope"));
    // The thrust drawn dips at the crown: a lowest point between higher ones (page y grows
    // downwards).
    let mut points: Vec<[f64; 2]> = path_segments(&parse_xml(&text), "thrust")
        .iter()
        .flat_map(|s| [[s[0], s[1]], [s[2], s[3]]])
        .collect();
    points.sort_by(|a, b| a[0].total_cmp(&b[0]));
    let middle = (points.len() / 3)..(2 * points.len() / 3);
    let crown = points[middle].iter().map(|p| p[1]).fold(f64::MIN, f64::max);
    let highest = points.iter().map(|p| p[1]).fold(f64::MAX, f64::min);
    assert!(
        crown > highest + 20.0,
        "no dent drawn: {crown} vs {highest}"
    );

    // The sound dome's section has no dip: its thrust rises to the crown.
    let sound = with_dome("assess-section-sound");
    let (code, err) = run_dome(&sound, &["--assess", "fit", "--thickness", "0.02"]);
    assert_eq!(code, 0, "{err}");
    let text = fs::read_to_string(sound.path("pics/section.svg")).unwrap();
    assert!(text.contains("a thrust surface fits"));
    let segments = path_segments(&parse_xml(&text), "thrust");
    let centre = segments
        .iter()
        .flat_map(|s| [[s[0], s[1]], [s[2], s[3]]])
        .min_by(|a, b| a[1].total_cmp(&b[1]))
        .unwrap();
    let (x_lo, x_hi) = segments
        .iter()
        .fold((f64::MAX, f64::MIN), |(l, h), s| (l.min(s[0]), h.max(s[2])));
    let mid = 0.5 * (x_lo + x_hi);
    assert!(
        (centre[0] - mid).abs() < 0.1 * (x_hi - x_lo),
        "the top is off centre"
    );
}

/// The red and blue faces of the thrust surface in the 3-D view of a run with `objective`,
/// after checking that each view draws every face once and that the extrados is translucent.
fn thrust_colours(objective: &str) -> (usize, usize) {
    let dir = with_dome("assess-3d");
    let args = ["--assess", objective, "--thickness", "0.1"];
    let (code, err) = run_dome(&dir, &args);
    assert_eq!(code, 0, "{err}");
    let elements = parse_xml(&fs::read_to_string(dir.path("pics/shape_3d.svg")).unwrap());
    let (thrust, faces) = read_obj(&dir.path("t.obj"));
    let (middle, _) = read_obj(&dir.path("dome.obj"));
    let r = read_json(&dir.path("r.json"));
    let a = &r["assessment"];
    let upper = numbers(&a["envelope"]["upper"]);
    let extrados: Vec<[f64; 3]> = (middle.iter().zip(&upper))
        .map(|(p, &z)| [p[0], p[1], z])
        .collect();
    for (id, pos) in [
        ("middle-faces", &middle),
        ("thrust-faces", &thrust),
        ("extrados-faces", &extrados),
    ] {
        let drawn = view_polygons(&elements, id);
        assert_eq!(drawn.len(), faces.len(), "{id}: one polygon per face");
        match_faces(&drawn, pos, &faces);
    }
    let veil = (elements.iter())
        .find(|e| e.attributes.get("id").map(String::as_str) == Some("extrados-faces"))
        .unwrap();
    let opacity: f64 = veil.attributes["opacity"].parse().unwrap();
    assert!(opacity > 0.0 && opacity < 1.0, "{opacity}");

    // Faces near the extrados are red, near the intrados blue.
    let (lo, hi) = (
        numbers(&a["bounds"]["lower"]),
        numbers(&a["bounds"]["upper"]),
    );
    let depth: Vec<f64> = (faces.iter())
        .map(|f| {
            f.iter()
                .map(|&v| (thrust[v][2] - lo[v]) / (hi[v] - lo[v]))
                .sum::<f64>()
                / 3.0
        })
        .collect();
    let drawn = view_polygons(&elements, "thrust-faces");
    let (order, _, _) = match_faces(&drawn, &thrust, &faces);
    let (mut red, mut blue) = (0, 0);
    for (d, &t) in drawn.iter().zip(&order) {
        let [r, _, b] = d.rgb;
        if depth[t] > 0.75 {
            assert!(
                r > b,
                "face {t} at depth {} is not red: {:?}",
                depth[t],
                d.rgb
            );
            red += 1;
        } else if depth[t] < 0.25 {
            assert!(
                b > r,
                "face {t} at depth {} is not blue: {:?}",
                depth[t],
                d.rgb
            );
            blue += 1;
        }
    }
    (red, blue)
}

#[test]
fn the_3d_view_colours_the_thrust_surface_by_its_depth_under_a_translucent_extrados() {
    // The least thrust rises to the extrados at the crown, the greatest sinks to the intrados.
    let (red, _) = thrust_colours("min-thrust");
    assert!(red > 0, "min-thrust: no face near the extrados");
    let (_, blue) = thrust_colours("max-thrust");
    assert!(blue > 0, "max-thrust: no face near the intrados");
}

#[test]
fn help_lists_the_assessment_options_and_pictures() {
    let dir = Scratch::new("assess-help");
    let out = run(&dir.0, &["--help"]);
    let help = String::from_utf8_lossy(&out.stdout);
    for phrase in [
        "--assess A",
        "min-thickness",
        "--thickness T",
        "--intrados A",
        "--unit-weight W",
        "--fixed-supports",
        "--load-pattern",
        "--section S",
        "section.svg",
    ] {
        assert!(help.contains(phrase), "--help lacks `{phrase}`");
    }
}

//! The `formfind` example end to end: runs the built program, reads its OBJ and JSON outputs
//! with small parsers of its own (not through the library) and recomputes the equilibrium of
//! the result independently; checks that bad input gets one line, exit status 2 and no files.

mod formfind_support;

use std::fs;
use std::sync::atomic::{AtomicUsize, Ordering};

use formfind_support::*;

#[test]
fn embedded_default_converges_and_balances() {
    let dir = Scratch::new("default");
    let out = run(&dir.0, &[]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "status {:?}\n{stdout}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("formfind-out/report.json"), "{stdout}");
    let od = dir.path("formfind-out");
    let eps = check_equilibrium(&od.join("vault-formfound.obj"), &od.join("report.json"));
    check_same_plan(&od.join("vault-input.obj"), &od.join("vault-formfound.obj"));
    check_pictures(&od.join("pictures"));
    // The default is a vault with openings and free edges.
    let r = read_json(&od.join("report.json"));
    assert_eq!(r["mesh"]["holes"], 2);
    assert!(!r["external_horizontal"].as_array().unwrap().is_empty());
    let supports = read_json(&od.join("vault-supports.json"));
    assert_eq!(supports["anchored"], r["anchored"]);
    println!("embedded default: ε∞ = {eps:e}");
}

fn shared_model(name: &str) {
    let Some(models) = models_dir() else { return };
    let dir = Scratch::new(name);
    let (obj, json) = (
        models.join(format!("{name}.obj")),
        models.join(format!("{name}.json")),
    );
    let (out_obj, report, pictures) = (dir.path("out.obj"), dir.path("r.json"), dir.path("pics"));
    let args = [
        obj.to_str().unwrap(),
        "--supports",
        json.to_str().unwrap(),
        "--out",
        out_obj.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
        "--pictures",
        pictures.to_str().unwrap(),
    ];
    let out = run(&dir.0, &args);
    assert!(
        out.status.success(),
        "{name}: status {:?}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    let eps = check_equilibrium(&out_obj, &report);
    check_same_plan(&obj, &out_obj);
    check_pictures(&pictures);
    println!("{name}: ε∞ = {eps:e}");
}

#[test]
fn dome_with_doors_converges_and_balances() {
    shared_model("dome_with_doors");
}

#[test]
fn neumunster_converges_and_balances() {
    shared_model("neumunster");
}

#[test]
fn stress_only_analyses_without_moving() {
    let dir = Scratch::new("stress-only");
    let out = run(
        &dir.0,
        &["--stress-only", "--report", "r.json", "--out", "o.obj"],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let r = read_json(&dir.path("r.json"));
    assert_eq!(r["termination"], "stress_only");
    assert_eq!(r["iterations"], 1);
    assert!(
        r["eps_inf"].as_f64().unwrap() > 1e-3,
        "the input is not self-supporting"
    );
    check_same_plan(&dir.path("vault-input.obj"), &dir.path("o.obj"));
    let (a, _) = read_obj(&dir.path("vault-input.obj"));
    let (b, _) = read_obj(&dir.path("o.obj"));
    assert_eq!(a, b, "--stress-only must not move vertices");
    assert!(!dir.path("formfind-out/pictures/height_change.svg").exists());
}

/// A valid 5-vertex square with its centre: four triangles.
const SQUARE: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 0.3\n\
                      f 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\n";

/// Runs formfind with `args` in a scratch folder holding `files`; asserts exit status 2, a
/// single stderr line containing `message`, and that no file was added.
fn rejects(files: &[(&str, &str)], args: &[&str], message: &str) {
    static CASE: AtomicUsize = AtomicUsize::new(0);
    let dir = Scratch::new(&format!("bad-{}", CASE.fetch_add(1, Ordering::Relaxed)));
    for (name, content) in files {
        fs::write(dir.path(name), content).unwrap();
    }
    let before = dir.listing();
    let mut all = vec!["--report", "outs/r.json", "--pictures", "outs/pics"];
    all.extend(args);
    let out = run(&dir.0, &all);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
    assert_eq!(
        stderr.lines().count(),
        1,
        "{args:?}: not one line: {stderr}"
    );
    assert!(
        stderr.contains(message),
        "{args:?}: `{stderr}` lacks `{message}`"
    );
    assert_eq!(dir.listing(), before, "{args:?}: output was written");
}

#[test]
fn bad_input_gets_one_line_and_no_output() {
    let sq = [
        ("sq.obj", SQUARE),
        ("s.json", "{\"anchored\": [0, 1, 2, 3]}"),
    ];
    rejects(&sq, &["missing.obj", "--supports", "s.json"], "missing.obj");
    rejects(&sq, &["sq.obj", "--supports", "nope.json"], "nope.json");
    rejects(
        &[("bad.obj", "v 0 0\nf 1 2 3\n"), ("s.json", "[0]")],
        &["bad.obj", "--supports", "s.json"],
        "bad.obj:1: vertex has 2 coordinates",
    );
    rejects(
        &[
            ("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n"),
            ("s.json", "[0]"),
        ],
        &["bad.obj", "--supports", "s.json"],
        "face refers to vertex 7",
    );
    rejects(
        &[("sq.obj", SQUARE), ("s.json", "{\"anchored\": [0, 99]}")],
        &["sq.obj", "--supports", "s.json"],
        "--supports s.json: anchored vertex 99: out of range (MESH's vertex ids are 0 to 4",
    );
    rejects(
        &[("sq.obj", SQUARE), ("s.json", "[3, 1, 3]")],
        &["sq.obj", "--supports", "s.json"],
        "--supports s.json: anchored vertex 3: listed twice",
    );
    rejects(
        &[("sq.obj", SQUARE), ("s.json", "{\"anchored\": [0, -1]}")],
        &["sq.obj", "--supports", "s.json"],
        "s.json:1:",
    );
    rejects(&sq, &["sq.obj"], "needs --supports");
    rejects(
        &sq,
        &["sq.obj", "--supports", "s.json", "--anchor-boundary"],
        "not several",
    );
    rejects(
        &sq,
        &["sq.obj", "--supports", "s.json", "--tol", "-1"],
        "--tol: -1 must be > 0",
    );
    rejects(
        &sq,
        &["sq.obj", "--supports", "s.json", "--tol", "x"],
        "--tol: expected a number",
    );
    rejects(
        &sq,
        &["sq.obj", "--supports", "s.json", "--max-iter", "0"],
        "--max-iter",
    );
    rejects(
        &sq,
        &["sq.obj", "--supports", "s.json", "--solver", "fast"],
        "'fast' is not one of 'reduced', 'edge_based'",
    );
    rejects(
        &sq,
        &["sq.obj", "--supports", "s.json", "--qp", "fast"],
        "'native', 'clarabel'",
    );
    rejects(
        &sq,
        &["sq.obj", "--supports", "s.json", "--qmin", "-0.1"],
        "--qmin",
    );
    rejects(
        &sq,
        &["sq.obj", "--supports", "s.json", "--qmin", "big"],
        "--qmin",
    );
    rejects(
        &sq,
        &["sq.obj", "--supports", "s.json", "--qmax", "0"],
        "--qmax",
    );
    rejects(
        &sq,
        &["sq.obj", "--supports", "s.json", "--tau", "maybe"],
        "'optimized', 'zero'",
    );
    rejects(
        &sq,
        &["sq.obj", "--supports", "s.json", "--holes", "linear"],
        "'affine', 'constant'",
    );
    rejects(
        &sq,
        &["sq.obj", "--supports", "s.json", "--load", "x"],
        "barycentric",
    );
    rejects(
        &sq,
        &["sq.obj", "--supports", "s.json", "--density", "0"],
        "--density",
    );
    rejects(
        &sq,
        &["sq.obj", "--supports", "s.json", "--frobnicate"],
        "unknown option",
    );
    rejects(
        &sq,
        &["sq.obj", "--supports", "s.json", "--odt", "five"],
        "expected an integer",
    );
    rejects(
        &sq,
        &["sq.obj", "other.obj", "--supports", "s.json"],
        "only one mesh",
    );
    rejects(&sq, &["--supports", "s.json"], "need a MESH");
    rejects(&sq, &["sq.obj", "--supports", "s.json", "--out"], "--out");
    // A misspelt face line would otherwise drop a face unseen.
    rejects(
        &[
            ("bad.obj", format!("{SQUARE}F 1 2 3\n").as_str()),
            ("s.json", "[0, 1, 2, 3]"),
        ],
        &["bad.obj", "--supports", "s.json"],
        "bad.obj:10: unknown statement `F`",
    );
    // Two squares stacked in plan.
    let stacked = format!(
        "{SQUARE}v 0.5 0.5 1\nv 1.5 0.5 1\nv 1.5 1.5 1\nv 0.5 1.5 1\nv 1 1 1.3\n\
         f 6 7 10\nf 7 8 10\nf 8 9 10\nf 9 6 10\n"
    );
    rejects(
        &[
            ("st.obj", &stacked[..]),
            ("s.json", "[0, 1, 2, 3, 5, 6, 7, 8]"),
        ],
        &["st.obj", "--supports", "s.json"],
        "overlap in plan",
    );
    // Units double precision cannot carry: refused by the mesh (1e200) or the solve (1e78).
    for (factor, needle) in [("1e200", "vertex 1 has the coordinate"), ("1e78", "loads")] {
        let f: f64 = factor.parse().unwrap();
        let scaled = format!(
            "v 0 0 0\nv {f:e} 0 0\nv {f:e} {f:e} 0\nv 0 {f:e} 0\nv {h:e} {h:e} 0.3\n\
             f 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\n",
            h = f / 2.0
        );
        rejects(
            &[("big.obj", &scaled[..]), ("s.json", "[0, 1, 2, 3]")],
            &["big.obj", "--supports", "s.json"],
            needle,
        );
    }
}

/// Runs formfind with `args` in a scratch folder set up by `prepare`; asserts exit status
/// `code`, a single stderr line containing every needle, and that every file and folder is as
/// it was, contents included.
fn fails_and_leaves_all_as_it_was(
    prepare: impl FnOnce(&Scratch),
    args: &[&str],
    code: i32,
    needles: &[&str],
) {
    static CASE: AtomicUsize = AtomicUsize::new(0);
    let dir = Scratch::new(&format!(
        "untouched-{}",
        CASE.fetch_add(1, Ordering::Relaxed)
    ));
    prepare(&dir);
    let before = dir.snapshot();
    let out = run(&dir.0, args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(code), "{args:?}: {stderr}");
    assert_eq!(
        stderr.lines().count(),
        1,
        "{args:?}: not one line: {stderr}"
    );
    for needle in needles {
        assert!(
            stderr.contains(needle),
            "{args:?}: `{stderr}` lacks `{needle}`"
        );
    }
    assert!(
        dir.snapshot() == before,
        "{args:?}: files changed: {:?}",
        dir.listing()
    );
}

fn old_mesh(dir: &Scratch) {
    fs::write(dir.path("o.obj"), "# the previous result\n").unwrap();
}

#[test]
fn unwritable_outputs_are_rejected_before_the_run() {
    let outputs = ["--out", "o.obj", "--report", "r.json", "--pictures", "pics"];
    // The report's path is a folder: the mesh before it must not be written or replaced.
    fails_and_leaves_all_as_it_was(
        |d| {
            old_mesh(d);
            fs::create_dir(d.path("R")).unwrap();
        },
        &["--out", "o.obj", "--report", "R", "--pictures", "pics"],
        2,
        &["--report", "`R` is a folder"],
    );
    // One picture's path is a folder.
    fails_and_leaves_all_as_it_was(
        |d| {
            old_mesh(d);
            fs::create_dir_all(d.path("pics/residuals.svg")).unwrap();
        },
        &outputs,
        2,
        &["--pictures", "residuals.svg` is a folder"],
    );
    // The pictures' folder would be inside a file.
    fails_and_leaves_all_as_it_was(
        |d| fs::write(d.path("file"), "").unwrap(),
        &[
            "--out",
            "a/o.obj",
            "--report",
            "a/r.json",
            "--pictures",
            "file/pics",
        ],
        2,
        &["--pictures", "`file` is not a folder"],
    );
}

#[test]
fn clashing_output_paths_are_rejected_naming_both_options() {
    fails_and_leaves_all_as_it_was(
        old_mesh,
        &["--out", "o.obj", "--report", "o.obj"],
        2,
        &["--out and --report name the same file `o.obj`"],
    );
    fails_and_leaves_all_as_it_was(
        |d| fs::create_dir(d.path("sub")).unwrap(),
        &["--out", "./x.obj", "--report", "sub/../x.obj"],
        2,
        &["--out and --report name the same file"],
    );
    fails_and_leaves_all_as_it_was(
        |_| {},
        &["--pictures", "p", "--report", "p/residuals.svg"],
        2,
        &["--report and --pictures name the same file"],
    );
    fails_and_leaves_all_as_it_was(
        |_| {},
        &["--report", "d", "--pictures", "d"],
        2,
        &["--report `d` and --pictures `d/plan_forces.svg` clash"],
    );
    // The embedded input's copy goes beside --out.
    fails_and_leaves_all_as_it_was(
        |_| {},
        &["--out", "o.obj", "--report", "vault-input.obj"],
        2,
        &["--report and the embedded input's copy"],
    );
}

#[test]
fn a_failed_write_leaves_nothing_behind_and_keeps_old_files() {
    // The report's name is valid but its temporary file's (longer by its prefix and suffix)
    // is not: the write fails after the checks, once the mesh is already staged.
    let long = format!("{}.json", "r".repeat(245));
    fails_and_leaves_all_as_it_was(
        old_mesh,
        &[
            "--stress-only",
            "--out",
            "o.obj",
            "--report",
            &long,
            "--pictures",
            "a/pics",
        ],
        1,
        &["File name too long"],
    );
}

#[test]
fn existing_outputs_are_replaced_when_all_are_written() {
    let dir = Scratch::new("replace");
    old_mesh(&dir);
    let out = run(
        &dir.0,
        &[
            "--stress-only",
            "--out",
            "o.obj",
            "--report",
            "r.json",
            "--pictures",
            "p",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (positions, _) = read_obj(&dir.path("o.obj"));
    assert!(!positions.is_empty(), "o.obj was not replaced");
    let hidden: Vec<String> = (dir.listing().into_iter())
        .filter(|n| n.contains(".formfind-"))
        .collect();
    assert!(hidden.is_empty(), "left behind: {hidden:?}");
}

#[test]
fn help_lists_every_option() {
    let dir = Scratch::new("help");
    let out = run(&dir.0, &["--help"]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    for flag in [
        "--supports",
        "--anchor-boundary",
        "--out",
        "--report",
        "--pictures",
        "--stress-only",
        "--solver",
        "--qp",
        "--tol",
        "--max-iter",
        "--qmin",
        "--qmin-scope",
        "--qmax",
        "--tau",
        "--holes",
        "--odt",
        "--density",
        "--load",
        "--up",
    ] {
        assert!(text.contains(flag), "--help lacks {flag}");
    }
    assert!(dir.listing().is_empty());
}

#[test]
fn not_converged_writes_outputs_and_exits_3() {
    let dir = Scratch::new("max-iter");
    let out = run(&dir.0, &["--max-iter", "2"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.contains("not converged"), "{stderr}");
    let r = read_json(&dir.path("formfind-out/report.json"));
    assert_eq!(r["termination"], "max_iterations");
    assert_eq!(r["iterations"], 2);
    assert_eq!(r["step_solvers"], serde_json::json!(["native", "native"]));
    assert!(dir.path("formfind-out/vault-formfound.obj").is_file());
    check_pictures(&dir.path("formfind-out/pictures"));
}

#[test]
fn anchor_boundary_with_quad_faces() {
    // A 4 × 4 grid of vertices, 3 × 3 quads; the four inner vertices are raised.
    let mut obj = String::new();
    for j in 0..4 {
        for i in 0..4 {
            let inner = (1..3).contains(&i) && (1..3).contains(&j);
            obj += &format!("v {i} {j} {}\n", if inner { 0.8 } else { 0.0 });
        }
    }
    for j in 0..3 {
        for i in 0..3 {
            let v = |di: usize, dj: usize| (j + dj) * 4 + i + di + 1;
            obj += &format!("f {} {} {} {}\n", v(0, 0), v(1, 0), v(1, 1), v(0, 1));
        }
    }
    let dir = Scratch::new("quads");
    fs::write(dir.path("quads.obj"), obj).unwrap();
    let out = run(&dir.0, &["quads.obj", "--anchor-boundary"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let od = dir.path("formfind-out");
    let (_, faces) = read_obj(&od.join("quads-formfound.obj"));
    assert_eq!(faces.len(), 18, "each quad is split into two triangles");
    let r = read_json(&od.join("report.json"));
    assert_eq!(r["anchored"].as_array().unwrap().len(), 12);
    check_equilibrium(&od.join("quads-formfound.obj"), &od.join("report.json"));
}

/// `--qp` chooses the QP solver; the report says which was asked for and which answered, and
/// both reach the same optimum on the embedded vault's input shape (the same objective: the
/// optimal forces themselves need not be unique).
#[test]
fn qp_solver_option_is_honoured_and_reported() {
    let mut objective = Vec::new();
    for qp in ["native", "clarabel"] {
        let dir = Scratch::new(&format!("qp-{qp}"));
        let out = run(&dir.0, &["--stress-only", "--qp", qp]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let r = read_json(&dir.path("formfind-out/report.json"));
        assert_eq!(r["settings"]["qp_solver"], qp);
        assert_eq!(r["qp_solver_used"], qp);
        assert_eq!(r["step_solvers"], serde_json::json!([qp]));
        objective.push(r["objective"].as_f64().unwrap());
    }
    let (a, b) = (objective[0], objective[1]);
    println!("objective: native {a:e}, clarabel {b:e}");
    assert!(
        (a - b).abs() <= 1e-6 * a.abs().max(b.abs()),
        "native {a} vs clarabel {b}"
    );
}

/// `--holes` chooses the Airy jump around holes and the report says which; on the embedded
/// vault (two holes, free edges) affine jumps, the default, reach a lower optimum than
/// constant ones.
#[test]
fn holes_option_is_honoured_and_reported() {
    let mut objective = Vec::new();
    for holes in [None, Some("constant"), Some("affine")] {
        let dir = Scratch::new(&format!("holes-{}", holes.unwrap_or("default")));
        let mut args = vec!["--stress-only"];
        if let Some(h) = holes {
            args.extend(["--holes", h]);
        }
        let out = run(&dir.0, &args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let r = read_json(&dir.path("formfind-out/report.json"));
        assert_eq!(r["settings"]["holes"], holes.unwrap_or("affine"));
        objective.push(r["objective"].as_f64().unwrap());
    }
    let [default, constant, affine] = objective[..] else {
        unreachable!()
    };
    println!("objective: default {default:e}, constant {constant:e}, affine {affine:e}");
    assert_eq!(default, affine);
    assert!(
        affine < constant * (1.0 - 1e-3),
        "affine {affine} vs constant {constant}"
    );
}

/// A 4 × 4 grid of quads as a Y-up modeller writes it: heights along the second axis, the
/// plan in the first and third (z = −y of the Z-up frame).
fn y_up_grid() -> String {
    let mut obj = String::new();
    for j in 0..4 {
        for i in 0..4 {
            let inner = (1..3).contains(&i) && (1..3).contains(&j);
            obj += &format!("v {i} {} {}\n", if inner { 0.8 } else { 0.0 }, -j);
        }
    }
    for j in 0..3 {
        for i in 0..3 {
            let v = |di: usize, dj: usize| (j + dj) * 4 + i + di + 1;
            obj += &format!("f {} {} {} {}\n", v(0, 0), v(1, 0), v(1, 1), v(0, 1));
        }
    }
    obj
}

#[test]
fn a_y_up_mesh_is_refused_with_a_hint_and_read_with_up_y() {
    rejects(
        &[("y.obj", &y_up_grid())],
        &["y.obj", "--anchor-boundary"],
        "try --up y",
    );
    rejects(&[], &["--up", "y"], "--up y needs a MESH");
    let dir = Scratch::new("y-up");
    fs::write(dir.path("y.obj"), y_up_grid()).unwrap();
    let out = run(&dir.0, &["y.obj", "--anchor-boundary", "--up", "y"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let od = dir.path("formfind-out");
    let r = read_json(&od.join("report.json"));
    assert_eq!(r["settings"]["up"], "y");
    assert_eq!(r["anchored"].as_array().unwrap().len(), 12);
    // The output keeps the file's axes: the plan (x, z) as read, heights along y.
    let input: Vec<Vec<f64>> = (y_up_grid().lines())
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| l.split(' ').map(|x| x.parse().unwrap()).collect())
        .collect();
    let (output, _) = read_obj(&od.join("y-formfound.obj"));
    for (a, b) in input.iter().zip(&output) {
        assert_eq!((a[0], a[2]), (b[0], b[2]), "plan moved: {a:?} -> {b:?}");
        let inner = a[1] > 0.0;
        assert!(
            !inner || b[1] > 0.0,
            "an inner vertex went below its supports: {b:?}"
        );
        assert!(inner || b[1] == 0.0, "a support moved: {b:?}");
    }
    assert_eq!(input.len(), output.len());
}

#[test]
fn infeasible_bounds_write_outputs_and_exit_3() {
    let dir = Scratch::new("infeasible");
    let out = run(&dir.0, &["--qmin", "10", "--qmax", "1e-6abs"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.contains("not converged (infeasible)"), "{stderr}");
    let r = read_json(&dir.path("formfind-out/report.json"));
    assert_eq!(r["termination"], "infeasible");
    assert_eq!(r["iterations"], 1);
    let loads = numbers(&r["loads"]);
    assert_eq!(
        loads.len(),
        r["mesh"]["vertices"].as_u64().unwrap() as usize
    );
    assert!(dir.path("formfind-out/vault-formfound.obj").is_file());
}

/// The same cap with the default (nearest) method converges from its mirror image, and the
/// report says so.
#[test]
fn a_hanging_cap_is_reported_mirrored() {
    let dir = Scratch::new("hanging-nearest");
    let cap = voussoir::generate::cap_dome(0.8, 300).unwrap();
    let heights: Vec<f64> = cap.positions().iter().map(|p| -p[2]).collect();
    let cap = cap.with_heights(&heights).unwrap();
    voussoir::io::write_obj(&dir.path("hanging.obj"), cap.positions(), cap.faces()).unwrap();
    let anchored = cap.anchored_ids();
    let supports = serde_json::json!({ "anchored": anchored }).to_string();
    fs::write(dir.path("s.json"), supports).unwrap();
    let out = run(&dir.0, &["hanging.obj", "--supports", "s.json"]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    let r = read_json(&dir.path("formfind-out/report.json"));
    assert_eq!(r["termination"], "converged");
    assert_eq!(r["mirrored"], true);
}

/// A hanging cap (concave up) stalls the paper's loop without a vertex to blame (with a
/// height limit beyond its moves): the summary says so in its one line, without an empty
/// list of details.
#[test]
fn a_stall_without_vertices_prints_no_empty_details() {
    let dir = Scratch::new("hanging");
    let cap = voussoir::generate::cap_dome(0.8, 300).unwrap();
    let hanging: Vec<f64> = cap.positions().iter().map(|p| -p[2]).collect();
    let cap = cap.with_heights(&hanging).unwrap();
    voussoir::io::write_obj(&dir.path("hanging.obj"), cap.positions(), cap.faces()).unwrap();
    let anchored: Vec<usize> = (0..cap.n_vertices())
        .filter(|&v| cap.anchored()[v])
        .collect();
    let supports = serde_json::json!({ "anchored": anchored }).to_string();
    fs::write(dir.path("s.json"), supports).unwrap();
    let out = run(
        &dir.0,
        &[
            "hanging.obj",
            "--supports",
            "s.json",
            "--method",
            "paper",
            "--max-height-change",
            "1000",
        ],
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(3), "{stdout}");
    let r = read_json(&dir.path("formfind-out/report.json"));
    assert_eq!(r["termination"], "stalled");
    assert_eq!(r["termination_vertices"], serde_json::json!([]));
    assert!(r["termination_detail"].is_null());
    assert!(stdout.contains("stalled after"), "{stdout}");
    assert!(
        !stdout.contains("details") && !stdout.contains("vertices:"),
        "{stdout}"
    );
}

/// A latitude-longitude dome in quads, as a modeller builds one: the fan split turns each
/// ring into quads all split along the same diagonal, which no network with every q ≥ q_min
/// > 0 balances; q_min binds the quads' edges only, so it form-finds with the defaults.
#[test]
fn a_latitude_longitude_quad_dome_form_finds_with_defaults() {
    let (rings, sectors) = (5, 24);
    let (obj, _) = common::quad_dome_obj(rings, sectors);
    let dir = Scratch::new("lat-long");
    fs::write(dir.path("dome.obj"), obj).unwrap();
    let out = run(&dir.0, &["dome.obj", "--anchor-lowest", "1e-9"]);
    assert!(
        out.status.success(),
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    let od = dir.path("formfind-out");
    let r = read_json(&od.join("report.json"));
    assert_eq!(r["settings"]["polygon_diagonals"], (rings - 1) * sectors);
    assert_eq!(r["anchored"].as_array().unwrap().len(), sectors);
    check_equilibrium(&od.join("dome-formfound.obj"), &od.join("report.json"));
}

//! Helpers of tests/formfind.rs: the example's executable, scratch folders, and an OBJ reader
//! and equilibrium check of this file's own (not the library's).
#![allow(dead_code)]

use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

use serde_json::Value;

/// The example's executable, built once per test run with the profile of this test binary
/// (`cargo test` builds examples already; `cargo test --test formfind` does not).
pub fn formfind() -> &'static Path {
    static BIN: OnceLock<PathBuf> = OnceLock::new();
    BIN.get_or_init(|| {
        let exe = std::env::current_exe().expect("test executable path");
        // target/<profile>/deps/formfind-HASH → target/<profile>
        let profile_dir = exe.parent().and_then(Path::parent).expect("target dir");
        let profile = profile_dir
            .file_name()
            .unwrap()
            .to_string_lossy()
            .into_owned();
        let mut build = Command::new(env!("CARGO"));
        build
            .args(["build", "--quiet", "--example", "formfind"])
            .current_dir(env!("CARGO_MANIFEST_DIR"));
        match profile.as_str() {
            "debug" => {}
            "release" => {
                build.arg("--release");
            }
            other => {
                build.args(["--profile", other]);
            }
        }
        let status = build.status().expect("cargo runs");
        assert!(status.success(), "building the formfind example failed");
        let bin = profile_dir
            .join("examples")
            .join(format!("formfind{}", std::env::consts::EXE_SUFFIX));
        assert!(bin.is_file(), "{} not found", bin.display());
        bin
    })
}

/// A fresh empty folder for one test, removed when dropped.
pub struct Scratch(pub PathBuf);

impl Scratch {
    pub fn new(name: &str) -> Scratch {
        let dir =
            std::env::temp_dir().join(format!("voussoir-formfind-{}-{name}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
        Scratch(dir)
    }

    pub fn path(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }

    /// Every file and folder below the scratch folder, relative to it, sorted.
    pub fn listing(&self) -> Vec<String> {
        fn walk(dir: &Path, base: &Path, out: &mut Vec<String>) {
            for entry in fs::read_dir(dir).unwrap() {
                let p = entry.unwrap().path();
                out.push(p.strip_prefix(base).unwrap().display().to_string());
                if fs::symlink_metadata(&p).unwrap().is_dir() {
                    walk(&p, base, out);
                }
            }
        }
        let mut out = Vec::new();
        walk(&self.0, &self.0, &mut out);
        out.sort();
        out
    }
}

impl Scratch {
    /// Every path below the scratch folder with the content of each regular file, the target of
    /// each symbolic link (`link:` and the path) and None for anything else (folders, FIFOs:
    /// reading a FIFO would wait for a writer).
    pub fn snapshot(&self) -> Vec<(String, Option<Vec<u8>>)> {
        self.listing()
            .into_iter()
            .map(|name| {
                let path = self.path(&name);
                let content = match fs::symlink_metadata(&path) {
                    Ok(m) if m.is_symlink() => fs::read_link(&path)
                        .ok()
                        .map(|t| format!("link:{}", t.display()).into_bytes()),
                    Ok(m) if m.is_file() => fs::read(&path).ok(),
                    _ => None,
                };
                (name, content)
            })
            .collect()
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = fs::remove_dir_all(&self.0);
    }
}

pub fn run(cwd: &Path, args: &[&str]) -> Output {
    Command::new(formfind())
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("formfind runs")
}

pub mod views;
pub mod xml;

#[path = "../common/mod.rs"]
pub mod common;
#[allow(unused_imports)] // each test binary uses its own part
pub use common::{models_dir, MODELS};

/// Vertices and triangles (0-based) of an OBJ file: `v x y z` and `f a b c` lines only.
pub fn read_obj(path: &Path) -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
    let text = fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let (mut v, mut f) = (Vec::new(), Vec::new());
    for line in text.lines() {
        let mut tokens = line.split_whitespace();
        match tokens.next() {
            Some("v") => {
                let c: Vec<f64> = tokens.take(3).map(|t| t.parse().unwrap()).collect();
                v.push([c[0], c[1], c[2]]);
            }
            Some("f") => {
                let i: Vec<usize> = tokens
                    .map(|t| t.split('/').next().unwrap().parse::<usize>().unwrap() - 1)
                    .collect();
                assert_eq!(i.len(), 3, "formfind writes triangles");
                f.push([i[0], i[1], i[2]]);
            }
            _ => {}
        }
    }
    (v, f)
}

pub fn read_json(path: &Path) -> Value {
    let text = fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

pub fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

/// Recomputes vertical and horizontal equilibrium from OUT.obj and R.json; returns ε∞.
pub fn check_equilibrium(obj: &Path, report_path: &Path) -> f64 {
    let (pos, faces) = read_obj(obj);
    let r = read_json(report_path);
    for key in [
        "termination",
        "iterations",
        "eps_inf",
        "history",
        "edges",
        "force_densities",
        "loads",
        "external_horizontal",
        "weights",
        "hole_coefficients",
        "objective",
        "hausdorff",
        "l2",
        "timings_s",
        "settings",
    ] {
        assert!(r.get(key).is_some(), "report lacks `{key}`");
    }
    for key in ["stress", "shape", "total"] {
        assert!(r["timings_s"][key].as_f64().unwrap() >= 0.0);
    }
    assert_eq!(r["termination"], "converged");
    // One ε∞ per stress step, and (nearest method) one per height step that reached
    // equilibrium: at most one after each stress step and after the start.
    let history = r["history"].as_array().unwrap();
    let steps = r["iterations"].as_u64().unwrap();
    assert!(
        (steps..=2 * steps + 1).contains(&(history.len() as u64)),
        "{} history entries for {steps} stress steps",
        history.len()
    );
    assert_eq!(history.last(), Some(&r["eps_inf"]));

    let n = pos.len();
    let edges: Vec<[usize; 2]> = r["edges"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| {
            [
                e[0].as_u64().unwrap() as usize,
                e[1].as_u64().unwrap() as usize,
            ]
        })
        .collect();
    let q = numbers(&r["force_densities"]);
    let p = numbers(&r["loads"]);
    assert_eq!(q.len(), edges.len());
    assert_eq!(p.len(), n);
    assert_eq!(numbers(&r["weights"]).len(), n);
    let mut external = vec![[0.0; 2]; n];
    for item in r["external_horizontal"].as_array().unwrap() {
        let v = item[0].as_u64().unwrap() as usize;
        external[v] = [item[1].as_f64().unwrap(), item[2].as_f64().unwrap()];
    }
    let mut free = vec![false; n];
    faces.iter().flatten().for_each(|&v| free[v] = true);
    for a in r["anchored"].as_array().unwrap() {
        free[a.as_u64().unwrap() as usize] = false;
    }

    // Every edge of the faces is reported, and nothing else.
    let mut from_faces: Vec<[usize; 2]> = faces
        .iter()
        .flat_map(|f| (0..3).map(move |k| [f[k].min(f[(k + 1) % 3]), f[k].max(f[(k + 1) % 3])]))
        .collect();
    from_faces.sort();
    from_faces.dedup();
    let mut reported = edges.clone();
    reported.sort();
    assert_eq!(
        reported, from_faces,
        "edges do not match the faces of OUT.obj"
    );

    // An edge whose bound is q ≥ 0 comes out of the Airy function at 0 up to round-off.
    let q_max = q.iter().fold(0.0f64, |a, &b| a.max(b));
    for (e, &qe) in q.iter().enumerate() {
        assert!(qe >= -1e-9 * q_max, "edge {e}: q = {qe} < 0 (tension)");
    }

    let mut res = vec![0.0; n];
    let mut hor = vec![[0.0; 2]; n];
    let mut scale = vec![0.0; n];
    for v in 0..n {
        res[v] = -p[v];
        hor[v] = external[v];
    }
    for (&[i, j], &qe) in edges.iter().zip(&q) {
        for (a, b) in [(i, j), (j, i)] {
            res[a] += qe * (pos[a][2] - pos[b][2]);
            for d in 0..2 {
                hor[a][d] += qe * (pos[a][d] - pos[b][d]);
            }
            scale[a] += qe * (pos[a][0] - pos[b][0]).hypot(pos[a][1] - pos[b][1]);
        }
    }
    let ids: Vec<usize> = (0..n).filter(|&v| free[v]).collect();
    let mean_p = ids.iter().map(|&v| p[v]).sum::<f64>() / ids.len() as f64;
    assert!(mean_p > 0.0);
    let eps = ids.iter().map(|&v| res[v].abs()).fold(0.0, f64::max) / mean_p;
    assert!(eps < 1e-6, "recomputed ε∞ = {eps:e} ≥ 1e-6");
    let reported_eps = r["eps_inf"].as_f64().unwrap();
    assert!(
        (eps - reported_eps).abs() <= 1e-9 + 1e-6 * reported_eps,
        "recomputed ε∞ {eps:e} differs from the reported {reported_eps:e}"
    );
    for &v in &ids {
        let h = hor[v][0].hypot(hor[v][1]);
        assert!(
            h <= 1e-8 * (scale[v] + mean_p),
            "vertex {v}: horizontal imbalance {h:e} (edge forces {:e})",
            scale[v]
        );
    }
    eps
}

/// OUT.obj keeps the input's plan and faces.
pub fn check_same_plan(input: &Path, output: &Path) {
    let (a, fa) = read_obj(input);
    let (b, fb) = read_obj(output);
    assert_eq!(fa, fb, "faces changed");
    assert_eq!(a.len(), b.len());
    for (v, (p, q)) in a.iter().zip(&b).enumerate() {
        assert!(p[0] == q[0] && p[1] == q[1], "vertex {v} moved in plan");
    }
}

pub const PICTURES: [&str; 5] = [
    "plan_forces.svg",
    "force_diagram.svg",
    "residuals.svg",
    "height_change.svg",
    "shape_3d.svg",
];

/// Every picture is a well-formed SVG document.
pub fn check_pictures(dir: &Path) {
    for name in PICTURES {
        let text = fs::read_to_string(dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        let elements = xml::parse_xml(&text);
        assert_eq!(elements[0].name, "svg", "{name}: the root is not <svg>");
    }
}

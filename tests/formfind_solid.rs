//! `formfind --solid`: a closed, outward, printable solid of the result in every solid
//! format, `--ascii` for STL and PLY, and bad arguments (exit 2, one line, nothing written).

mod formfind_support;

use std::collections::HashMap;
use std::fs;

use formfind_support::*;
use voussoir::io;

fn watertight(faces: &[[u32; 3]]) -> bool {
    let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
    for f in faces {
        for k in 0..3 {
            *directed.entry((f[k], f[(k + 1) % 3])).or_default() += 1;
        }
    }
    directed
        .iter()
        .all(|(&(a, b), &n)| n == 1 && directed.get(&(b, a)) == Some(&1))
}

/// Runs the embedded default with `extra` arguments; asserts success.
fn run_default(dir: &Scratch, extra: &[&str]) -> serde_json::Value {
    let mut args = vec!["--report", "r.json", "--pictures", "p", "--out", "v.obj"];
    args.extend(extra);
    let out = run(&dir.0, &args);
    assert!(
        out.status.success(),
        "{extra:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    read_json(&dir.path("r.json"))
}

#[test]
fn solid_in_every_format_is_closed_outward_and_as_thick_as_asked() {
    let dir = Scratch::new("solid-formats");
    for name in ["s.off", "s.obj", "s.stl", "s.ply"] {
        let report = run_default(&dir, &["--solid", "0.08", name]);
        let (p, f) = io::read_mesh(&dir.path(name)).unwrap();
        let w = io::weld(&p, &f, io::DEFAULT_WELD_TOLERANCE).unwrap();
        assert!(watertight(&w.faces), "{name}");
        let volume = voussoir::signed_volume(&w.positions, &w.faces);
        let solid = &report["solid"];
        let expected = solid["mid_surface_area"].as_f64().unwrap() * 0.08;
        assert!(
            (volume / expected - 1.0).abs() < 1e-2,
            "{name}: volume {volume}, area x thickness {expected}"
        );
        assert_eq!(solid["faces"].as_u64().unwrap() as usize, w.faces.len());
        assert_eq!(solid["thickness"], 0.08);
    }
    run_default(&dir, &["--solid", "0.08", "s.3mf"]);
    let bytes = fs::read(dir.path("s.3mf")).unwrap();
    assert!(bytes.starts_with(b"PK\x03\x04"), "3MF is a zip package");
}

#[test]
fn solid_from_density_and_unit_weight() {
    let dir = Scratch::new("solid-density");
    run_default(&dir, &["--solid", "0.05", "a.off"]);
    let r = run_default(
        &dir,
        &[
            "--density",
            "2",
            "--solid",
            "density",
            "b.off",
            "--solid-unit-weight",
            "40",
        ],
    );
    assert!(r["solid"]["volume"].as_f64().unwrap() > 0.0);
    assert_eq!(r["solid"]["thickness"]["unit_weight"], 40.0);
    let (a, b) = (
        io::read_mesh(&dir.path("a.off")).unwrap(),
        io::read_mesh(&dir.path("b.off")).unwrap(),
    );
    assert_eq!(a, b, "density 2 / unit weight 40 is thickness 0.05");
}

#[test]
fn ascii_writes_stl_and_ply_as_text() {
    let dir = Scratch::new("ascii");
    run_default(&dir, &["--solid", "0.05", "s.stl"]);
    assert!(!fs::read(dir.path("s.stl")).unwrap().starts_with(b"solid"));
    let args = ["--report", "r.json", "--pictures", "p", "--ascii"];
    let mut all = args.to_vec();
    all.extend(["--out", "v.ply", "--solid", "0.05", "t.stl"]);
    assert!(run(&dir.0, &all).status.success());
    assert!(fs::read(dir.path("t.stl"))
        .unwrap()
        .starts_with(b"solid voussoir"));
    let ply = fs::read(dir.path("v.ply")).unwrap();
    assert!(String::from_utf8_lossy(&ply).contains("format ascii 1.0"));
    let (a, _) = io::read_mesh(&dir.path("s.stl")).unwrap();
    let (b, _) = io::read_mesh(&dir.path("t.stl")).unwrap();
    assert_eq!(
        a, b,
        "binary and ASCII STL hold the same single-precision values"
    );
}

#[test]
fn bad_solid_arguments_exit_2_with_one_line_and_nothing_written() {
    let dir = Scratch::new("solid-bad");
    let cases: [(&[&str], &str); 9] = [
        (&["--solid", "0", "s.stl"], "expected a thickness > 0"),
        (&["--solid", "-1", "s.stl"], "expected a thickness > 0"),
        (&["--solid", "thick", "s.stl"], "`thick`"),
        (&["--solid", "0.1"], "--solid: expected THICKNESS OUT"),
        (&["--solid", "0.1", "s.xyz"], "unknown extension `.xyz`"),
        (
            &["--solid", "density", "s.stl"],
            "needs --solid-unit-weight",
        ),
        (&["--solid-unit-weight", "3"], "needs --solid density"),
        (&["--out", "shell.3mf"], "3MF holds closed solids"),
        // Found after form finding: the lower offset of the crown turns over.
        (&["--solid", "20", "s.stl"], "turns over"),
    ];
    for (args, needle) in cases {
        let mut all = vec!["--report", "r.json", "--pictures", "p"];
        all.extend(args);
        let out = run(&dir.0, &all);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{args:?}: {stderr}");
        assert!(stderr.contains(needle), "{args:?}: {stderr}");
        assert!(dir.listing().is_empty(), "{args:?}: {:?}", dir.listing());
    }
    let out = run(&dir.0, &["--solid", "20", "s.stl"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("at face ") && stderr.contains("(vertices "),
        "{stderr}"
    );
}

#[test]
fn help_documents_solid_and_ascii() {
    let dir = Scratch::new("solid-help");
    let out = run(&dir.0, &["--help"]);
    let text = String::from_utf8_lossy(&out.stdout);
    for option in ["--solid T OUT", "--solid-unit-weight W", "--ascii", ".3mf"] {
        assert!(text.contains(option), "--help lacks {option}");
    }
}

#[test]
fn shared_model_solid_with_holes_is_closed() {
    let Some(models) = models_dir() else { return };
    let dir = Scratch::new("solid-hex");
    let (obj, json) = (models.join("hex.obj"), models.join("hex.json"));
    let args = [
        obj.to_str().unwrap(),
        "--supports",
        json.to_str().unwrap(),
        "--report",
        "r.json",
        "--pictures",
        "p",
        "--out",
        "hex.off",
        "--solid",
        "0.01",
        "hex-solid.stl",
    ];
    let out = run(&dir.0, &args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report = read_json(&dir.path("r.json"));
    assert_eq!(report["mesh"]["holes"], 3);
    let (p, f) = io::read_mesh(&dir.path("hex-solid.stl")).unwrap();
    let w = io::weld(&p, &f, io::DEFAULT_WELD_TOLERANCE).unwrap();
    assert!(watertight(&w.faces));
    let volume = voussoir::signed_volume(&w.positions, &w.faces);
    let reported = report["solid"]["volume"].as_f64().unwrap();
    assert!(
        (volume / reported - 1.0).abs() < 1e-4,
        "{volume} vs {reported}"
    );
    let expected = report["solid"]["mid_surface_area"].as_f64().unwrap() * 0.01;
    assert!(
        (volume / expected - 1.0).abs() < 1e-2,
        "{volume} vs {expected}"
    );
}

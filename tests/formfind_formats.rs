//! The `formfind` example with OFF, STL and PLY meshes in and out: the same form finding as
//! from OBJ, STL welded with supports given on its own vertex ids, `--anchor-lowest`, and bad
//! files rejected with exit status 2, one line naming the line or element, and no output.

mod formfind_support;

use std::fs;
use std::path::Path;

use formfind_support::*;
use voussoir::io;

/// Runs formfind in `dir` on `args` plus the output paths `out` and `r.json`; asserts success.
fn run_ok(dir: &Scratch, args: &[&str], out: &str) -> serde_json::Value {
    let (out, report, pictures) = (dir.path(out), dir.path("r.json"), dir.path("pics"));
    let mut all: Vec<&str> = args.to_vec();
    all.extend([
        "--out",
        out.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
        "--pictures",
        pictures.to_str().unwrap(),
    ]);
    let result = run(&dir.0, &all);
    assert!(
        result.status.success(),
        "{args:?}: {:?}\n{}",
        result.status,
        String::from_utf8_lossy(&result.stderr)
    );
    read_json(&report)
}

fn bits(positions: &[[f64; 3]]) -> Vec<[u64; 3]> {
    positions.iter().map(|p| p.map(f64::to_bits)).collect()
}

#[test]
fn off_in_ply_out_form_finds_as_obj_does() {
    let Some(models) = models_dir() else { return };
    let dir = Scratch::new("off-ply");
    let (obj, json) = (
        models.join("neumunster.obj"),
        models.join("neumunster.json"),
    );
    let (positions, faces) = io::read_mesh(&obj).unwrap();
    let off = dir.path("neumunster.off");
    io::write_mesh(&off, &positions, &faces).unwrap();
    let json = json.to_str().unwrap();
    let from_obj = run_ok(&dir, &[obj.to_str().unwrap(), "--supports", json], "a.obj");
    let from_off = run_ok(&dir, &[off.to_str().unwrap(), "--supports", json], "b.ply");
    assert_eq!(from_obj["anchored"], from_off["anchored"]);
    assert_eq!(from_off["settings"]["weld"]["merged"], 0);
    let (a, fa) = io::read_mesh(&dir.path("a.obj")).unwrap();
    let (b, fb) = io::read_mesh(&dir.path("b.ply")).unwrap();
    assert_eq!(bits(&a), bits(&b));
    assert_eq!(fa, fb);
    check_equilibrium(&dir.path("a.obj"), &dir.path("r.json"));
}

#[test]
fn stl_input_is_welded_and_its_supports_mapped() {
    let Some(models) = models_dir() else { return };
    let dir = Scratch::new("stl");
    let (positions, faces) = io::read_mesh(&models.join("neumunster.obj")).unwrap();
    let anchored = io::read_supports(&models.join("neumunster.json")).unwrap();
    let stl = dir.path("neumunster.stl");
    io::write_mesh(&stl, &positions, &faces).unwrap();
    // Supports on the STL's own vertices: the last corner of each anchored vertex, as a user
    // picking them in the file would find them.
    let soup_ids: Vec<u32> = anchored
        .iter()
        .map(|&v| {
            let corners: Vec<u32> = faces.iter().flatten().copied().collect();
            let at = corners.iter().rposition(|&u| u == v).unwrap();
            at as u32
        })
        .collect();
    let supports = dir.path("s.json");
    fs::write(&supports, format!("{{\"anchored\": {soup_ids:?}}}")).unwrap();
    let report = run_ok(
        &dir,
        &[
            stl.to_str().unwrap(),
            "--supports",
            supports.to_str().unwrap(),
        ],
        "out.obj",
    );
    let weld = &report["settings"]["weld"];
    assert_eq!(weld["input_vertices"], 3 * faces.len());
    assert_eq!(weld["merged"], 3 * faces.len() - 325);
    assert_eq!(report["anchored"].as_array().unwrap().len(), anchored.len());
    // The anchored welded vertices sit where the original supports are (in single precision).
    let (out, _) = io::read_mesh(&dir.path("out.obj")).unwrap();
    for id in report["anchored"].as_array().unwrap() {
        let p = out[id.as_u64().unwrap() as usize];
        assert!(anchored
            .iter()
            .any(|&v| { positions[v as usize].map(|c| f64::from(c as f32)) == p }));
    }
    check_equilibrium(&dir.path("out.obj"), &dir.path("r.json"));
}

#[test]
fn anchor_lowest_finds_the_supports_of_a_vault_on_the_ground() {
    let Some(models) = models_dir() else { return };
    let dir = Scratch::new("lowest");
    let obj = models.join("free_vault.obj");
    let json = models.join("free_vault.json");
    let given = run_ok(
        &dir,
        &[obj.to_str().unwrap(), "--supports", json.to_str().unwrap()],
        "a.obj",
    );
    let lowest = run_ok(
        &dir,
        &[obj.to_str().unwrap(), "--anchor-lowest", "1e-9"],
        "b.obj",
    );
    assert_eq!(given["anchored"], lowest["anchored"]);
    assert!(lowest["settings"]["supports"]
        .as_str()
        .unwrap()
        .contains("lowest height"));
    // An absolute reach of half the vault's height anchors more.
    let wide = run_ok(
        &dir,
        &[obj.to_str().unwrap(), "--anchor-lowest", "0.5abs"],
        "c.obj",
    );
    assert!(wide["anchored"].as_array().unwrap().len() > 28);
}

/// Runs formfind on `file` (written from `bytes`) with `--anchor-boundary`; asserts exit 2,
/// one line holding `message`, and nothing written.
fn rejects_file(name: &str, bytes: &[u8], message: &str) {
    let dir = Scratch::new(&format!("bad-{name}"));
    fs::write(dir.path(name), bytes).unwrap();
    let before = dir.listing();
    let out = run(&dir.0, &[name, "--anchor-boundary", "--out", "o.ply"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{name}: {stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.contains(message), "{name}: {stderr}");
    assert_eq!(dir.listing(), before, "{name}: something was written");
}

fn binary_ply(dir: &Path) -> Vec<u8> {
    let path = dir.join("t.ply");
    let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    io::write_mesh(&path, &positions, &[[0, 1, 2]]).unwrap();
    fs::read(path).unwrap()
}

#[test]
fn bad_files_exit_2_naming_the_line_or_element() {
    let source = Scratch::new("ply-source");
    let ply = binary_ply(&source.0);
    let mut stl = vec![0u8; 80];
    stl.extend(2u32.to_le_bytes());
    stl.extend([0u8; 60]);
    let tri = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n";
    rejects_file(
        "t.off",
        format!("{tri}3 0 1 3\n").as_bytes(),
        "t.off:6: face 0 refers to vertex 3",
    );
    rejects_file(
        "c.off",
        b"OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
        "before face 1",
    );
    rejects_file(
        "n.off",
        b"OFF\n3 1 0\n0 0 0\n1 0 nan\n",
        "n.off:4: vertex 1",
    );
    rejects_file("g.off", b"\x00\x01garbage", "g.off:1:");
    rejects_file("t.stl", &stl, "this file has 144 bytes");
    rejects_file("g.stl", b"abc", "neither ASCII STL");
    rejects_file("t.ply", &ply[..ply.len() - 3], "face 0");
    rejects_file(
        "g.ply",
        b"ply\nformat ascii 1.0\nelement vertex x\nend_header\n",
        "g.ply:3: bad header",
    );
    rejects_file("m.xyz", b"", "unknown extension `.xyz`");
}

#[test]
fn bad_options_of_formats_and_supports_exit_2() {
    let dir = Scratch::new("bad-options");
    fs::write(
        dir.path("m.off"),
        "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
    )
    .unwrap();
    let before = dir.listing();
    for (args, message) in [
        (
            &["m.off", "--anchor-boundary", "--out", "o.xyz"][..],
            "--out: invalid argument",
        ),
        (
            &["m.off", "--anchor-lowest", "-1"],
            "--anchor-lowest: -1 is not a finite number >= 0",
        ),
        (
            &["m.off", "--anchor-lowest", "0.1", "--anchor-boundary"],
            "not several",
        ),
        (
            &["m.off", "--anchor-boundary", "--weld", "x"],
            "--weld: expected a number",
        ),
        (&["--anchor-lowest", "0.1"], "need a MESH"),
    ] {
        let out = run(&dir.0, args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(message), "{args:?}: {stderr}");
    }
    assert_eq!(dir.listing(), before);
}

/// A 6×6 grid dome over the unit square with a sliver of about 1e-9 of the median plan area
/// (a vertex 1e-10 past the middle of an interior edge, so slightly inverted), as OBJ text.
fn sliver_dome_obj() -> String {
    const N: u32 = 6;
    let id = |i: u32, j: u32| j * (N + 1) + i + 1;
    let mut text = String::new();
    for j in 0..=N {
        for i in 0..=N {
            let (x, y) = (f64::from(i) / 6.0, f64::from(j) / 6.0);
            let z = 0.6 - (x - 0.5).powi(2) - (y - 0.5).powi(2);
            text += &format!("v {x:?} {y:?} {z:?}\n");
        }
    }
    // The middle of the diagonal of cell (2, 2), from (2, 2) to (3, 3), pushed across it.
    let m = (N + 1) * (N + 1) + 1;
    text += &format!("v {:?} {:?} 0.55\n", 2.5 / 6.0 + 1e-10, 2.5 / 6.0 - 1e-10);
    for j in 0..N {
        for i in 0..N {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            if (i, j) == (2, 2) {
                // (a, c, d) split at m on its edge (a, c): (a, m, d), (m, c, d) and the sliver.
                text += &format!("f {a} {b} {c}\nf {a} {m} {d}\nf {m} {c} {d}\nf {a} {c} {m}\n");
            } else {
                text += &format!("f {a} {b} {c}\nf {a} {c} {d}\n");
            }
        }
    }
    text
}

#[test]
fn plan_slivers_are_repaired_and_listed_or_rejected_with_strict() {
    let dir = Scratch::new("slivers");
    let mesh = dir.path("sliver.obj");
    fs::write(&mesh, sliver_dome_obj()).unwrap();
    let report = run_ok(
        &dir,
        &[mesh.to_str().unwrap(), "--anchor-boundary"],
        "out.off",
    );
    let repairs = report["plan_repairs"].as_array().unwrap();
    assert_eq!(repairs.len(), 1, "{repairs:?}");
    // Faces 28 to 31 are those of cell (2, 2): (a, b, c), then the split (a, c, d), sliver last.
    assert_eq!(
        repairs[0]["flip"]["faces"],
        serde_json::json!([31, 28]),
        "{repairs:?}"
    );
    assert_eq!(report["termination"], "converged");
    let before = dir.listing();
    let out = run(
        &dir.0,
        &[
            mesh.to_str().unwrap(),
            "--anchor-boundary",
            "--strict",
            "--out",
            "strict.obj",
        ],
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("(almost) zero plan area: 31"), "{stderr}");
    assert_eq!(dir.listing(), before);
}

//! The `formfind` example against issue 48's reproducers: PLY counts beyond 64 bits, ASCII PLY
//! and STL lines out of step with their counts, outputs that are devices, FIFOs, links or the
//! inputs, repeated options, extreme `--solid` thicknesses and messages that named the wrong
//! cause. Bad input: exit status 2, one line on stderr, nothing written; never a panic.

mod formfind_support;

use std::fs;
use std::sync::atomic::{AtomicUsize, Ordering};

use formfind_support::*;

/// A valid 5-vertex square with its centre: four triangles.
const SQUARE: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 0.3\n\
                      f 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\n";
const SUPPORTS: &str = "[0, 1, 2, 3]";

/// The PLY header of issue 48's reproducer with the given counts.
fn ply_head(format: &str, vertices: &str, faces: &str) -> String {
    format!(
        "ply\nformat {format} 1.0\nelement vertex {vertices}\nproperty float x\n\
         property float y\nproperty float z\nelement face {faces}\n\
         property list uchar int vertex_indices\nend_header\n"
    )
}

/// Runs `args` in a scratch folder holding `files` (and what `prepare` adds); asserts exit
/// status 2, one line on stderr holding every one of `needles`, no panic, and nothing
/// written or changed.
fn refused(
    files: &[(&str, &[u8])],
    prepare: impl FnOnce(&Scratch),
    args: &[&str],
    needles: &[&str],
) {
    static CASE: AtomicUsize = AtomicUsize::new(0);
    let dir = Scratch::new(&format!("hostile-{}", CASE.fetch_add(1, Ordering::Relaxed)));
    for (name, bytes) in files {
        fs::write(dir.path(name), bytes).unwrap();
    }
    prepare(&dir);
    let before = dir.snapshot();
    let out = run(&dir.0, args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
    assert_eq!(
        stderr.lines().count(),
        1,
        "{args:?}: not one line: {stderr}"
    );
    assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
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

#[test]
fn ply_counts_beyond_64_bits_are_errors_naming_the_line() {
    let huge = "99999999999999999999999";
    let vertices = "0 0 0\n1 0 0\n0 1 0\n";
    let cases = [
        (ply_head("ascii", huge, "1") + vertices + "3 0 1 2\n", "p.ply:3: bad header: element `vertex`: count `99999999999999999999999` is larger than 18446744073709551615"),
        (ply_head("ascii", "3", huge) + vertices + "3 0 1 2\n", "p.ply:7: bad header: element `face`"),
        (ply_head("binary_little_endian", huge, "1"), "p.ply:3:"),
        (ply_head("binary_big_endian", "3", "18446744073709551616"), "p.ply:7:"),
    ];
    for (text, message) in cases {
        refused(
            &[("p.ply", text.as_bytes())],
            |_| {},
            &["p.ply", "--anchor-boundary"],
            &[message],
        );
    }
}

#[test]
fn ascii_ply_face_lines_must_match_their_count() {
    let vertices = "0 0 0\n1 0 0\n0 1 0\n1 1 0.5\n";
    let cases = [
        (
            ply_head("ascii", "4", "1") + vertices + "3 0 1 2 3\n",
            "p.ply:14: face 0: 1 more number than its properties take, in `3 0 1 2 3`",
        ),
        (
            ply_head("ascii", "4", "2") + vertices + "3 0 1 2 3 1 3 2\n3 0 1 3\n",
            "p.ply:14: face 0: 4 more numbers",
        ),
        (
            ply_head("ascii", "4", "1") + vertices + "3 0 1\n",
            "p.ply:14: face 0: the line ends before item 2 of `vertex_indices`",
        ),
        (
            ply_head("ascii", "4", "1") + vertices + "3 0 1 1\n",
            "face 0: lists vertex 1 twice",
        ),
    ];
    for (text, message) in cases {
        refused(
            &[("p.ply", text.as_bytes())],
            |_| {},
            &["p.ply", "--anchor-boundary"],
            &[message],
        );
    }
}

#[test]
fn stl_and_obj_lines_are_quoted_short_and_nothing_follows_endsolid() {
    let facet = "facet normal 0 0 1\n outer loop\n vertex 0 0 0\n vertex 1 0 0\n vertex 0 1 0\n endloop\nendfacet\n";
    let trailing = format!("solid a\n{facet}endsolid a\nthese bytes were ignored\n");
    refused(
        &[("t.stl", trailing.as_bytes())],
        |_| {},
        &["t.stl", "--anchor-boundary"],
        &["t.stl:10: expected `solid` (after `endsolid`, only another solid may follow) (`these bytes were ignored`)"],
    );
    // A 1 MB line is quoted by 40 characters, not echoed whole in Rust debug form.
    let long = format!(
        "solid a\n{}endsolid a\n",
        facet.replace("0 1 0", &"9".repeat(1 << 20))
    );
    refused(
        &[("l.stl", long.as_bytes())],
        |_| {},
        &["l.stl", "--anchor-boundary"],
        &["l.stl:6: expected `vertex x y z` for corner 2 of triangle 0 (`vertex 9999"],
    );
    let obj_long = format!("v 0 0 0\nv 1 0 0\nv 0 1 {}\nf 1 2 3\n", "x".repeat(1 << 20));
    refused(
        &[("l.obj", obj_long.as_bytes())],
        |_| {},
        &["l.obj", "--anchor-boundary"],
        &["l.obj:3: bad number `xxxx"],
    );
    refused(
        &[("r.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2\n")],
        |_| {},
        &["r.obj", "--anchor-boundary"],
        &["r.obj:4: face lists vertex 2 twice"],
    );
    for name in ["l.stl", "l.obj"] {
        let dir = Scratch::new(&format!("short-{name}"));
        let bytes = if name == "l.stl" {
            long.as_bytes()
        } else {
            obj_long.as_bytes()
        };
        fs::write(dir.path(name), bytes).unwrap();
        let out = run(&dir.0, &[name, "--anchor-boundary"]);
        assert!(
            out.stderr.len() < 300,
            "{name}: {} bytes on stderr",
            out.stderr.len()
        );
    }
}

/// Files of a run whose outputs are checked: the square, its supports, a FIFO, links.
#[cfg(unix)]
fn output_fixtures(dir: &Scratch) {
    use std::os::unix::fs::symlink;
    let made = std::process::Command::new("mkfifo")
        .arg(dir.path("fifo.json"))
        .status();
    assert!(made.unwrap().success());
    symlink("sq.obj", dir.path("to-input.obj")).unwrap();
    symlink("/dev/null", dir.path("null.obj")).unwrap();
    symlink("fifo.json", dir.path("to-fifo.json")).unwrap();
    fs::hard_link(dir.path("sq.obj"), dir.path("hard.obj")).unwrap();
}

#[cfg(unix)]
#[test]
fn outputs_that_are_devices_fifos_or_inputs_are_refused() {
    let files: [(&str, &[u8]); 2] = [
        ("sq.obj", SQUARE.as_bytes()),
        ("s.json", SUPPORTS.as_bytes()),
    ];
    let cases: [(&[&str], &str); 11] = [
        (
            &["--report", "/dev/full"],
            "--report: /dev/full: is a character device, not a regular file",
        ),
        (
            &["--report", "/dev/null"],
            "--report: /dev/null: is a character device",
        ),
        (
            &["--report", "fifo.json"],
            "--report: fifo.json: is a FIFO (named pipe)",
        ),
        (
            &["--report", "to-fifo.json"],
            "--report: to-fifo.json: is a FIFO",
        ),
        // Under Command::output, the run's stdout and stderr are pipes.
        (
            &["--report", "/proc/self/fd/1"],
            "--report: /proc/self/fd/1: is a FIFO",
        ),
        (
            &["--report", "/proc/self/fd/2"],
            "--report: /proc/self/fd/2: is a FIFO",
        ),
        (
            &["--out", "null.obj"],
            "--out: null.obj: is a character device",
        ),
        (
            &["--out", "sq.obj"],
            "--out `sq.obj` names the input file of MESH",
        ),
        (
            &["--out", "to-input.obj"],
            "--out `to-input.obj` names the input file of MESH",
        ),
        (
            &["--out", "hard.obj"],
            "--out `hard.obj` names the input file of MESH",
        ),
        (
            &["--report", "s.json"],
            "--report `s.json` names the input file of --supports",
        ),
    ];
    for (extra, message) in cases {
        let mut args = vec!["sq.obj", "--supports", "s.json", "--stress-only"];
        args.extend(extra);
        refused(&files, output_fixtures, &args, &[message]);
    }
    for device in ["/dev/full", "/dev/null"] {
        assert!(
            !fs::metadata(device).unwrap().is_file(),
            "{device} was replaced"
        );
    }
    // The solid's output and the embedded input's copies are checked as well.
    refused(
        &files,
        output_fixtures,
        &[
            "sq.obj",
            "--supports",
            "s.json",
            "--stress-only",
            "--solid",
            "0.01",
            "sq.obj",
        ],
        &["--solid `sq.obj` names the input file of MESH"],
    );
}

#[cfg(unix)]
#[test]
fn outputs_are_written_through_symbolic_links() {
    use std::os::unix::fs::symlink;
    let dir = Scratch::new("through-links");
    fs::write(dir.path("sq.obj"), SQUARE).unwrap();
    fs::write(dir.path("s.json"), SUPPORTS).unwrap();
    fs::create_dir(dir.path("elsewhere")).unwrap();
    fs::write(dir.path("elsewhere/real.obj"), "old").unwrap();
    symlink("elsewhere/real.obj", dir.path("o.obj")).unwrap();
    symlink("elsewhere/report.json", dir.path("r.json")).unwrap();
    let out = run(
        &dir.0,
        &[
            "sq.obj",
            "--supports",
            "s.json",
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
    for link in ["o.obj", "r.json"] {
        assert!(
            fs::symlink_metadata(dir.path(link)).unwrap().is_symlink(),
            "{link} replaced"
        );
    }
    let (positions, _) = read_obj(&dir.path("elsewhere/real.obj"));
    assert_eq!(positions.len(), 5);
    assert_eq!(
        read_json(&dir.path("elsewhere/report.json"))["anchored"]
            .as_array()
            .unwrap()
            .len(),
        4
    );
    let hidden: Vec<String> = (dir.listing().into_iter())
        .filter(|n| n.contains(".formfind-"))
        .collect();
    assert!(hidden.is_empty(), "left behind: {hidden:?}");
}

#[test]
fn repeated_options_are_refused_naming_them() {
    let files: [(&str, &[u8]); 2] = [
        ("sq.obj", SQUARE.as_bytes()),
        ("s.json", SUPPORTS.as_bytes()),
    ];
    let base = ["sq.obj", "--supports", "s.json"];
    let cases: [(&[&str], &str); 4] = [
        (
            &["--out", "a.obj", "--out", "b.obj"],
            "--out is given twice; give it once",
        ),
        (&["--tol", "1e-3", "--tol", "1e-9"], "--tol is given twice"),
        (
            &["--stress-only", "--stress-only"],
            "--stress-only is given twice",
        ),
        (
            &["--weld", "1e-3", "--no-weld"],
            "--weld and --no-weld are both given; give one of them",
        ),
    ];
    for (extra, message) in cases {
        let args: Vec<&str> = base.iter().chain(extra).copied().collect();
        refused(&files, |_| {}, &args, &[message]);
    }
    refused(
        &files,
        |_| {},
        &["sq.obj", "--supports", "s.json", "--supports", "s.json"],
        &["--supports is given twice"],
    );
}

#[test]
fn extreme_solid_thicknesses_get_what_fits_or_the_range() {
    let Some(models) = models_dir() else { return };
    let bytes: Vec<Vec<u8>> = ["hex.obj", "hex.json"]
        .iter()
        .map(|n| fs::read(models.join(n)).unwrap())
        .collect();
    let files = [
        ("hex.obj", bytes[0].as_slice()),
        ("hex.json", bytes[1].as_slice()),
    ];
    let run_with = |t: &str, out: &str, message: &str| {
        refused(
            &files,
            |_| {},
            &[
                "hex.obj",
                "--supports",
                "hex.json",
                "--stress-only",
                "--solid",
                t,
                out,
            ],
            &["--solid: ", message],
        );
    };
    for t in ["1e154", "1e200", "1e300"] {
        run_with(
            t,
            "s.obj",
            "the shell's curvature allows at most 8.0941e-2 there",
        );
        run_with(
            t,
            "s.stl",
            "the shell's curvature allows at most 8.0941e-2 there",
        );
    }
    for t in ["1e-20", "1e-300"] {
        run_with(t, "s.obj", "is too small for a solid");
    }
}

#[test]
fn messages_name_the_cause_and_count_in_words() {
    // Welding that merges every face away is the tolerance's fault, not an "empty mesh".
    refused(
        &[(
            "tiny.obj",
            b"v 0 0 0\nv 1e-12 0 0\nv 0 1e-12 0\nv 1000 1000 0\nf 1 2 3\n",
        )],
        |_| {},
        &["tiny.obj", "--anchor-boundary"],
        &[
            "--weld: welding within",
            "every face (1 in all), so no face is left",
        ],
    );
    // A square ring: one hole, and the summary says so in the singular.
    let ring = "v 0 0 0\nv 3 0 0\nv 3 3 0\nv 0 3 0\nv 1 1 1\nv 2 1 1\nv 2 2 1\nv 1 2 1\n\
                f 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n";
    let dir = Scratch::new("one-hole");
    fs::write(dir.path("ring.obj"), ring).unwrap();
    let out = run(&dir.0, &["ring.obj", "--anchor-boundary", "--stress-only"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.contains("8 vertices, 8 faces, 16 edges, 1 hole, 8 anchored"),
        "{stdout}"
    );
}

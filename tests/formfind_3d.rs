//! The `formfind` example's 3-D picture (`shape_3d.svg`): well-formed SVG, one polygon per face
//! and view, faces back to front by depths recomputed here from the written meshes, one scale
//! for both views, colours by height change, back faces darker.

mod formfind_support;

use std::fs;
use std::path::Path;

use formfind_support::views::{dot, match_faces, view_frame, view_polygons, V3};
use formfind_support::xml::{parse_xml, Element};
use formfind_support::*;

/// Mean distance of each face from the viewer (larger is farther).
fn depths(pos: &[V3], faces: &[[usize; 3]]) -> Vec<f64> {
    let [_, _, eye] = view_frame();
    faces
        .iter()
        .map(|f| -f.iter().map(|&v| dot(eye, pos[v])).sum::<f64>() / 3.0)
        .collect()
}

fn assert_back_to_front(order: &[usize], depth: &[f64], view: &str) {
    let span = depth.iter().fold(0.0f64, |m, d| m.max(d.abs()));
    for (k, w) in order.windows(2).enumerate() {
        assert!(
            depth[w[0]] >= depth[w[1]] - 1e-12 * span,
            "{view}: polygon {} (face {}, depth {}) is drawn before the farther face {} (depth {})",
            k,
            w[0],
            depth[w[0]],
            w[1],
            depth[w[1]]
        );
    }
}

/// True when the face, turned counter-clockwise in plan (its top side up), shows its top.
fn shows_top(pos: &[V3], f: [usize; 3]) -> bool {
    let [a, b, c] = f.map(|v| pos[v]);
    let (e1, e2) = (
        [0, 1, 2].map(|k| b[k] - a[k]),
        [0, 1, 2].map(|k| c[k] - a[k]),
    );
    let n = [
        e1[1] * e2[2] - e1[2] * e2[1],
        e1[2] * e2[0] - e1[0] * e2[2],
        e1[0] * e2[1] - e1[1] * e2[0],
    ];
    let [_, _, eye] = view_frame();
    // n[2] is twice the signed plan area: flip clockwise faces.
    n[2].signum() * dot(n, eye) >= 0.0
}

fn run_ok(dir: &Scratch, args: &[&str]) {
    let out = run(&dir.0, args);
    assert!(
        out.status.success(),
        "status {:?}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
}

fn read_picture(path: &Path) -> Vec<Element> {
    let text = fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    parse_xml(&text)
}

/// Checks the 3-D picture of a run on `input` (with the `form-found` mesh `found`), both as
/// written to OBJ; returns the number of faces.
fn check_views(picture: &Path, input: &Path, found: &Path) -> usize {
    let elements = read_picture(picture);
    let (input, faces) = read_obj(input);
    let (found, _) = read_obj(found);
    let mut fits = Vec::new();
    for (id, pos) in [("input-faces", &input), ("form-found-faces", &found)] {
        let drawn = view_polygons(&elements, id);
        assert_eq!(drawn.len(), faces.len(), "{id}: one polygon per face");
        let (order, scale, baseline) = match_faces(&drawn, pos, &faces);
        assert_back_to_front(&order, &depths(pos, &faces), id);
        fits.push((scale, baseline));
    }
    let [(s0, b0), (s1, b1)] = [fits[0], fits[1]];
    assert!((s0 - s1).abs() < 1e-3 * s0, "scales differ: {s0} and {s1}");
    assert!(
        (b0 - b1).abs() < 0.5,
        "the views' heights differ: {b0} and {b1}"
    );
    let polygons = elements.iter().filter(|e| e.name == "polygon").count();
    assert_eq!(polygons, 2 * faces.len(), "no other polygons");
    faces.len()
}

#[test]
fn both_views_draw_every_face_back_to_front_at_one_scale() {
    let dir = Scratch::new("3d-order");
    run_ok(&dir, &[]);
    let od = dir.path("formfind-out");
    check_views(
        &od.join("pictures/shape_3d.svg"),
        &od.join("vault-input.obj"),
        &od.join("vault-formfound.obj"),
    );
}

#[test]
fn a_shared_model_is_drawn_back_to_front() {
    let Some(models) = models_dir() else { return };
    let dir = Scratch::new("3d-three-pillar");
    let (obj, json) = (
        models.join("three_pillar.obj"),
        models.join("three_pillar.json"),
    );
    let args = [
        obj.to_str().unwrap(),
        "--supports",
        json.to_str().unwrap(),
        "--out",
        "o.obj",
    ];
    run_ok(&dir, &args);
    let picture = dir.path("formfind-out/pictures/shape_3d.svg");
    let faces = check_views(&picture, &obj, &dir.path("o.obj"));
    assert_eq!(faces, 642);
}

#[test]
fn colours_follow_the_height_change() {
    let dir = Scratch::new("3d-colours");
    run_ok(&dir, &[]);
    let od = dir.path("formfind-out");
    let elements = read_picture(&od.join("pictures/shape_3d.svg"));
    let (input, faces) = read_obj(&od.join("vault-input.obj"));
    let (found, _) = read_obj(&od.join("vault-formfound.obj"));
    let dz: Vec<f64> = faces
        .iter()
        .map(|f| f.iter().map(|&v| found[v][2] - input[v][2]).sum::<f64>() / 3.0)
        .collect();
    let m = dz.iter().fold(0.0f64, |a, d| a.max(d.abs()));
    assert!(m > 0.0, "form finding moved the default vault");
    for (id, pos) in [("input-faces", &input), ("form-found-faces", &found)] {
        let drawn = view_polygons(&elements, id);
        let (order, _, _) = match_faces(&drawn, pos, &faces);
        let (mut neutral, mut up, mut down) = (0, 0, 0);
        for (d, &t) in drawn.iter().zip(&order) {
            let [r, g, b] = d.rgb.map(i32::from);
            if dz[t] == 0.0 {
                assert!(
                    r == g && g == b,
                    "{id}: unchanged face {t} is not grey: {:?}",
                    d.rgb
                );
                neutral += 1;
            } else if dz[t] > 0.2 * m {
                assert!(r > b, "{id}: raised face {t} is not red: {:?}", d.rgb);
                up += 1;
            } else if dz[t] < -0.2 * m {
                assert!(b > r, "{id}: lowered face {t} is not blue: {:?}", d.rgb);
                down += 1;
            }
        }
        assert!(
            neutral > 0 && up > 0 && down > 0,
            "{id}: {neutral} unchanged, {up} raised, {down} lowered faces checked"
        );
    }
}

#[test]
fn stress_only_draws_the_input_alone_in_grey_with_darker_undersides() {
    let dir = Scratch::new("3d-stress-only");
    run_ok(&dir, &["--stress-only", "--out", "o.obj"]);
    let elements = read_picture(&dir.path("formfind-out/pictures/shape_3d.svg"));
    let (input, faces) = read_obj(&dir.path("vault-input.obj"));
    assert!(view_polygons(&elements, "form-found-faces").is_empty());
    let drawn = view_polygons(&elements, "input-faces");
    assert_eq!(drawn.len(), faces.len(), "one polygon per face");
    let (order, _, _) = match_faces(&drawn, &input, &faces);
    assert_back_to_front(&order, &depths(&input, &faces), "input");
    let (mut top, mut under) = (Vec::new(), Vec::new());
    for (d, &t) in drawn.iter().zip(&order) {
        let [r, g, b] = d.rgb;
        assert!(
            r == g && g == b,
            "face {t} is not grey without form finding"
        );
        if shows_top(&input, faces[t]) {
            top.push(f64::from(r))
        } else {
            under.push(f64::from(r))
        }
    }
    // The default vault's oculi show some of its underside.
    assert!(!under.is_empty() && !top.is_empty());
    let brightest_top = top.iter().copied().fold(0.0, f64::max);
    let brightest_under = under.iter().copied().fold(0.0, f64::max);
    assert!(
        brightest_under < 0.7 * brightest_top,
        "undersides ({brightest_under}) are not darker than tops ({brightest_top})"
    );
}

#[test]
fn help_says_what_the_3d_picture_shows() {
    let dir = Scratch::new("3d-help");
    let out = run(&dir.0, &["--help"]);
    let help = String::from_utf8_lossy(&out.stdout);
    for phrase in ["shape_3d.svg", "−60°", "30°"] {
        assert!(help.contains(phrase), "--help lacks `{phrase}`:\n{help}");
    }
}

#[test]
#[should_panic(expected = "</svg> closes <g>")]
fn the_xml_check_rejects_crossed_tags() {
    parse_xml(r#"<svg><g fill="red"></svg></g>"#);
}

#[test]
#[should_panic(expected = "unclosed elements")]
fn the_xml_check_rejects_an_unclosed_element() {
    parse_xml(r#"<svg><polygon points="0,0 1,0 0,1"/>"#);
}

#[test]
#[should_panic(expected = "unquoted attribute")]
fn the_xml_check_rejects_an_unquoted_attribute() {
    parse_xml("<svg width=3/>");
}

/// A square grid of `n` × `n` cells, two triangles each, over a shallow dome.
fn grid_obj(n: usize) -> String {
    let mut obj = String::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (i as f64 / n as f64, j as f64 / n as f64);
            let z = 0.3 * x * (1.0 - x) * y * (1.0 - y) * 16.0;
            obj += &format!("v {x} {y} {z}\n");
        }
    }
    for j in 0..n {
        for i in 0..n {
            let a = j * (n + 1) + i + 1;
            let (b, c, d) = (a + 1, a + n + 2, a + n + 1);
            obj += &format!("f {a} {b} {c}\nf {a} {c} {d}\n");
        }
    }
    obj
}

#[test]
fn the_3d_picture_takes_under_80_bytes_a_face() {
    let dir = Scratch::new("3d-compact");
    fs::write(dir.path("grid.obj"), grid_obj(60)).unwrap();
    let args = ["grid.obj", "--anchor-boundary", "--stress-only"];
    run_ok(&dir, &args);
    let picture = dir.path("formfind-out/pictures/shape_3d.svg");
    let bytes = fs::metadata(&picture).unwrap().len() as f64;
    let faces = 2 * 60 * 60;
    assert_eq!(
        view_polygons(&read_picture(&picture), "input-faces").len(),
        faces
    );
    // The points to a tenth of a pixel and one colour: about 70 bytes a face.
    let per_face = bytes / faces as f64;
    assert!(per_face < 80.0, "{per_face:.1} bytes per face");
}

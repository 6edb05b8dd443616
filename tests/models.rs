//! The nine real vault models of ../shared/data/models: counts against the README table and
//! a summary of their boundaries and supports. Skipped when the folder is absent, except in CI
//! or with VSR_REQUIRE_MODELS=1, where its absence fails.

mod common;
use common::{find_models, models_dir, models_required};
use voussoir::{io, Mesh};

/// (name, V, E, F) from the models README.
const MODELS: [(&str, usize, usize, usize); 9] = [
    ("free_vault", 360, 1000, 640),
    ("dome_with_doors", 577, 1600, 1024),
    ("lilium", 1201, 3504, 2304),
    ("cheese", 2348, 6218, 3832),
    ("four_holes", 749, 2146, 1394),
    ("neumunster", 325, 900, 576),
    ("hex", 648, 1800, 1152),
    ("three_pillar", 361, 1005, 642),
    ("vault_pq", 343, 938, 596),
];

fn load(dir: &std::path::Path, name: &str) -> Mesh {
    let obj = dir.join(format!("{name}.obj"));
    let json = dir.join(format!("{name}.json"));
    io::load_model(&obj, &json)
        .unwrap_or_else(|e| panic!("{name}: {e}"))
        .mesh
}

#[test]
fn models_load_with_expected_counts() {
    let Some(dir) = models_dir() else { return };
    println!(
        "{:<16} {:>5} {:>5} {:>5} {:>3} {:>5} {:>5} {:>8} {:>8} {:>9} {:>8} {:>6}",
        "model",
        "V",
        "E",
        "F",
        "rev",
        "loops",
        "holes",
        "anchored",
        "interior",
        "on holes",
        "free bd",
        "unref"
    );
    for (name, v, e, f) in MODELS {
        let mesh = load(&dir, name);
        assert_eq!(
            (mesh.n_vertices(), mesh.edges().len(), mesh.faces().len()),
            (v, e, f),
            "{name}: V/E/F"
        );
        let n = mesh.n_vertices();
        // Anchored and referenced: hex.json also anchors its two unreferenced vertices.
        let anchored = (0..n)
            .filter(|&i| mesh.anchored()[i] && mesh.referenced()[i])
            .count();
        let interior_anchored = (0..n)
            .filter(|&i| mesh.anchored()[i] && mesh.referenced()[i] && !mesh.on_boundary()[i])
            .count();
        let on_holes: usize = mesh
            .holes()
            .map(|h| {
                let vertices = &mesh.loops()[h].vertices;
                vertices
                    .iter()
                    .filter(|&&i| mesh.anchored()[i as usize])
                    .count()
            })
            .sum();
        for l in mesh.loops() {
            assert_eq!(l.is_outer, l.signed_area > 0.0, "{name}: loop orientation");
        }
        let free = (0..n).filter(|&i| mesh.is_free_boundary(i)).count();
        println!(
            "{:<16} {:>5} {:>5} {:>5} {:>3} {:>5} {:>5} {:>8} {:>8} {:>9} {:>8} {:>6}",
            name,
            n,
            mesh.edges().len(),
            mesh.faces().len(),
            if mesh.reversed() { "yes" } else { "no" },
            mesh.loops().len(),
            mesh.holes().count(),
            anchored,
            interior_anchored,
            on_holes,
            free,
            mesh.unreferenced().len()
        );
        if name == "hex" {
            assert_eq!(mesh.unreferenced().len(), 2, "hex: unreferenced vertices");
            assert!(mesh
                .unreferenced()
                .iter()
                .all(|&i| !mesh.is_non_anchored(i as usize)));
        }
    }
}

#[test]
fn models_are_required_in_ci_and_on_request_only() {
    assert!(!models_required(None, None));
    for ci in ["true", "1", "yes", "TRUE"] {
        assert!(models_required(Some(ci), None), "CI={ci}");
    }
    for ci in ["", "0", "false", "False"] {
        assert!(!models_required(Some(ci), None), "CI={ci:?}");
    }
    assert!(models_required(None, Some("1")));
    assert!(!models_required(None, Some("0")));
    assert!(!models_required(None, Some("")));
}

#[test]
fn a_missing_models_folder_is_skipped_unless_required() {
    let absent = std::env::temp_dir().join("voussoir-no-such-models-folder");
    assert_eq!(find_models(absent.clone(), false), None);
    let failed = std::panic::catch_unwind(|| find_models(absent, true));
    assert!(
        failed.is_err(),
        "an absent, required folder must fail the test"
    );
    let present = std::env::temp_dir();
    assert_eq!(find_models(present.clone(), true), Some(present));
}

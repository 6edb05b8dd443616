//! One set of defaults: Rust's `analyse` with `StressSettings::default()` and C's
//! `vsr_analyse` with the settings of `vsr_settings_create` give the same answer, bit for bit.

mod capi_support;
mod common;

use capi_support::{assert_ok, doubles, settings, Dome};
use common::{holed_disk, load_model};
use std::ptr::null_mut;
use voussoir::capi::*;
use voussoir::*;

/// Force densities, residuals and hole coefficients of `mesh` analysed through the C API with
/// default settings.
fn analysed_through_c(mesh: &Mesh) -> [Vec<f64>; 3] {
    let anchored = (0..mesh.positions().len() as u32)
        .filter(|&v| mesh.anchored()[v as usize])
        .collect();
    let flat = Dome {
        positions: mesh.positions().iter().flatten().copied().collect(),
        triangles: mesh.faces().iter().flatten().copied().collect(),
        anchored,
    };
    let (c_mesh, s) = (flat.create(), settings());
    let mut r = null_mut();
    assert_ok(unsafe { vsr_analyse(c_mesh, s, &mut r) });
    let out = [
        doubles(r, vsr_result_force_densities),
        doubles(r, vsr_result_residuals),
        doubles(r, vsr_result_hole_coefficients),
    ];
    unsafe {
        vsr_result_destroy(r);
        vsr_settings_destroy(s);
        vsr_mesh_destroy(c_mesh);
    }
    out
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

#[test]
fn rust_and_c_analyse_alike_with_default_settings() {
    assert_eq!(
        FormFindSettings::default().stress,
        StressSettings::default()
    );
    // A free rim arc (τ, q_min on boundary edges) around an anchored hole.
    let mut meshes = vec![(
        "holed disk".to_string(),
        holed_disk(5, 0.01, |u, outer| {
            (outer && u[1] < 0.2) || (u[0] - 0.3).hypot(u[1] - 0.1) < 0.26
        }),
    )];
    if let Some(mesh) = load_model("four_holes") {
        meshes.push(("four_holes".to_string(), mesh));
    }
    for (label, mesh) in meshes {
        let [q, residuals, holes] = analysed_through_c(&mesh);
        let rust = analyse(&Problem::new(mesh), &StressSettings::default()).unwrap();
        assert!(rust.status.is_solved(), "{label}: {:?}", rust.status);
        assert_eq!(bits(&q), bits(&rust.force_densities), "{label}");
        assert_eq!(bits(&residuals), bits(&rust.residuals), "{label}");
        let rust_holes: Vec<f64> = rust.hole_coefficients.iter().flatten().copied().collect();
        assert_eq!(bits(&holes), bits(&rust_holes), "{label}");
        assert!(!rust_holes.is_empty(), "{label} has holes");
    }
}

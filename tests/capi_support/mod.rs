//! Shared by the C ABI tests: a small dome as flat arrays, and checked wrappers.
#![allow(dead_code)]

use std::ffi::CStr;
use voussoir::capi::*;

/// A spherical cap of 60° over the unit disk as flat arrays: a centre vertex and `rings`
/// rings of `segments` vertices, the outer ring anchored.
pub struct Dome {
    pub positions: Vec<f64>,
    pub triangles: Vec<u32>,
    pub anchored: Vec<u32>,
}

impl Dome {
    pub fn new(rings: u32, segments: u32) -> Dome {
        let angle = 60f64.to_radians();
        let sphere = 1.0 / angle.sin();
        let height = |r: f64| (sphere * sphere - r * r).sqrt() - sphere * angle.cos();
        let mut positions = vec![0.0, 0.0, height(0.0)];
        for k in 1..=rings {
            let r = f64::from(k) / f64::from(rings);
            for m in 0..segments {
                // Odd rings are turned by half a step: triangles zig-zag between rings.
                let step = f64::from(m) + 0.5 * f64::from(k % 2);
                let a = std::f64::consts::TAU * step / f64::from(segments);
                positions.extend([r * a.cos(), r * a.sin(), height(r)]);
            }
        }
        let id = |k: u32, m: u32| 1 + (k - 1) * segments + m % segments;
        let mut triangles = Vec::new();
        for m in 0..segments {
            triangles.push([0, id(1, m), id(1, m + 1)]);
        }
        for k in 1..rings {
            for m in 0..segments {
                let (a0, a1, b0, b1) = (id(k, m), id(k, m + 1), id(k + 1, m), id(k + 1, m + 1));
                if k % 2 == 1 {
                    // Inner vertex a0 lies between outer b0 and b1.
                    triangles.push([b0, b1, a0]);
                    triangles.push([a0, b1, a1]);
                } else {
                    // Outer vertex b0 lies between inner a0 and a1.
                    triangles.push([a0, b0, a1]);
                    triangles.push([a1, b0, b1]);
                }
            }
        }
        // Counter-clockwise in plan.
        let p = |v: u32| [positions[3 * v as usize], positions[3 * v as usize + 1]];
        for t in &mut triangles {
            let [a, b, c] = t.map(p);
            if (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) < 0.0 {
                t.swap(1, 2);
            }
        }
        let anchored = (0..segments).map(|m| id(rings, m)).collect();
        Dome {
            positions,
            triangles: triangles.into_iter().flatten().collect(),
            anchored,
        }
    }

    pub fn n_vertices(&self) -> usize {
        self.positions.len() / 3
    }

    pub fn n_triangles(&self) -> usize {
        self.triangles.len() / 3
    }

    pub fn create(&self) -> *mut VsrMesh {
        let mut mesh = std::ptr::null_mut();
        let status = unsafe {
            vsr_mesh_create(
                self.positions.as_ptr(),
                self.n_vertices(),
                self.triangles.as_ptr(),
                self.n_triangles(),
                self.anchored.as_ptr(),
                self.anchored.len(),
                &mut mesh,
            )
        };
        assert_eq!(status, VsrStatus::Ok, "{}", last_error());
        mesh
    }
}

pub fn last_error() -> String {
    unsafe { CStr::from_ptr(vsr_last_error_message()) }
        .to_str()
        .unwrap()
        .to_string()
}

/// Asserts a failed call: its status, and a one-line message that names `argument`.
#[track_caller]
pub fn assert_failed(status: VsrStatus, expected: VsrStatus, argument: &str) {
    let message = last_error();
    assert_eq!(status, expected, "message: {message}");
    assert!(
        message.contains(&format!("`{argument}`")),
        "message does not name `{argument}`: {message}"
    );
    assert!(
        !message.contains('\n'),
        "message is not one line: {message}"
    );
}

/// Asserts success and an empty last error.
#[track_caller]
pub fn assert_ok(status: VsrStatus) {
    assert_eq!(status, VsrStatus::Ok, "message: {}", last_error());
    assert_eq!(last_error(), "");
}

pub fn settings() -> *mut VsrSettings {
    let mut s = std::ptr::null_mut();
    assert_ok(unsafe { vsr_settings_create(&mut s) });
    s
}

/// Copies a double array out of a result with a size query first.
pub fn doubles(
    result: *const VsrResult,
    get: unsafe extern "C" fn(*const VsrResult, *mut f64, usize, *mut usize) -> VsrStatus,
) -> Vec<f64> {
    let mut n = usize::MAX;
    assert_ok(unsafe { get(result, std::ptr::null_mut(), 0, &mut n) });
    let mut v = vec![f64::NAN; n];
    let mut m = 0;
    assert_ok(unsafe { get(result, v.as_mut_ptr(), v.len(), &mut m) });
    assert_eq!(m, n);
    v
}

/// Everything a result reports, for comparing runs bit for bit.
#[derive(Debug, PartialEq)]
pub struct Snapshot {
    pub arrays: Vec<Vec<u64>>,
    pub termination: Option<(VsrTermination, usize)>,
}

pub fn snapshot(result: *const VsrResult) -> Snapshot {
    let getters: [unsafe extern "C" fn(*const VsrResult, *mut f64, usize, *mut usize) -> VsrStatus;
        11] = [
        vsr_result_positions,
        vsr_result_force_densities,
        vsr_result_airy,
        vsr_result_weights,
        vsr_result_tau,
        vsr_result_external_horizontal,
        vsr_result_loads,
        vsr_result_residuals,
        vsr_result_horizontal_imbalance,
        vsr_result_force_diagram_centres,
        vsr_result_force_diagram_segments,
    ];
    let arrays = getters
        .iter()
        .map(|g| doubles(result, *g).iter().map(|x| x.to_bits()).collect())
        .collect();
    let mut kind = VsrResultKind::Analysis;
    assert_ok(unsafe { vsr_result_kind(result, &mut kind) });
    let termination = (kind == VsrResultKind::FormFinding).then(|| {
        let (mut t, mut i) = (VsrTermination::Cancelled, 0);
        assert_ok(unsafe { vsr_result_termination(result, &mut t, &mut i) });
        (t, i)
    });
    Snapshot {
        arrays,
        termination,
    }
}

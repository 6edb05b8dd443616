//! Solves through the C ABI in parallel threads give results identical (bit for bit) to the
//! same solves run one after another: on separate handles, and on shared `const` handles.

mod capi_support;

use capi_support::{assert_ok, settings, snapshot, Dome, Snapshot};
use std::ptr::null_mut;
use voussoir::capi::*;

/// One solve: which entry point, which formulation, how flat the input is.
#[derive(Clone, Copy)]
struct Case {
    form_find: bool,
    formulation: VsrFormulation,
    flatten: f64,
}

const CASES: [Case; 4] = [
    Case {
        form_find: false,
        formulation: VsrFormulation::Reduced,
        flatten: 1.0,
    },
    Case {
        form_find: false,
        formulation: VsrFormulation::EdgeBased,
        flatten: 0.5,
    },
    Case {
        form_find: true,
        formulation: VsrFormulation::Reduced,
        flatten: 0.3,
    },
    Case {
        form_find: true,
        formulation: VsrFormulation::EdgeBased,
        flatten: 0.3,
    },
];

fn mesh_for(case: Case) -> *mut VsrMesh {
    let mut d = Dome::new(5, 12);
    d.positions
        .iter_mut()
        .skip(2)
        .step_by(3)
        .for_each(|z| *z *= case.flatten);
    d.create()
}

fn settings_for(case: Case) -> *mut VsrSettings {
    let s = settings();
    assert_ok(unsafe { vsr_settings_set_formulation(s, case.formulation as u32) });
    assert_ok(unsafe { vsr_settings_set_max_iterations(s, 12) });
    s
}

fn solve(mesh: *const VsrMesh, s: *const VsrSettings, form_find: bool) -> Snapshot {
    let mut r = null_mut();
    let status = unsafe {
        if form_find {
            vsr_form_find(mesh, s, &mut r)
        } else {
            vsr_analyse(mesh, s, &mut r)
        }
    };
    assert_ok(status);
    let snap = snapshot(r);
    unsafe { vsr_result_destroy(r) };
    snap
}

/// Creates its own handles, solves, frees them.
fn run(case: Case) -> Snapshot {
    let (mesh, s) = (mesh_for(case), settings_for(case));
    let snap = solve(mesh, s, case.form_find);
    unsafe {
        vsr_settings_destroy(s);
        vsr_mesh_destroy(mesh);
    }
    snap
}

#[test]
fn parallel_solves_on_separate_handles_equal_sequential_ones() {
    let sequential: Vec<Snapshot> = CASES.iter().map(|&c| run(c)).collect();
    for _round in 0..2 {
        let parallel: Vec<Snapshot> = std::thread::scope(|scope| {
            let handles: Vec<_> = CASES.iter().map(|&c| scope.spawn(move || run(c))).collect();
            handles.into_iter().map(|h| h.join().unwrap()).collect()
        });
        assert_eq!(parallel, sequential);
    }
    // The form-finding cases did iterate.
    assert!(sequential[2].termination.unwrap().1 > 1);
}

/// Raw handles shared read-only across threads.
#[derive(Clone, Copy)]
struct Shared(*const VsrMesh, *const VsrSettings);
// SAFETY: the header allows concurrent use of `const` handles.
unsafe impl Send for Shared {}
unsafe impl Sync for Shared {}

#[test]
fn parallel_solves_on_shared_const_handles_equal_sequential_ones() {
    let case = CASES[2];
    let (mesh, s) = (mesh_for(case), settings_for(case));
    let shared = Shared(mesh, s);
    let sequential = solve(mesh, s, true);
    let parallel: Vec<Snapshot> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..4)
            .map(|_| {
                scope.spawn(move || {
                    let shared = shared;
                    solve(shared.0, shared.1, true)
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for p in parallel {
        assert_eq!(p, sequential);
    }
    unsafe {
        vsr_settings_destroy(s);
        vsr_mesh_destroy(mesh);
    }
}

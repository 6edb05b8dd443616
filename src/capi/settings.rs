//! `VsrSettings`: the options of both solves, with one validating setter per option.
//!
//! Defaults are those of the Rust [`FormFindSettings::default`]; every setter converts its
//! arguments (enums, +INFINITY for "no bound") and leaves the range checks to
//! [`FormFindSettings::validate`], through `update`, before it changes anything.
//!
//! Every option of [`FormFindSettings`] and its [`crate::StressSettings`] has a setter here.
//! When an option is added to the Rust settings, add its `vsr_settings_set_*` function (see
//! ARCHITECTURE.md, "Adding a setting") and a row in the defaults table of
//! `vsr_settings_create`, then rewrite the header (`VSR_BLESS=1 cargo test --test
//! capi_header`).

use super::boundary::{boundary, free, give, handle_mut, CResult, Failure};
use super::enum_args;
use super::status::VsrStatus;
use crate::stress::QBound;
use crate::FormFindSettings;
use std::ffi::{c_int, c_void};

/// Progress callback of `vsr_form_find`, called once per iteration after its stress step with
/// the 0-based iteration number and the ε∞ the loop goes on with (max |r_i| / mean load,
/// dimensionless): that step's, or the previous forces' when the step is not taken (see
/// `vsr_result_eps_history`).
/// Return 0 to continue, non-zero to cancel (the result then reports
/// `VSR_TERMINATION_CANCELLED` and holds the state reached). It runs on the thread that called
/// `vsr_form_find`; it must not unwind (throw a C++ exception or longjmp) out of the call, and
/// must not destroy the handles in use.
pub type VsrProgressFn =
    Option<unsafe extern "C" fn(user: *mut c_void, iteration: usize, eps_inf: f64) -> c_int>;

/// A progress callback with the `user` pointer passed back to it, as both settings handles
/// (`VsrSettings`, `VsrAssessSettings`) hold it.
#[derive(Clone, Copy)]
pub(crate) struct Progress {
    callback: VsrProgressFn,
    user: *mut c_void,
}

impl Default for Progress {
    fn default() -> Progress {
        Progress {
            callback: None,
            user: std::ptr::null_mut(),
        }
    }
}

impl Progress {
    /// Runs `solve` with the callback as the library's progress function (`None` without
    /// one): a non-zero return of the callback cancels.
    pub(crate) fn run<R>(self, solve: impl FnOnce(Option<&mut crate::Progress>) -> R) -> R {
        match self.callback {
            Some(cb) => {
                let user = self.user;
                let mut progress = |k: usize, value: f64| {
                    // SAFETY: the callback and `user` are valid for this call (caller's
                    // contract); C code does not unwind into Rust.
                    unsafe { cb(user, k, value) == 0 }
                };
                solve(Some(&mut progress))
            }
            None => solve(None),
        }
    }

    /// Stores `callback` and `user` in the `progress` of the settings handle `settings`
    /// (`callback` NULL removes both): the body of both `_set_progress` functions.
    ///
    /// # Safety
    /// `settings`: NULL or a valid handle with exclusive access.
    pub(crate) unsafe fn set<H>(
        settings: *mut H,
        progress: impl FnOnce(&mut H) -> &mut Progress,
        callback: VsrProgressFn,
        user: *mut c_void,
    ) -> CResult {
        // SAFETY: caller's contract.
        let s = unsafe { handle_mut("settings", settings)? };
        *progress(s) = Progress {
            callback,
            user: if callback.is_some() {
                user
            } else {
                std::ptr::null_mut()
            },
        };
        Ok(())
    }
}

/// Opaque handle: solver options. Create with `vsr_settings_create` (defaults documented
/// there), change with the `vsr_settings_set_*` functions, free with `vsr_settings_destroy`.
pub struct VsrSettings {
    pub(crate) form: FormFindSettings,
    pub(crate) progress: Progress,
}

/// Creates settings with the documented defaults (those of the Rust `FormFindSettings`, whose
/// stress settings are the Rust `StressSettings` defaults):
///
/// | option | default |
/// |---|---|
/// | method | `VSR_METHOD_NEAREST` |
/// | fairness γ (nearest method) | 0.03 |
/// | max height change | 1 plan diagonal |
/// | tolerance (on ε∞) | 1e-6 |
/// | max iterations (stress steps) | 100 |
/// | stall window | 8 iterations |
/// | q_min | 0.05, `VSR_BOUND_KIND_RELATIVE` (× p̄ / L₀), scope `VSR_EDGE_SCOPE_ALL` |
/// | q_max | none (+INFINITY) |
/// | τ mode | `VSR_TAU_MODE_OPTIMIZED` |
/// | hole mode | `VSR_HOLE_MODE_AFFINE` |
/// | load rule | `VSR_LOAD_RULE_BARYCENTRIC` |
/// | formulation | `VSR_FORMULATION_REDUCED` |
/// | QP solver | `VSR_QP_SOLVER_NATIVE` |
/// | regularisation ε | 1e-16 |
/// | dual edge length bounds | none |
/// | schedule μ₀, β, μ_min, η, pull ν (paper method) | 1, 0.25, 1e-9, 1e-3, 0 |
/// | proximal weight | 1e-6 |
/// | ODT sweeps, ODT moves free boundary | 0 (plan never moves), 0 (no) |
/// | progress callback | none |
///
/// `vsr_analyse` uses the same settings, so it gives the answer of the Rust `analyse` with
/// default settings (q_min 0.05 relative by default; set q_min to 0 for plain compression).
/// `out` receives a handle owned by the caller (free with `vsr_settings_destroy`); untouched
/// on failure.
///
/// # Safety
/// `out` must be writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_settings_create(out: *mut *mut VsrSettings) -> VsrStatus {
    boundary!({
        let handle = VsrSettings {
            form: FormFindSettings::default(),
            progress: Progress::default(),
        };
        // SAFETY: forwarded caller's contract.
        unsafe { give(out, handle) }
    })
}

/// Frees settings. NULL is a no-op. Results do not refer to their settings.
///
/// # Safety
/// `settings` must be NULL or a handle from `vsr_settings_create` not yet destroyed, used by
/// no other thread.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_settings_destroy(settings: *mut VsrSettings) {
    // SAFETY: forwarded caller's contract.
    boundary!(keep_error, (), { unsafe { free(settings) } })
}

/// Applies `f` to a copy of the settings, validates the copy with the library's
/// [`FormFindSettings::validate`] (the one set of range checks), and stores it on success.
/// `args` maps the settings' field names to the setter's argument names (see [`rejected`]).
unsafe fn update(
    settings: *mut VsrSettings,
    args: &[(&str, &str)],
    f: impl FnOnce(&mut FormFindSettings),
) -> CResult {
    // SAFETY: forwarded caller's contract.
    unsafe {
        validated(
            settings,
            |h| &mut h.form,
            FormFindSettings::validate,
            args,
            f,
        )
    }
}

/// The body of every settings setter of both handles: applies `f` to a copy of the settings
/// `slot` picks in the handle `settings`, checks the copy with the library's `validate`, and
/// stores it on success (a failure is [`rejected`], naming the setter's argument by `args`).
///
/// # Safety
/// `settings`: NULL or a valid handle with exclusive access.
pub(crate) unsafe fn validated<H, S: Clone>(
    settings: *mut H,
    slot: impl FnOnce(&mut H) -> &mut S,
    validate: fn(&S) -> crate::Result<()>,
    args: &[(&str, &str)],
    f: impl FnOnce(&mut S),
) -> CResult {
    // SAFETY: caller's contract (valid handle, exclusive access).
    let stored = slot(unsafe { handle_mut("settings", settings)? });
    let mut copy = stored.clone();
    f(&mut copy);
    validate(&copy).map_err(|e| rejected(e, args))?;
    *stored = copy;
    Ok(())
}

/// A setter's failure from the library's validation of the settings (the reason as the
/// library words it; `VSR_STATUS_NON_FINITE` for NaN and infinities): `args` maps the
/// settings' field names to the setter's argument names, which the message names; a field
/// outside it, or a relation between two settings (q_max below q_min), keeps the setting's
/// own name.
fn rejected(e: crate::Error, args: &[(&str, &str)]) -> Failure {
    let relation = crate::validate::is_relation(&e);
    let status = if crate::validate::is_not_finite(&e) {
        VsrStatus::NonFinite
    } else {
        VsrStatus::InvalidArgument
    };
    match e {
        crate::Error::InvalidArgument { name, reason } => {
            let field = |a: &&(&str, &str)| a.0 == name && !relation;
            let arg = args.iter().find(field).map_or(name, |a| a.1);
            Failure::new(status, format!("argument `{arg}`: {reason}"))
        }
        e => Failure::invalid("settings", e),
    }
}

/// Sets the convergence tolerance on ε∞ = max |r_i| / mean p_i (dimensionless): form
/// finding stops when ε∞ < tolerance. Finite and > 0. Default 1e-6.
///
/// # Safety
/// `settings`: a valid handle with exclusive access.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_settings_set_tolerance(
    settings: *mut VsrSettings,
    tolerance: f64,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe { update(settings, &[], |f| f.tolerance = tolerance) }
    })
}

/// Sets the maximum number of form-finding iterations (stress steps), >= 1. Default 100.
///
/// # Safety
/// `settings`: a valid handle with exclusive access.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_settings_set_max_iterations(
    settings: *mut VsrSettings,
    max_iterations: usize,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe { update(settings, &[], |f| f.max_iterations = max_iterations) }
    })
}

/// Sets the stall window: form finding stops as stalled when the best ε∞ has not improved by
/// 1% over this many iterations. >= 1. Default 8.
///
/// # Safety
/// `settings`: a valid handle with exclusive access.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_settings_set_stall_window(
    settings: *mut VsrSettings,
    iterations: usize,
) -> VsrStatus {
    boundary!({
        let args = [("stall_window", "iterations")];
        // SAFETY: forwarded caller's contract.
        unsafe { update(settings, &args, |f| f.stall_window = iterations) }
    })
}

/// Sets the lower bound q_min on force densities. `kind` is a `VsrBoundKind`:
/// `VSR_BOUND_KIND_ABSOLUTE` (force per length) or `VSR_BOUND_KIND_RELATIVE` (× p̄ / L₀).
/// `value` finite and >= 0, and <= q_max when both have the same kind. Default 0.05 relative
/// (0 gives plain compression).
///
/// # Safety
/// `settings`: a valid handle with exclusive access.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_settings_set_q_min(
    settings: *mut VsrSettings,
    value: f64,
    kind: u32,
) -> VsrStatus {
    boundary!({
        let relative = enum_args::bound_kind("kind", kind)?;
        let bound = if relative {
            QBound::Relative(value)
        } else {
            QBound::Absolute(value)
        };
        // SAFETY: forwarded caller's contract.
        unsafe { update(settings, &[("q_min", "value")], |f| f.stress.q_min = bound) }
    })
}

/// Sets which edges q_min applies to: a `VsrEdgeScope`, `VSR_EDGE_SCOPE_ALL` (default: a free
/// corner with only boundary edges could otherwise reach q = 0 and never balance) or
/// `VSR_EDGE_SCOPE_INTERIOR`.
///
/// # Safety
/// `settings`: a valid handle with exclusive access.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_settings_set_q_min_scope(
    settings: *mut VsrSettings,
    scope: u32,
) -> VsrStatus {
    boundary!({
        let scope = enum_args::edge_scope("scope", scope)?;
        // SAFETY: forwarded caller's contract.
        unsafe { update(settings, &[], |f| f.stress.q_min_scope = scope) }
    })
}

/// Sets the upper bound q_max on force densities (allowable stress × thickness). `kind` is a
/// `VsrBoundKind` as for q_min. `value` > 0 and >= q_min when both have the same kind;
/// +INFINITY removes the bound. Default: no bound.
///
/// # Safety
/// `settings`: a valid handle with exclusive access.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_settings_set_q_max(
    settings: *mut VsrSettings,
    value: f64,
    kind: u32,
) -> VsrStatus {
    boundary!({
        let relative = enum_args::bound_kind("kind", kind)?;
        let bound = if value == f64::INFINITY {
            None
        } else if relative {
            Some(QBound::Relative(value))
        } else {
            Some(QBound::Absolute(value))
        };
        // SAFETY: forwarded caller's contract.
        unsafe { update(settings, &[("q_max", "value")], |f| f.stress.q_max = bound) }
    })
}

/// Sets the normal stress at free boundary vertices: a `VsrTauMode`. Default
/// `VSR_TAU_MODE_OPTIMIZED`.
///
/// # Safety
/// `settings`: a valid handle with exclusive access.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_settings_set_tau_mode(
    settings: *mut VsrSettings,
    mode: u32,
) -> VsrStatus {
    boundary!({
        let mode = enum_args::tau_mode("mode", mode)?;
        // SAFETY: forwarded caller's contract.
        unsafe { update(settings, &[], |f| f.stress.tau = mode) }
    })
}

/// Sets how holes carry stress: a `VsrHoleMode`. Default `VSR_HOLE_MODE_AFFINE` (the true
/// optimum); `VSR_HOLE_MODE_CONSTANT` is the paper's hole-induced stress.
///
/// # Safety
/// `settings`: a valid handle with exclusive access.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_settings_set_hole_mode(
    settings: *mut VsrSettings,
    mode: u32,
) -> VsrStatus {
    boundary!({
        let mode = enum_args::hole_mode("mode", mode)?;
        // SAFETY: forwarded caller's contract.
        unsafe { update(settings, &[], |f| f.stress.holes = mode) }
    })
}

/// Sets how form finding moves the shape: a `VsrMethod`. Default `VSR_METHOD_NEAREST`.
///
/// # Safety
/// `settings`: a valid handle with exclusive access.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_settings_set_method(
    settings: *mut VsrSettings,
    method: u32,
) -> VsrStatus {
    boundary!({
        let method = enum_args::method("method", method)?;
        // SAFETY: forwarded caller's contract.
        unsafe { update(settings, &[], |f| f.method = method) }
    })
}

/// Sets γ, the weight of the fairness term γ Σ_e c_e (Δz_i − Δz_j)² on the height change of
/// the nearest method, relative to the area-weighted squared change (dimensionless; c_e is the
/// plan area beside edge e over its squared length). Finite and >= 0; 0 turns it off. Default
/// 0.03.
///
/// # Safety
/// `settings`: a valid handle with exclusive access.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_settings_set_fairness(
    settings: *mut VsrSettings,
    gamma: f64,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe { update(settings, &[("fairness", "gamma")], |f| f.fairness = gamma) }
    })
}

/// Sets the largest height change form finding may make at any vertex (either method), in
/// plan bounding-box diagonals. Finite and > 0. Default 1. A run that reaches no state in
/// equilibrium within it ends `VSR_TERMINATION_BLOCKED`.
///
/// # Safety
/// `settings`: a valid handle with exclusive access.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_settings_set_max_height_change(
    settings: *mut VsrSettings,
    diagonals: f64,
) -> VsrStatus {
    boundary!({
        let args = [("max_height_change", "diagonals")];
        // SAFETY: forwarded caller's contract.
        unsafe { update(settings, &args, |f| f.max_height_change = diagonals) }
    })
}

/// Sets how face weights become vertex loads: a `VsrLoadRule`. Default
/// `VSR_LOAD_RULE_BARYCENTRIC`.
///
/// # Safety
/// `settings`: a valid handle with exclusive access.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_settings_set_load_rule(
    settings: *mut VsrSettings,
    rule: u32,
) -> VsrStatus {
    boundary!({
        let rule = enum_args::load_rule("rule", rule)?;
        // SAFETY: forwarded caller's contract.
        unsafe { update(settings, &[], |f| f.stress.load_rule = rule) }
    })
}

/// Sets the stress formulation of both solves: a `VsrFormulation`. Default
/// `VSR_FORMULATION_REDUCED`; `VSR_FORMULATION_EDGE_BASED` is the reference solver.
///
/// # Safety
/// `settings`: a valid handle with exclusive access.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_settings_set_formulation(
    settings: *mut VsrSettings,
    formulation: u32,
) -> VsrStatus {
    boundary!({
        let formulation = enum_args::formulation("formulation", formulation)?;
        // SAFETY: forwarded caller's contract.
        unsafe { update(settings, &[], |f| f.stress.formulation = formulation) }
    })
}

/// Sets the solver of the stress QP of both solves: a `VsrQpSolver`. Default
/// `VSR_QP_SOLVER_NATIVE` (the structured interior-point method, falling back to clarabel when
/// it does not converge); `VSR_QP_SOLVER_CLARABEL` is the reference.
///
/// # Safety
/// `settings`: a valid handle with exclusive access.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_settings_set_qp_solver(
    settings: *mut VsrSettings,
    solver: u32,
) -> VsrStatus {
    boundary!({
        let solver = enum_args::qp_solver("solver", solver)?;
        // SAFETY: forwarded caller's contract.
        unsafe { update(settings, &[], |f| f.stress.solver = solver) }
    })
}

/// Sets ε of the regulariser ε Σ (l_e q_e)² (dimensionless, in the solver's frame) that makes
/// the force densities unique. Finite and >= 0. Default 1e-16; the solver retries with ε × 100
/// (twice at most) after a numerical failure and reports the ε used.
///
/// # Safety
/// `settings`: a valid handle with exclusive access.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_settings_set_regularisation(
    settings: *mut VsrSettings,
    epsilon: f64,
) -> VsrStatus {
    boundary!({
        let args = [("regularisation", "epsilon")];
        // SAFETY: forwarded caller's contract.
        unsafe { update(settings, &args, |f| f.stress.regularisation = epsilon) }
    })
}

/// Bounds the dual (force-diagram) edge length of interior edges: `lo` ≤ q_e l_e / p̄ ≤ `hi`,
/// in units of the mean load p̄ over non-anchored vertices (dimensionless). `lo` must be
/// finite and at least 0, `hi` greater than `lo` (+INFINITY for no upper bound); `lo` = 0 with
/// `hi` = +INFINITY removes the bounds. Default none.
///
/// # Safety
/// `settings`: a valid handle with exclusive access.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_settings_set_dual_length_bounds(
    settings: *mut VsrSettings,
    lo: f64,
    hi: f64,
) -> VsrStatus {
    boundary!({
        // Unbounded on both sides: no bounds (any other pair is checked as given).
        let bounds = (lo != 0.0 || hi != f64::INFINITY).then_some((lo, hi));
        let args = [
            ("dual_length_bounds.lo", "lo"),
            ("dual_length_bounds.hi", "hi"),
        ];
        // SAFETY: forwarded caller's contract.
        unsafe { update(settings, &args, |f| f.stress.dual_length_bounds = bounds) }
    })
}

/// Sets the weight μ of the penalty μ Σ (d*_a − d*_b)² / p̄² on the variation of dual
/// (force-diagram) edge lengths d* = q l over pairs of interior edges sharing a face: a
/// smoother force diagram. `mu` finite and >= 0 (0, the default, turns it off). Form finding
/// fades the weight as μ `decay`ᵏ at outer iteration k so that the loop can still converge;
/// `decay` in [0, 1), default 0.5 (closer to 1: smoother diagram, shape further from the
/// input, more iterations). A stress-only analysis uses μ as given.
///
/// # Safety
/// `settings`: a valid handle with exclusive access.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_settings_set_dual_length_smoothing(
    settings: *mut VsrSettings,
    mu: f64,
    decay: f64,
) -> VsrStatus {
    boundary!({
        let args = [
            ("dual_length_smoothing", "mu"),
            ("smoothing_decay", "decay"),
        ];
        // SAFETY: forwarded caller's contract.
        unsafe {
            update(settings, &args, |f| {
                f.stress.dual_length_smoothing = mu;
                f.smoothing_decay = decay;
            })
        }
    })
}

/// Sets μ₀ of the paper method's proximal schedule μ_k = max(μ₀ βᵏ, μ_min) (relative to the
/// mean diagonal of the height system; dimensionless). Finite and >= 0. Default 1.
///
/// # Safety
/// `settings`: a valid handle with exclusive access.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_settings_set_schedule_mu0(
    settings: *mut VsrSettings,
    mu0: f64,
) -> VsrStatus {
    boundary!({
        let args = [("schedule.mu0", "mu0")];
        // SAFETY: forwarded caller's contract.
        unsafe { update(settings, &args, |f| f.schedule.mu0 = mu0) }
    })
}

/// Sets β, the per-iteration decay of the paper method's proximal weight μ. Finite, in
/// [0, 1]. Default 0.25.
///
/// # Safety
/// `settings`: a valid handle with exclusive access.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_settings_set_schedule_beta(
    settings: *mut VsrSettings,
    beta: f64,
) -> VsrStatus {
    boundary!({
        let args = [("schedule.beta", "beta")];
        // SAFETY: forwarded caller's contract.
        unsafe { update(settings, &args, |f| f.schedule.beta = beta) }
    })
}

/// Sets μ_min, the floor of the proximal weight (dimensionless). Finite and >= 0. Default 1e-9.
///
/// # Safety
/// `settings`: a valid handle with exclusive access.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_settings_set_schedule_mu_min(
    settings: *mut VsrSettings,
    mu_min: f64,
) -> VsrStatus {
    boundary!({
        let args = [("schedule.mu_min", "mu_min")];
        // SAFETY: forwarded caller's contract.
        unsafe { update(settings, &args, |f| f.schedule.mu_min = mu_min) }
    })
}

/// Sets η in the per-vertex proximal weights λ_i = ‖r‖∞ / (|r_i| + η ‖r‖∞) (dimensionless).
/// Finite and > 0. Default 1e-3.
///
/// # Safety
/// `settings`: a valid handle with exclusive access.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_settings_set_schedule_eta(
    settings: *mut VsrSettings,
    eta: f64,
) -> VsrStatus {
    boundary!({
        let args = [("schedule.eta", "eta")];
        // SAFETY: forwarded caller's contract.
        unsafe { update(settings, &args, |f| f.schedule.eta = eta) }
    })
}

/// Sets ν, the pull of every height towards its input value (relative to the mean diagonal
/// of the height system; dimensionless). Finite and >= 0; 0 (default) = no pull.
///
/// # Safety
/// `settings`: a valid handle with exclusive access.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_settings_set_schedule_pull(
    settings: *mut VsrSettings,
    pull: f64,
) -> VsrStatus {
    boundary!({
        let args = [("schedule.pull", "pull")];
        // SAFETY: forwarded caller's contract.
        unsafe { update(settings, &args, |f| f.schedule.pull = pull) }
    })
}

/// Sets the weight of the proximal term Σ l_e² (q_e − q_e^prev)² (dimensionless, in the
/// solver's frame) that keeps each form-finding stress step after the first near the previous
/// force densities (it vanishes at a self-supporting fixed point). Finite and >= 0; 0 turns it
/// off. Default 1e-6. Not used by `vsr_analyse`.
///
/// # Safety
/// `settings`: a valid handle with exclusive access.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_settings_set_proximal_weight(
    settings: *mut VsrSettings,
    weight: f64,
) -> VsrStatus {
    boundary!({
        let args = [("proximal_weight", "weight")];
        // SAFETY: forwarded caller's contract.
        unsafe { update(settings, &args, |f| f.proximal_weight = weight) }
    })
}

/// Sets the number of Optimal Delaunay Triangulation sweeps of the plan: one before each of
/// the first `iterations` stress steps of form finding (vertices move in plan, on the 3-D
/// surface; connectivity is unchanged). 0 (default) keeps the plan fixed. Not used by
/// `vsr_analyse`.
///
/// # Safety
/// `settings`: a valid handle with exclusive access.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_settings_set_odt_iterations(
    settings: *mut VsrSettings,
    iterations: usize,
) -> VsrStatus {
    boundary!({
        // SAFETY: forwarded caller's contract.
        unsafe { update(settings, &[], |f| f.odt_iterations = iterations) }
    })
}

/// Lets ODT sweeps move free boundary vertices too (`enable` 1) or not (0, default: on the
/// shared models it made form finding infeasible or divergent more often than it helped).
/// Any other value: `VSR_STATUS_INVALID_ARGUMENT`.
///
/// # Safety
/// `settings`: a valid handle with exclusive access.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_settings_set_odt_free_boundary(
    settings: *mut VsrSettings,
    enable: u32,
) -> VsrStatus {
    boundary!({
        let on = match enable {
            0 => false,
            1 => true,
            v => return Err(Failure::invalid("enable", format!("{v} is not 0 or 1"))),
        };
        // SAFETY: forwarded caller's contract.
        unsafe { update(settings, &[], |f| f.odt_free_boundary = on) }
    })
}

/// Sets the progress callback of `vsr_form_find` (see `VsrProgressFn`) and the `user` pointer
/// passed back to it unchanged. `callback` NULL removes it (default: none). Voussoir never
/// dereferences or frees `user`; it must stay valid while a solve using these settings runs.
/// If the settings are shared by concurrent solves, the callback is called concurrently.
///
/// # Safety
/// `settings`: a valid handle with exclusive access; `callback`: NULL or a function with the
/// `VsrProgressFn` signature.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vsr_settings_set_progress(
    settings: *mut VsrSettings,
    callback: VsrProgressFn,
    user: *mut c_void,
) -> VsrStatus {
    // SAFETY: forwarded caller's contract.
    boundary!({ unsafe { Progress::set(settings, |s| &mut s.progress, callback, user) } })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{EdgeScope, Formulation, HoleMode, LoadRule, QpSolver, TauMode};

    /// The defaults documented on `vsr_settings_create`. When a Rust default changes, update
    /// the table there (src/capi/settings.rs) and rewrite the header with
    /// `VSR_BLESS=1 cargo test --test capi_header`.
    #[test]
    fn documented_defaults() {
        let f = FormFindSettings::default();
        assert_eq!(f.tolerance, 1e-6);
        assert_eq!(f.max_iterations, 100);
        assert_eq!(f.method, crate::FormMethod::Nearest);
        assert_eq!(f.fairness, 0.03);
        assert_eq!(f.max_height_change, 1.0);
        assert_eq!(f.stall_window, 8);
        assert_eq!(f.stress.q_min, QBound::Relative(0.05));
        assert_eq!(f.stress.q_min_scope, EdgeScope::All);
        assert_eq!(f.stress.q_max, None);
        assert_eq!(f.stress.tau, TauMode::Optimized);
        assert_eq!(f.stress.holes, HoleMode::Affine);
        assert_eq!(f.stress.load_rule, LoadRule::Barycentric);
        assert_eq!(f.stress.formulation, Formulation::Reduced);
        assert_eq!(f.stress.solver, QpSolver::Native);
        assert_eq!(f.stress.regularisation, 1e-16);
        let s = f.schedule;
        assert_eq!(
            [s.mu0, s.beta, s.mu_min, s.eta, s.pull],
            [1.0, 0.25, 1e-9, 1e-3, 0.0]
        );
    }
}

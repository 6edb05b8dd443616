//! Hanging inputs (docs/method.md §13.1): shapes drawn upside down, below the surface their
//! supports span, cannot stand near themselves (a shape in equilibrium under downward loads
//! lies above that surface), so the nearest method form-finds the nearest shape to their mirror
//! image. Over a generated family (domes, vaults with anchored and free edges, an oculus,
//! vaults on four pillars, sizes, depths and seeded random perturbations) every answer is in
//! equilibrium by residuals recomputed here, within the height limit of the input as given,
//! and reports that it was mirrored; upright inputs are not mirrored.

mod common;
use common::{largest_change, plan_diagonal, recomputed_eps_inf};
use voussoir::generate::{self, KnownPlan, Perturbation};
use voussoir::*;

/// `mesh` upside down about its supports' plane (z = 0 in every generator here), its depth
/// scaled by `scale`.
fn hang(mesh: Mesh, scale: f64) -> Mesh {
    let heights: Vec<f64> = mesh.positions().iter().map(|p| -scale * p[2]).collect();
    mesh.with_heights(&heights).unwrap()
}

/// A square vault on four corner pillars (the outer boundary within 0.3 of a corner anchored,
/// free edges between them) of about `n` vertices and rise `rise` at the centre, its edges
/// arching up between the pillars.
fn pillar_vault(n: usize, rise: f64) -> Mesh {
    let k = ((n as f64).sqrt() * 0.9) as usize;
    let domain = generate::Domain {
        outer: generate::rectangle(-1.0, -1.0, 1.0, 1.0, k, k),
        holes: vec![],
    };
    let (p, t) = generate::triangulate(&domain, 1.6 * 4.0 / (2.0 * n as f64)).unwrap();
    generate::lift(
        &p,
        &t,
        |u| rise * (2.0 - u[0] * u[0] - u[1] * u[1]) / 2.0,
        |u, outer| outer && u[0].abs() > 0.7 && u[1].abs() > 0.7,
    )
    .unwrap()
}

/// The generated family: (name, upright shape).
fn upright_family() -> Vec<(String, Mesh)> {
    let mut family = Vec::new();
    for (angle, n) in [(0.6, 150), (0.8, 600), (1.0, 300)] {
        family.push((
            format!("cap {angle} rad, {n}"),
            generate::cap_dome(angle, n).unwrap(),
        ));
    }
    for plan in KnownPlan::ALL {
        family.push((
            format!("{plan:?} vault"),
            generate::vault(plan, 300).unwrap(),
        ));
    }
    for (n, rise) in [(200, 0.4), (500, 0.7)] {
        family.push((
            format!("pillar vault {n}, rise {rise}"),
            pillar_vault(n, rise),
        ));
    }
    family
}

/// Runs the nearest method on `input` and checks the answer; returns the result.
fn check(name: &str, input: Mesh) -> FormFindResult {
    let settings = FormFindSettings::default();
    let problem = Problem::new(input);
    let r = form_find(&problem, &settings, None).unwrap();
    let mesh = &problem.mesh;
    let eps = recomputed_eps_inf(mesh, &r);
    let moved = largest_change(mesh, &r.positions);
    assert_eq!(
        r.termination,
        Termination::Converged,
        "{name}: {:?}",
        r.history
    );
    assert!(eps < 1e-6, "{name}: recomputed ε∞ {eps:e}");
    assert!(
        moved <= settings.max_height_change * (1.0 + 1e-9),
        "{name}: moved {moved} diagonals"
    );
    assert!((r.max_change - moved).abs() <= 1e-12, "{name}: {moved}");
    r
}

#[test]
fn hanging_inputs_converge_from_their_mirror_image() {
    for (name, upright) in upright_family() {
        for scale in [0.5, 1.0] {
            let case = format!("{name} hanging, depth × {scale}");
            let r = check(&case, hang(upright.clone(), scale));
            assert!(r.mirrored, "{case}: not mirrored");
        }
    }
}

#[test]
fn perturbed_hanging_inputs_converge() {
    let family = upright_family();
    for (seed, (name, upright)) in family.iter().enumerate() {
        let kind = [Perturbation::Noise, Perturbation::Dent, Perturbation::Ridge][seed % 3];
        let case = format!("{name} hanging, {kind:?} seed {seed}");
        let input = generate::perturb(&hang(upright.clone(), 1.0), kind, seed as u64);
        let r = check(&case, input);
        assert!(r.mirrored, "{case}: not mirrored");
    }
}

/// The answer for a dome drawn upside down is the dome: nearer to the mirror image than a
/// tenth of the rise at every vertex, where the input is a whole rise or more away.
#[test]
fn a_dome_upside_down_becomes_the_dome() {
    let upright = generate::cap_dome(0.8, 600).unwrap();
    let rise = upright.positions().iter().map(|p| p[2]).fold(0.0, f64::max);
    let r = check("cap upside down", hang(upright.clone(), 1.0));
    let off = (upright.positions().iter().zip(&r.positions))
        .map(|(a, b)| (a[2] - b[2]).abs())
        .fold(0.0, f64::max);
    assert!(off < 0.1 * rise, "{off} from the upright dome, rise {rise}");
    assert!(r.max_change > 0.9 * 2.0 * rise / plan_diagonal(&upright));
}

/// Upright inputs, and perturbed ones, are never mirrored.
#[test]
fn upright_inputs_are_not_mirrored() {
    for (seed, (name, upright)) in upright_family().into_iter().enumerate() {
        let input = generate::perturb(&upright, Perturbation::Noise, seed as u64);
        let r = check(&name, input);
        assert!(!r.mirrored, "{name}: mirrored");
    }
}

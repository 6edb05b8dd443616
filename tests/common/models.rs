//! Where the shared real models are, and whether their absence fails the tests that need them:
//! it does in CI (`CI` set, as CI services do) and whenever `VSR_REQUIRE_MODELS=1`, so that a
//! missing folder cannot make those tests pass without checking anything; elsewhere they say
//! skipped. Included by the benches too (`#[path]`), which print the models' rows when the
//! folder is there.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

/// The shared real models: `NAME.obj` with its supports `NAME.json` in [`models_dir`].
pub const MODELS: [&str; 9] = [
    "free_vault",
    "dome_with_doors",
    "lilium",
    "cheese",
    "four_holes",
    "neumunster",
    "hex",
    "three_pillar",
    "vault_pq",
];

/// The shared model `name` of `dir` (see [`models_dir`]) with its supports, read as every
/// layer reads a file (`io::load_model`).
pub fn read_shared(dir: &Path, name: &str) -> voussoir::Result<voussoir::Problem> {
    voussoir::io::load_model(
        &dir.join(format!("{name}.obj")),
        &dir.join(format!("{name}.json")),
    )
}

/// Whether the models must be present, from the values of `CI` and `VSR_REQUIRE_MODELS`.
pub fn models_required(ci: Option<&str>, require: Option<&str>) -> bool {
    let ci =
        ci.is_some_and(|v| !matches!(v.trim().to_ascii_lowercase().as_str(), "" | "0" | "false"));
    ci || require.is_some_and(|v| v.trim() == "1")
}

/// The folder of the shared real models (see `find_models`), required as the environment says.
pub fn models_dir() -> Option<PathBuf> {
    let var = |name| std::env::var(name).ok();
    find_models(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/data/models"),
        models_required(var("CI").as_deref(), var("VSR_REQUIRE_MODELS").as_deref()),
    )
}

/// `dir` when it is a folder; None (with a "skipped" line) when it is absent and not
/// `required`. Panics, failing the calling test, when it is absent and `required`.
pub fn find_models(dir: PathBuf, required: bool) -> Option<PathBuf> {
    if dir.is_dir() {
        return Some(dir);
    }
    if required {
        panic!(
            "{} not found, and CI or VSR_REQUIRE_MODELS=1 requires the shared models",
            dir.display()
        );
    }
    println!("skipped: {} not found", dir.display());
    None
}

/// The non-anchored vertex nearest the plan centroid of the referenced vertices.
pub fn central_vertex(mesh: &voussoir::Mesh) -> usize {
    let referenced: Vec<usize> = (0..mesh.positions().len())
        .filter(|&v| mesh.referenced()[v])
        .collect();
    let n = referenced.len() as f64;
    let c = referenced.iter().fold([0.0; 2], |c, &v| {
        let p = mesh.positions()[v];
        [c[0] + p[0] / n, c[1] + p[1] / n]
    });
    let d = |v: usize| {
        let p = mesh.positions()[v];
        (p[0] - c[0]).hypot(p[1] - c[1])
    };
    (referenced.into_iter())
        .filter(|&v| mesh.is_non_anchored(v))
        .min_by(|&a, &b| d(a).total_cmp(&d(b)))
        .expect("a non-anchored vertex")
}

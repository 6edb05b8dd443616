//! Where the shared real models are, and whether their absence fails the tests that need them:
//! it does in CI (`CI` set, as CI services do) and whenever `VSR_REQUIRE_MODELS=1`, so that a
//! missing folder cannot make those tests pass without checking anything; elsewhere they say
//! skipped.

use std::path::PathBuf;

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

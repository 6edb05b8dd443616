//! Plan repair leaves the nine shared models alone: none has a face below the default
//! tolerance, so reading them with repair on gives the meshes validation accepts unchanged.
//! Skipped when ../shared/data/models is absent (failing in CI:
//! tests/common/models.rs).

mod common;

use common::{models_dir, MODELS};
use voussoir::io;
use voussoir::{repair_plan, DEFAULT_REPAIR_TOLERANCE};

#[test]
fn shared_models_need_no_repair() {
    let Some(dir) = models_dir() else {
        return;
    };
    for model in MODELS {
        let (mut positions, mut faces) = io::read_mesh(&dir.join(format!("{model}.obj"))).unwrap();
        let anchored = io::read_supports(&dir.join(format!("{model}.json"))).unwrap();
        let (p0, f0) = (positions.clone(), faces.clone());
        let repairs = repair_plan(
            &mut positions,
            &mut faces,
            &anchored,
            DEFAULT_REPAIR_TOLERANCE,
        )
        .unwrap();
        assert!(repairs.is_empty(), "{model}: {repairs:?}");
        assert_eq!((positions, faces), (p0, f0), "{model}");
    }
}

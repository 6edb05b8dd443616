//! Plan repair leaves the nine shared models alone: none has a face below the default
//! tolerance, so reading them with repair on gives the meshes validation accepts unchanged.
//! Skipped when ../shared/data/models is absent.

use std::path::PathBuf;

use voussoir::io;
use voussoir::{repair_plan, DEFAULT_REPAIR_TOLERANCE};

const MODELS: [&str; 9] = [
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

#[test]
fn shared_models_need_no_repair() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/data/models");
    if !dir.is_dir() {
        println!("skipped: ../shared/data/models not found");
        return;
    }
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

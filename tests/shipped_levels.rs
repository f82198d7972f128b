//! Every level shipped under `levels/` loads, and its `.glb` (when shipped) is exactly what
//! export makes of it today.

use std::path::{Path, PathBuf};

use arlpcg::level::scene::Scene;
use arlpcg::level::{gltf, yaml};

fn yaml_files(dir: &Path, found: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            yaml_files(&path, found);
        } else if path.extension().is_some_and(|e| e == "yaml") {
            found.push(path);
        }
    }
}

#[test]
fn every_shipped_level_loads_and_its_glb_is_current() {
    let mut files = Vec::new();
    yaml_files(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("levels"),
        &mut files,
    );
    assert!(
        files.len() >= 4,
        "expected the shipped example levels, found {files:?}"
    );
    for path in files {
        let level = yaml::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let glb = path.with_extension("glb");
        if glb.exists() {
            let current = gltf::to_glb(&Scene::of_level(&level).unwrap());
            assert!(
                std::fs::read(&glb).unwrap() == current,
                "{} is stale: re-export it",
                glb.display()
            );
        }
    }
}

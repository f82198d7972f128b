//! What `arlpcg view` draws: a level's scene (the same boxes, road and markers the glTF export
//! writes, `crates/core/src/level/scene.rs`) as flat JSON a browser turns into triangles, each
//! piece tinted toward red by its share of the recorded failures.

use serde_json::{Value, json};

use arlpcg_core::level::Level;
use arlpcg_core::level::scene::{Material, Scene};

/// The colour a piece that holds every recorded failure is tinted to.
const FAILURE_RED: [f32; 4] = [0.9, 0.12, 0.1, 1.0];

/// The scene of `level` as the view page reads it: `boxes` (centre, heading in degrees,
/// extents, colour), `meshes` (world positions, normals and triangle indices, colour),
/// `points` (spawn, finish) and a `title`. Pure: the same level gives the same bytes.
pub fn scene_json(level: &Level, title: &str) -> Value {
    let scene = Scene::of_level(level);
    let failures = failure_shares(level);
    let colour = |name: &str, material: Material| {
        let base = material.colour();
        match piece_index(name).and_then(|k| failures.get(k)) {
            Some(&share) if share > 0.0 => blend(base, FAILURE_RED, share),
            _ => base,
        }
    };
    let boxes: Vec<Value> = scene
        .nodes
        .iter()
        .map(|node| {
            json!({
                "name": node.name,
                "centre": node.centre,
                "heading": node.heading,
                "extents": node.extents,
                "rgba": colour(&node.name, node.material),
            })
        })
        .collect();
    let meshes: Vec<Value> = scene
        .meshes
        .iter()
        .flat_map(|mesh| {
            mesh.primitives.iter().map(|(triangles, material)| {
                json!({
                    "name": mesh.name,
                    "positions": triangles.positions.concat(),
                    "normals": triangles.normals.concat(),
                    "indices": triangles.triangles.concat(),
                    "rgba": colour(&mesh.name, *material),
                })
            })
        })
        .collect();
    let points: Vec<Value> = scene
        .points
        .iter()
        .map(|point| json!({"name": point.name, "position": point.position, "heading": point.heading}))
        .collect();
    json!({
        "title": title,
        "game": level.game().name(),
        "pieces": level.piece_count(),
        "boxes": boxes,
        "meshes": meshes,
        "points": points,
    })
}

/// Each piece's share of the failures the level's statistics record, scaled so that the most
/// failed piece is 1 (none recorded: empty).
fn failure_shares(level: &Level) -> Vec<f32> {
    let Some(stats) = &level.stats else {
        return Vec::new();
    };
    let most = stats.failures_by_piece.iter().copied().max().unwrap_or(0);
    if most == 0 {
        return Vec::new();
    }
    stats
        .failures_by_piece
        .iter()
        .map(|&n| n as f32 / most as f32)
        .collect()
}

/// The piece a scene node stands for (`block_007`, `segment_007`: piece 7), none for the start
/// block, markers and obstacles.
fn piece_index(name: &str) -> Option<usize> {
    let digits = name
        .strip_prefix("block_")
        .or_else(|| name.strip_prefix("segment_"))?;
    digits.split('-').next()?.parse().ok()
}

fn blend(a: [f32; 4], b: [f32; 4], t: f32) -> [f32; 4] {
    let t = t.clamp(0.0, 1.0);
    std::array::from_fn(|i| a[i] + (b[i] - a[i]) * t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use arlpcg_core::level::yaml;

    fn shipped(path: &str) -> Level {
        yaml::load(&std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(path)).unwrap()
    }

    fn names<'a>(scene: &'a Value, part: &str) -> Vec<&'a str> {
        scene[part]
            .as_array()
            .unwrap()
            .iter()
            .map(|b| b["name"].as_str().unwrap())
            .collect()
    }

    #[test]
    fn every_piece_and_marker_is_in_the_scene_and_failures_turn_a_piece_red() {
        let mut level = shipped("levels/platform/platform_seed7_aux-1.00.yaml");
        let failures = level.stats.as_ref().unwrap().failures_by_piece.clone();
        let blocks = level.piece_count();
        let scene = scene_json(&level, "a level");
        let boxes = names(&scene, "boxes");
        assert!(boxes.contains(&"start_block"), "{boxes:?}");
        assert_eq!(
            boxes.iter().filter(|n| n.starts_with("block_")).count(),
            blocks
        );
        assert_eq!(names(&scene, "points"), ["spawn", "finish", "finish_zone"]);
        assert_eq!(scene, scene_json(&level, "a level"), "pure");

        let rgba = |scene: &Value, name: &str| {
            let boxes = scene["boxes"].as_array().unwrap();
            boxes.iter().find(|b| b["name"] == name).unwrap()["rgba"].clone()
        };
        let most = failures
            .iter()
            .position(|&n| n == *failures.iter().max().unwrap())
            .unwrap();
        level.stats = None;
        let unplayed = scene_json(&level, "a level");
        let block = format!("block_{most:03}");
        assert_ne!(
            rgba(&scene, &block),
            rgba(&unplayed, &block),
            "the most failed block is red"
        );
        assert_eq!(rgba(&scene, "start_block"), rgba(&unplayed, "start_block"));

        let track = scene_json(
            &shipped("levels/racing/racing_seed7_aux+0.00.yaml"),
            "a track",
        );
        let meshes = track["meshes"].as_array().unwrap();
        assert!(names(&track, "meshes").contains(&"segment_000"));
        let first = &meshes[0];
        let vertices = first["positions"].as_array().unwrap().len() / 3;
        let indices = first["indices"].as_array().unwrap();
        assert!(!indices.is_empty());
        assert!(
            indices
                .iter()
                .all(|i| (i.as_u64().unwrap() as usize) < vertices)
        );
    }
}

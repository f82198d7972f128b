//! What `arlpcg view` draws: a level's scene (the same boxes, road and markers the glTF export
//! writes, `crates/core/src/level/scene.rs`) as flat JSON a browser turns into triangles, each
//! piece tinted toward red by its share of the recorded failures, and the certificate's run
//! (the recorded run that reaches the goal) as a trail over it, the first trials of its
//! verification played again; and the request that builds a level's scene again at another λ
//! (the page's slider).

use std::sync::Arc;

use serde_json::{Value, json};

use crate::services::certificate;
use crate::services::generation::{KeptPrefix, LevelRequest};
use arlpcg_core::level::scene::{Material, Physics, Scene};
use arlpcg_core::level::stats::Outcome;
use arlpcg_core::level::{Level, PolicyRef, Shape};

/// The run drawn over a level.
#[derive(Debug, Clone, PartialEq)]
pub enum Trail {
    /// The certificate run, played again.
    Run {
        /// The run's seed.
        seed: u64,
        /// Where the player was at every step.
        path: Vec<[f32; 3]>,
        /// Whether it reached the goal again.
        succeeded: bool,
    },
    /// No trail, and why (an unplayed level, no certificate, its Solver's file missing).
    None(String),
}

impl Trail {
    /// The certificate run of `level`, played again with the Solver that recorded it
    /// ([`certificate::run`]).
    pub fn of_certificate(level: &Level) -> Trail {
        match certificate::run(level) {
            Ok((seed, run)) => Trail::Run {
                seed,
                succeeded: run.result.outcome == Outcome::Success,
                path: run.path,
            },
            Err(why) => Trail::None(format!("{why:#}")),
        }
    }

    fn json(&self) -> Value {
        match self {
            Trail::Run {
                seed,
                path,
                succeeded,
            } => json!({"seed": seed, "succeeded": succeeded, "points": path.concat()}),
            Trail::None(why) => json!({"none": why}),
        }
    }
}

/// How many of a level's verification trials the view plays again and draws.
pub const REPLAYED_RUNS: u32 = 8;

/// The first [`REPLAYED_RUNS`] trials of `level`'s verification played again
/// ([`certificate::replays`]), as the view page draws them: `runs` (each one's `seed`,
/// `succeeded` and flat world `points`) and `solver` (who played), or `none` and why.
pub fn runs_json(level: &Level) -> Value {
    match certificate::replays(level, REPLAYED_RUNS) {
        Ok(runs) => {
            let runs: Vec<Value> = runs
                .into_iter()
                .map(|(seed, run)| {
                    json!({
                        "seed": seed,
                        "succeeded": run.result.outcome == Outcome::Success,
                        "points": run.path.concat(),
                    })
                })
                .collect();
            let solver = level.stats.as_ref().map(|s| s.solver.describe());
            json!({"runs": runs, "solver": solver})
        }
        Err(why) => json!({"none": format!("{why:#}")}),
    }
}

/// The colour a piece that holds every recorded failure is tinted to.
const FAILURE_RED: [f32; 4] = [0.9, 0.12, 0.1, 1.0];

/// The scene of `level` as the view page reads it: `boxes` (centre, heading in degrees,
/// extents, colour), `meshes` (world positions, normals and triangle indices, colour),
/// `points` (spawn, finish, and the finish region with its `size`), the `trail` (flat world positions, or why there is none) and a
/// `title`. Pure: the same level and trail give the same bytes.
pub fn scene_json(level: &Level, title: &str, trail: &Trail) -> Value {
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
        .map(|point| {
            let mut json =
                json!({"name": point.name, "position": point.position, "heading": point.heading});
            // The finish region: the box where reaching it counts a success.
            if let Physics::TriggerBox { size } = point.physics {
                json["size"] = json!(size);
            }
            json
        })
        .collect();
    json!({
        "title": title,
        "game": level.game().name(),
        "pieces": level.piece_count(),
        "boxes": boxes,
        "meshes": meshes,
        "points": points,
        "trail": trail.json(),
    })
}

/// The request that builds `level`'s scene again at λ `aux` (the view's slider): its start,
/// goal and obstacles kept (a kept prefix of no pieces, read from the file `from`), its seed
/// (0 for a hand-made level), its profile and its style knobs. The seed's first draw: rebuilt at
/// the λ a Generator made it with, a level that was its seed's first draw comes back as it was.
pub fn rebuild_request(level: Arc<Level>, from: PolicyRef, aux: f64) -> LevelRequest {
    LevelRequest::new(level.seed.unwrap_or(0), Some(aux))
        .obstacles(obstacle_count(&level))
        .profile(level.profile.clone())
        .knobs(knob_values(&level))
        .keep(KeptPrefix {
            level,
            pieces: 0,
            from,
        })
}

/// How many obstacles `level` has (a Generator draws that many again from its seed).
pub fn obstacle_count(level: &Level) -> u32 {
    match level.track.shape() {
        Shape::Road(road) => road.obstacles.len() as u32,
        Shape::Blocks(_) => 0,
    }
}

/// `level`'s value of each of its game's style knobs, in the game's order (0: not recorded).
pub fn knob_values(level: &Level) -> Vec<f32> {
    level
        .game()
        .shape()
        .knobs()
        .iter()
        .map(|name| level.knobs.get(*name).copied().unwrap_or(0.0) as f32)
        .collect()
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

    fn none() -> Trail {
        Trail::None("not played".into())
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
        let scene = scene_json(&level, "a level", &none());
        let boxes = names(&scene, "boxes");
        assert!(boxes.contains(&"start_block"), "{boxes:?}");
        assert_eq!(
            boxes.iter().filter(|n| n.starts_with("block_")).count(),
            blocks
        );
        assert_eq!(names(&scene, "points"), ["spawn", "finish", "finish_zone"]);
        // Only the finish region has a size: the goal block's top, 2 m high.
        let sizes: Vec<&Value> = scene["points"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| &p["size"])
            .collect();
        assert!(sizes[0].is_null() && sizes[1].is_null());
        let goal_size = level.platform().unwrap().last().size;
        assert_eq!(sizes[2], &json!([goal_size, 2.0, goal_size]));
        assert_eq!(scene, scene_json(&level, "a level", &none()), "pure");

        let rgba = |scene: &Value, name: &str| {
            let boxes = scene["boxes"].as_array().unwrap();
            boxes.iter().find(|b| b["name"] == name).unwrap()["rgba"].clone()
        };
        let most = failures
            .iter()
            .position(|&n| n == *failures.iter().max().unwrap())
            .unwrap();
        level.stats = None;
        let unplayed = scene_json(&level, "a level", &none());
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
            &none(),
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

    /// The certificate run is played again with the Solver that recorded it: its trail leaves
    /// the spawn and ends at the finish; a level with no certificate says why it has none.
    #[test]
    fn the_certificate_run_is_drawn_as_a_trail_from_spawn_to_finish() {
        // The shipped level names its Solver by a path from the repository's root, where
        // cargo runs the tests.
        let level = shipped("levels/platform/platform_seed7_aux-1.00.yaml");
        let trail = Trail::of_certificate(&level);
        let Trail::Run {
            seed,
            path,
            succeeded,
        } = &trail
        else {
            panic!("{trail:?}");
        };
        assert_eq!(Some(*seed), level.stats.as_ref().unwrap().certificate);
        assert!(*succeeded && path.len() > 10, "{} steps", path.len());
        let scene = scene_json(&level, "a level", &trail);
        let point = |name: &str| {
            let points = scene["points"].as_array().unwrap();
            let p = &points.iter().find(|p| p["name"] == name).unwrap()["position"];
            [0, 1, 2].map(|k| p[k].as_f64().unwrap() as f32)
        };
        let far = |a: [f32; 3], b: [f32; 3]| ((a[0] - b[0]).powi(2) + (a[2] - b[2]).powi(2)).sqrt();
        assert!(far(path[0], point("spawn")) < 1.0, "{:?}", path[0]);
        assert!(far(*path.last().unwrap(), point("finish")) < 4.0);
        let flat = scene["trail"]["points"].as_array().unwrap();
        assert_eq!(flat.len(), 3 * path.len());

        let mut unplayed = level.clone();
        unplayed.stats = None;
        let Trail::None(why) = Trail::of_certificate(&unplayed) else {
            panic!("no statistics, no run");
        };
        assert!(why.contains("no statistics"), "{why}");
        let scene = scene_json(&unplayed, "a level", &Trail::None(why.clone()));
        assert_eq!(scene["trail"]["none"], why.as_str());
    }

    /// The slider's rebuild keeps the level's scene and seed: at the λ the shipped Generator
    /// made a shipped level with, it is that level's track again; at another λ it is another
    /// track from the same start toward the same goal, past the same obstacles.
    #[test]
    fn a_level_rebuilt_at_its_own_aux_is_itself_and_at_another_another_over_the_same_scene() {
        use crate::services::making::LevelSource;
        use crate::services::policies::load_generator;
        for (file, game) in [
            ("levels/platform/platform_seed7_aux-1.00.yaml", "platform"),
            ("levels/racing/racing_seed7_aux+0.00.yaml", "racing"),
        ] {
            let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
            let (level, from) = yaml::load_pinned(&root.join(file)).unwrap();
            let (generator, _) = load_generator(
                &root.join(format!("policies/{game}/generator.safetensors")),
                level.game(),
            )
            .unwrap();
            let level = Arc::new(level);
            let at = |aux: f64| {
                let request = rebuild_request(level.clone(), from.clone(), aux);
                LevelSource::Generator(&generator).level(&request).unwrap()
            };
            let own = level.aux.unwrap();
            let again = at(own);
            assert_eq!(again.track, level.track, "{file}");
            assert_eq!((again.seed, again.goal), (level.seed, level.goal));
            let other = at(if own > 0.0 { -1.0 } else { 1.0 });
            assert_ne!(other.track, level.track, "{file}");
            assert_eq!(other.goal, level.goal);
            // The spawn, the start block, the goal's marker and any obstacle (the finish
            // lies on the last piece, which moves).
            let scene = |l: &Level| {
                let scene = scene_json(l, "", &none());
                let fixed = |part: &str| {
                    let all = scene[part].as_array().unwrap().iter();
                    all.filter(|v| {
                        let name = v["name"].as_str().unwrap();
                        !["block_", "segment_", "finish"]
                            .iter()
                            .any(|p| name.starts_with(p))
                    })
                    .cloned()
                    .collect::<Vec<_>>()
                };
                (fixed("points"), fixed("boxes"))
            };
            assert_eq!(
                scene(&other),
                scene(&level),
                "{file}: start, goal and obstacles kept"
            );
        }
    }
}

//! glTF export read back with the `gltf` crate: one node per block plus start block and
//! markers, names, extras, and world bounds that match the level.

use std::collections::BTreeMap;

use crate::common::import_glb;
use arlpcg_core::game::GameSpec;
use arlpcg_core::game::platform::rules;
use arlpcg_core::level::Shape;
use arlpcg_core::level::platform::BLOCK_THICKNESS;
use arlpcg_core::level::racing::FINISH_LENGTH;
use arlpcg_core::level::racing::ROAD_WIDTH;
use arlpcg_core::level::scene::{PhysicsExtensions, Scene};
use arlpcg_core::level::{Level, PlatformRulesConfig, gltf as export};

fn level(seed: u64) -> Level {
    rules::platform_level(
        seed,
        Some(-1.0),
        None,
        &PlatformRulesConfig::default(),
        &Default::default(),
    )
    .unwrap()
}

/// `q · v · q⁻¹`: `v` turned by the unit quaternion `q` = [x, y, z, w].
fn rotate(q: [f64; 4], v: [f64; 3]) -> [f64; 3] {
    let u = [q[0], q[1], q[2]];
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let uv = cross(u, v);
    let uuv = cross(u, uv);
    [0, 1, 2].map(|k| v[k] + 2.0 * (q[3] * uv[k] + uuv[k]))
}

/// World-space bounds of every node's unit cube, from the file's own transforms.
fn node_bounds(node: &gltf::Node) -> ([f32; 3], [f32; 3]) {
    let (t, r, s) = node.transform().decomposed();
    let rotate = |v: [f32; 3]| {
        let turned = rotate(r.map(f64::from), v.map(f64::from));
        turned.map(|c| c as f32)
    };
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for corner in 0..8 {
        let local = [0, 1, 2].map(|k| {
            if corner >> k & 1 == 1 {
                0.5 * s[k]
            } else {
                -0.5 * s[k]
            }
        });
        let world = rotate(local);
        for k in 0..3 {
            lo[k] = lo[k].min(world[k] + t[k]);
            hi[k] = hi[k].max(world[k] + t[k]);
        }
    }
    (lo, hi)
}

#[test]
fn glb_reads_back_with_one_node_per_block_and_matching_bounds() {
    for seed in [1, 2, 3] {
        let level = level(seed);
        let track = level.platform().unwrap();
        let glb = export::to_glb(&Scene::of_level(&level));
        // Left for `.ci/run` to pass through the Khronos validator.
        let exports = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("gltf-exports");
        std::fs::create_dir_all(&exports).unwrap();
        std::fs::write(exports.join(format!("rules_seed{seed}.glb")), &glb).unwrap();
        let (document, buffers) = import_glb(&glb);
        let nodes: Vec<gltf::Node> = document.nodes().collect();
        // start block, every block, start and goal markers, spawn, finish and its zone, then a
        // collider beside the start block and every block
        assert_eq!(nodes.len(), 2 * (track.block_count() + 1) + 5);
        assert_eq!(nodes[0].name(), Some("start_block"));
        assert_eq!(nodes[1].name(), Some("block_000"));
        let last_name = format!("block_{:03}", track.block_count() - 1);
        assert_eq!(nodes[track.block_count()].name(), Some(last_name.as_str()));
        let goal = track.block_count() + 2;
        assert_eq!(nodes[goal].name(), Some("goal"));
        assert_eq!(nodes[goal + 2].name(), Some("finish"));
        assert_eq!(nodes[goal + 4].name(), Some("start_block_collider"));
        // Block nodes sit where the level says: top face at the block's height, centred on it.
        for (node, platform) in nodes.iter().zip(track.platforms()) {
            let (lo, hi) = node_bounds(node);
            assert!(
                (hi[1] as f64 - platform.position[1]).abs() < 1e-4,
                "{:?}: top {} vs {}",
                node.name(),
                hi[1],
                platform.position[1]
            );
            assert!(((hi[1] - lo[1]) as f64 - BLOCK_THICKNESS).abs() < 1e-4);
            for k in [0, 2] {
                let centre = 0.5 * (lo[k] + hi[k]) as f64;
                assert!(
                    (centre - platform.position[k]).abs() < 1e-3,
                    "{:?} centre {centre} vs {}",
                    node.name(),
                    platform.position[k]
                );
                // A square of side s turned by any heading spans between s and s*sqrt(2).
                let span = (hi[k] - lo[k]) as f64;
                assert!(span >= platform.size - 1e-3 && span <= platform.size * 2f64.sqrt() + 1e-3);
            }
        }
        // The block's generator parameters travel in its extras.
        let extras: serde_json::Value =
            serde_json::from_str(nodes[1].extras().as_ref().unwrap().get()).unwrap();
        assert_eq!(extras["distance"], track.block_params()[0].distance);
        // The mesh data is a unit cube.
        let mesh = nodes[1].mesh().unwrap();
        let primitive = mesh.primitives().next().unwrap();
        let reader = primitive.reader(|b| Some(&buffers[b.index()]));
        let positions: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
        assert_eq!(positions.len(), 24);
        assert!(positions.iter().flatten().all(|c| c.abs() == 0.5));
    }
}

#[test]
fn export_is_deterministic_and_gltf_matches_glb() {
    let level = level(4);
    let scene = Scene::of_level(&level);
    assert_eq!(export::to_glb(&scene), export::to_glb(&scene));
    let gltf_out = export::to_gltf(&scene, "level.bin");
    let root: serde_json::Value = serde_json::from_slice(&gltf_out.main).unwrap();
    assert_eq!(root["buffers"][0]["uri"], "level.bin");
    assert_eq!(
        root["nodes"].as_array().unwrap().len(),
        2 * (level.piece_count() + 1) + 5
    );
    assert_eq!(root["scenes"][0]["extras"]["aux"], -1.0);
    assert_eq!(
        gltf_out.bin.len(),
        root["buffers"][0]["byteLength"].as_u64().unwrap() as usize
    );
}

/// Each triangle of `primitive`: its three positions and three normals.
fn triangles(primitive: &gltf::Primitive, buffers: &[Vec<u8>]) -> Vec<[([f32; 3], [f32; 3]); 3]> {
    let reader = primitive.reader(|b| Some(&buffers[b.index()]));
    let positions: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
    let normals: Vec<[f32; 3]> = reader.read_normals().unwrap().collect();
    let indices: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
    indices
        .chunks(3)
        .map(|t| [0, 1, 2].map(|k| (positions[t[k] as usize], normals[t[k] as usize])))
        .collect()
}

fn sub(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Engines cull back faces: every triangle of every mesh must be wound counter-clockwise seen
/// from the side its stored normals point to, and every closed mesh (blocks, boxes, markers,
/// cylinders: all but the road's open surface and skirts) must enclose a positive volume, that
/// is face outward.
#[test]
fn every_mesh_faces_outward_and_its_winding_agrees_with_its_normals() {
    let platform = level(4);
    let racing = arlpcg_core::game::racing::rules::racing_level(
        9,
        Some(0.0),
        None,
        &arlpcg_core::level::racing::RacingRulesConfig {
            obstacles: 6,
            ..Default::default()
        },
        &Default::default(),
    )
    .unwrap();
    let track = racing.racing().unwrap();
    let kinds = |kind: &str| {
        track
            .obstacles
            .iter()
            .filter(|o| format!("{o:?}").starts_with(kind))
            .count()
    };
    assert!(
        kinds("Box") > 0 && kinds("Cylinder") > 0,
        "{:?}",
        track.obstacles
    );
    for level in [platform, racing] {
        let glb = export::to_glb(&Scene::of_level(&level));
        let (document, buffers) = import_glb(&glb);
        let mut closed_meshes = 0;
        for mesh in document.meshes() {
            let name = mesh.name().unwrap_or("?").to_string();
            let mut volume = 0.0f64;
            for primitive in mesh.primitives() {
                for (i, [a, b, c]) in triangles(&primitive, &buffers).into_iter().enumerate() {
                    let face = cross(sub(b.0, a.0), sub(c.0, a.0));
                    let stored = [0, 1, 2].map(|k| a.1[k] + b.1[k] + c.1[k]);
                    assert!(
                        dot(face, stored) > 0.0,
                        "{}: mesh {name}, triangle {i} is wound against its normals",
                        level.game()
                    );
                    volume += f64::from(dot(a.0, cross(b.0, c.0))) / 6.0;
                }
            }
            if !name.starts_with("segment_") {
                closed_meshes += 1;
                assert!(
                    volume > 0.0,
                    "{}: mesh {name} faces inward (volume {volume})",
                    level.game()
                );
            }
        }
        assert!(closed_meshes > 0, "{}", level.game());
    }
}

fn rotate_z(rotation: [f32; 4]) -> [f32; 3] {
    let [x, y, z, w] = rotation;
    let u = [x, y, z];
    let v = [0.0, 0.0, 1.0];
    let uv = cross(u, v);
    let uuv = cross(u, uv);
    [0, 1, 2].map(|k| v[k] + 2.0 * (w * uv[k] + uuv[k]))
}

/// An engine finds where to spawn (position, and +Z along the start heading) and the finish
/// (the goal block, or across the road's end, with the reach that counts as success).
#[test]
fn spawn_and_finish_nodes_carry_start_heading_and_goal_reach() {
    use arlpcg_core::level::heading::heading_direction;
    let platform = level(6);
    let racing = arlpcg_core::game::RacingGame::rule_level(6, &Default::default()).unwrap();
    for level in [platform, racing] {
        let glb = export::to_glb(&Scene::of_level(&level));
        let (document, _) = import_glb(&glb);
        let node = |name: &str| {
            document
                .nodes()
                .find(|n| n.name() == Some(name))
                .unwrap_or_else(|| panic!("{}: no {name} node", level.game()))
        };
        let (start, heading, end, end_direction) = match level.racing() {
            Some(track) => {
                let road = track.road();
                let samples = road.samples();
                let [a, b] = [
                    samples[samples.len() - 2].centre,
                    samples[samples.len() - 1].centre,
                ];
                let d = [b[0] - a[0], b[2] - a[2]];
                let n = (d[0] * d[0] + d[1] * d[1]).sqrt();
                (
                    track.position,
                    track.heading,
                    road.end().0,
                    [d[0] / n, d[1] / n],
                )
            }
            None => {
                let track = level.platform().unwrap();
                let last = track.last();
                (
                    track.start().position,
                    track.start().heading,
                    last.position,
                    heading_direction(last.heading),
                )
            }
        };
        let (t, r, _) = node("spawn").transform().decomposed();
        assert!(
            (0..3).all(|k| (t[k] as f64 - start[k]).abs() < 1e-3),
            "{}: {t:?}",
            level.game()
        );
        let forward = rotate_z(r);
        let [x, z] = heading_direction(heading);
        assert!(
            (forward[0] as f64 - x).abs() < 1e-4 && (forward[2] as f64 - z).abs() < 1e-4,
            "{}: spawn +Z {forward:?}, heading {heading}",
            level.game()
        );
        let finish = node("finish");
        let (t, r, _) = finish.transform().decomposed();
        assert!(
            (0..3).all(|k| (t[k] as f64 - end[k]).abs() < 1e-3),
            "{}: {t:?} {end:?}",
            level.game()
        );
        let forward = rotate_z(r);
        assert!(
            (forward[0] as f64 - end_direction[0]).abs() < 0.02
                && (forward[2] as f64 - end_direction[1]).abs() < 0.02,
            "{}: finish +Z {forward:?}, along {end_direction:?}",
            level.game()
        );
        let extras: serde_json::Value =
            serde_json::from_str(finish.extras().as_ref().unwrap().get()).unwrap();
        assert!(
            extras["reach_horizontal_m"].as_f64().unwrap() > 0.0,
            "{extras}"
        );
        assert_eq!(extras["goal"], serde_json::json!(level.goal));
    }
}

/// Racing rule track 9 with 6 obstacles (boxes and cylinders).
fn racing_with_obstacles() -> Level {
    arlpcg_core::game::racing::rules::racing_level(
        9,
        None,
        None,
        &arlpcg_core::level::racing::RacingRulesConfig {
            obstacles: 6,
            ..Default::default()
        },
        &Default::default(),
    )
    .unwrap()
}

/// The levels the physics tests export: rule levels of seeds 1 ..= `seeds` of each game, and
/// a racing level among obstacles.
fn physics_levels(seeds: u64) -> impl Iterator<Item = Level> {
    use arlpcg_core::game::{GameSpec, RacingGame};
    (1..=seeds)
        .map(level)
        .chain((1..=seeds).filter_map(|seed| RacingGame::rule_level(seed, &Default::default())))
        .chain([racing_with_obstacles()])
}

/// Colliders an engine imports (`OMI_physics_body` / `OMI_physics_shape`): an unscaled box beside
/// every block and box obstacle with the block's size, a cylinder beside every cylinder, each
/// road segment's own mesh as a triangle mesh, and a trigger at the finish; markers collide with
/// nothing. On 20 rule levels of each game and a racing level among obstacles.
#[test]
fn every_solid_piece_has_a_collider_and_the_finish_a_trigger() {
    let levels = physics_levels(20);
    for level in levels {
        let game = level.game();
        let out = export::to_gltf(&Scene::of_level(&level), "level.bin");
        let root: serde_json::Value = serde_json::from_slice(&out.main).unwrap();
        assert_eq!(
            root["extensionsUsed"],
            serde_json::json!(["OMI_physics_body", "OMI_physics_shape"])
        );
        assert!(
            root.get("extensionsRequired").is_none(),
            "used, not required"
        );
        let shapes = root["extensions"]["OMI_physics_shape"]["shapes"]
            .as_array()
            .unwrap();
        let nodes = root["nodes"].as_array().unwrap();
        let named = |name: &str| nodes.iter().find(|n| n["name"] == name);
        let shape_of = |node: &serde_json::Value, role: &str| {
            let index = node["extensions"]["OMI_physics_body"][role]["shape"].as_u64()?;
            shapes.get(index as usize)
        };
        let mut solid = 0;
        for node in nodes {
            let name = node["name"].as_str().unwrap();
            let is_box = name.starts_with("block_")
                || name == "start_block"
                || (name.starts_with("obstacle_") && node.get("scale").is_some());
            if is_box && !name.ends_with("_collider") {
                let collider = named(&format!("{name}_collider"))
                    .unwrap_or_else(|| panic!("{game}: {name} has no collider"));
                assert!(collider.get("scale").is_none(), "{game}: {name}: unscaled");
                assert_eq!(collider["translation"], node["translation"]);
                let shape = shape_of(collider, "collider").unwrap();
                assert_eq!(shape["type"], "box");
                assert_eq!(shape["box"]["size"], node["scale"], "{game}: {name}");
                solid += 1;
            }
            if name.starts_with("segment_") && !name.ends_with("_collider") {
                // Beside the segment, not on it (Godot 4 drops the mesh of a collider node).
                assert!(node.get("extensions").is_none(), "{game}: {name}");
                let collider = named(&format!("{name}_collider"))
                    .unwrap_or_else(|| panic!("{game}: {name} has no collider"));
                assert_eq!(collider["translation"], node["translation"]);
                let shape = shape_of(collider, "collider").unwrap();
                assert_eq!(shape["type"], "trimesh");
                assert_eq!(shape["trimesh"]["mesh"], node["mesh"], "{game}: {name}");
                solid += 1;
            }
            if name.starts_with("obstacle_")
                && node.get("mesh").is_some()
                && node.get("scale").is_none()
            {
                let collider = named(&format!("{name}_collider")).unwrap();
                let shape = shape_of(collider, "collider").unwrap();
                assert_eq!(shape["type"], "cylinder");
                both_radius_forms(shape);
                solid += 1;
            }
            if name == "start" || name == "goal" {
                assert!(
                    node.get("extensions").is_none(),
                    "{game}: markers do not collide"
                );
            }
        }
        assert!(solid >= level.piece_count(), "{game}: {solid} solid nodes");
        let trigger = named("finish_zone").expect("a finish zone");
        let shape = shape_of(trigger, "trigger").unwrap();
        assert_eq!(shape["type"], "box");
        finish_zone_is_where_the_game_counts_success(&level, trigger, &shape["box"]["size"]);
    }
}

/// The finish trigger is the success region: the goal block's top (platform), the road's last
/// 3 m across its width (racing), in the trigger node's own frame.
fn finish_zone_is_where_the_game_counts_success(
    level: &Level,
    trigger: &serde_json::Value,
    size: &serde_json::Value,
) {
    let number = |v: &serde_json::Value| v.as_f64().unwrap();
    let size: Vec<f64> = size.as_array().unwrap().iter().map(number).collect();
    let t: Vec<f64> = trigger["translation"]
        .as_array()
        .unwrap()
        .iter()
        .map(number)
        .collect();
    let q: Vec<f64> = trigger["rotation"]
        .as_array()
        .unwrap()
        .iter()
        .map(number)
        .collect();
    // A world point in the trigger's frame: q⁻¹ · (p − t).
    let local = |p: [f64; 3]| {
        let v = [p[0] - t[0], p[1] - t[1], p[2] - t[2]];
        rotate([-q[0], -q[1], -q[2], q[3]], v)
    };
    let inside = |p: [f64; 3]| {
        let l = local(p);
        (0..3).all(|k| l[k].abs() <= 0.5 * size[k] + 1e-4)
    };
    match level.shape() {
        Shape::Blocks(track) => {
            let goal = track.last();
            assert_eq!(
                size,
                vec![goal.size, 2.0, goal.size],
                "the goal block's top"
            );
            let half = 0.5 * goal.size - 1e-3;
            let top = goal.position;
            for (a, c) in [
                (-1.0, -1.0),
                (-1.0, 1.0),
                (1.0, -1.0),
                (1.0, 1.0),
                (0.0, 0.0),
            ] {
                let [fx, fz] = arlpcg_core::level::heading::heading_direction(goal.heading);
                let p = [
                    top[0] + half * (a * fx - c * fz),
                    top[1] + 0.01,
                    top[2] + half * (a * fz + c * fx),
                ];
                assert!(inside(p), "every corner of the goal block's top: {p:?}");
            }
            let before = &track.platforms()[track.platforms().len() - 2];
            assert!(!inside([
                before.position[0],
                before.position[1] + 0.01,
                before.position[2]
            ]));
        }
        Shape::Road(track) => {
            let road = track.road();
            assert_eq!(size, vec![ROAD_WIDTH, 6.0, FINISH_LENGTH]);
            // Points `back` metres before the road's end, `across` from its centre line.
            let end = road.samples()[road.samples().len() - 1];
            let at = |back: f64, across: f64| {
                let (p, f) = (end.across(across), end.forward());
                [0, 1, 2].map(|k| p[k] - back * f[k])
            };
            for across in [-0.49 * ROAD_WIDTH, 0.0, 0.49 * ROAD_WIDTH] {
                assert!(inside(at(0.1, across)), "the road's end, {across} m across");
                assert!(inside(at(FINISH_LENGTH - 0.1, across)), "3 m before it");
                assert!(!inside(at(FINISH_LENGTH + 0.5, across)), "3.5 m before it");
            }
            // Half a metre beyond either edge, measured level, as the game measures the car's
            // distance from the centre line (a banked end tilts the surface, not the rule).
            let (s, c) = end.heading.sin_cos();
            for side in [-1.0, 1.0] {
                let off = side * (0.5 * ROAD_WIDTH + 0.5);
                let p = [
                    end.centre[0] - off * s,
                    end.centre[1],
                    end.centre[2] - off * c,
                ];
                assert!(!inside(p), "beside the road");
            }
        }
    }
}

/// A cylinder carries `radiusBottom` and `radiusTop` (the current OMI specification) and
/// `radius` (what Godot 4 reads), all one value.
fn both_radius_forms(shape: &serde_json::Value) {
    let cylinder = &shape["cylinder"];
    assert!(
        cylinder["radius"].as_f64().is_some_and(|r| r > 0.0),
        "{shape}"
    );
    assert_eq!(cylinder["radiusBottom"], cylinder["radius"], "{shape}");
    assert_eq!(cylinder["radiusTop"], cylinder["radius"], "{shape}");
}

/// `--collision-names`: every solid node with a mesh (and only those) is named with Godot's
/// `-col` import hint, one for each collider of the physics extension; markers keep their names.
#[test]
fn collision_names_mark_exactly_the_solid_meshes() {
    use arlpcg_core::level::scene::COLLISION_SUFFIX;
    for level in [level(5), racing_with_obstacles()] {
        let game = level.game();
        let nodes_of = |scene: Scene| {
            let out = export::to_gltf(&scene, "level.bin");
            let root: serde_json::Value = serde_json::from_slice(&out.main).unwrap();
            root["nodes"].as_array().unwrap().clone()
        };
        let plain = nodes_of(Scene::of_level(&level));
        assert!(
            plain
                .iter()
                .all(|n| !n["name"].as_str().unwrap().ends_with(COLLISION_SUFFIX)),
            "{game}: no hints unless asked"
        );
        let named = nodes_of(Scene::of_level(&level).with_collision_names());
        let name = |n: &serde_json::Value| n["name"].as_str().unwrap().to_string();
        let hinted: Vec<String> = named
            .iter()
            .map(name)
            .filter(|n| n.ends_with(COLLISION_SUFFIX))
            .collect();
        let mut colliders = 0;
        for node in &named {
            if node["extensions"]["OMI_physics_body"]["collider"].is_null() {
                continue;
            }
            colliders += 1;
            let visual = name(node).trim_end_matches("_collider").to_string();
            assert!(
                hinted.contains(&visual),
                "{game}: the collider {} belongs to no -col mesh",
                name(node)
            );
        }
        assert_eq!(hinted.len(), colliders, "{game}: {hinted:?}");
        assert!(colliders > level.piece_count(), "{game}");
        for marker in ["start", "goal"] {
            assert!(
                named.iter().any(|n| n["name"] == marker),
                "{game}: {marker}"
            );
        }
    }
}

/// The document of `level`'s `.gltf` export with its colliders in `physics`.
fn document_with(level: &Level, physics: PhysicsExtensions) -> serde_json::Value {
    let scene = Scene::of_level(level).with_physics_extensions(physics);
    serde_json::from_slice(&export::to_gltf(&scene, "level.bin").main).unwrap()
}

/// Each node's extension `name` by the node's name, for the nodes that carry it.
fn by_node(root: &serde_json::Value, name: &str) -> BTreeMap<String, serde_json::Value> {
    let nodes = root["nodes"].as_array().unwrap();
    nodes
        .iter()
        .filter(|n| !n["extensions"][name].is_null())
        .map(|n| {
            (
                n["name"].as_str().unwrap().into(),
                n["extensions"][name].clone(),
            )
        })
        .collect()
}

/// `--physics khr`: the same colliders and trigger as the OMI export, on the same nodes, in the
/// Khronos drafts' terms: a `KHR_implicit_shapes` box of the same size, a cylinder of the same
/// height and radius (`radiusBottom`, `radiusTop`), each road segment's mesh as
/// `geometry.node`, the segment's own node; `finish_zone` a box trigger where the game counts
/// success. Every index points at a shape or a node with a mesh, and each shape is used once.
/// Nothing of OMI's is written, and the extensions are used, not required.
#[test]
fn khr_physics_has_one_collider_per_solid_piece_and_the_finish_a_trigger() {
    let levels = physics_levels(5);
    let mut cylinders = 0;
    for level in levels {
        let game = level.game();
        let omi = document_with(&level, PhysicsExtensions::Omi);
        let root = document_with(&level, PhysicsExtensions::Khr);
        assert_eq!(
            root["extensionsUsed"],
            serde_json::json!([export::KHR_SHAPES, export::KHR_BODY])
        );
        assert!(
            root.get("extensionsRequired").is_none(),
            "used, not required"
        );
        assert!(
            !root.to_string().contains("OMI_"),
            "{game}: no OMI with khr"
        );
        let shapes = root["extensions"][export::KHR_SHAPES]["shapes"]
            .as_array()
            .unwrap();
        let nodes = root["nodes"].as_array().unwrap();
        let omi_shapes = omi["extensions"]["OMI_physics_shape"]["shapes"]
            .as_array()
            .unwrap();
        let omi_bodies = by_node(&omi, "OMI_physics_body");
        let bodies = by_node(&root, export::KHR_BODY);
        assert_eq!(
            bodies.keys().collect::<Vec<_>>(),
            omi_bodies.keys().collect::<Vec<_>>(),
            "{game}: the same nodes carry a body"
        );
        let mut used = vec![0; shapes.len()];
        for (name, body) in &bodies {
            let (role, omi_role) = match name.as_str() {
                "finish_zone" => ("trigger", &omi_bodies[name]["trigger"]),
                _ => ("collider", &omi_bodies[name]["collider"]),
            };
            assert_eq!(body.as_object().unwrap().len(), 1, "{game}: {name}: {body}");
            let geometry = body[role]["geometry"].as_object().unwrap();
            assert_eq!(geometry.len(), 1, "{game}: {name}: shape or node, not both");
            let omi_shape = &omi_shapes[omi_role["shape"].as_u64().unwrap() as usize];
            match (geometry.get("shape"), geometry.get("node")) {
                (Some(index), None) => {
                    let index = index.as_u64().unwrap() as usize;
                    assert!(index < shapes.len(), "{game}: {name}: shape {index}");
                    used[index] += 1;
                    let shape = &shapes[index];
                    assert_eq!(shape["type"], omi_shape["type"], "{game}: {name}");
                    match shape["type"].as_str().unwrap() {
                        "box" => assert_eq!(shape["box"], omi_shape["box"], "{game}: {name}"),
                        "cylinder" => {
                            let (c, o) = (&shape["cylinder"], &omi_shape["cylinder"]);
                            assert_eq!(c.as_object().unwrap().len(), 3, "{game}: {name}: {c}");
                            assert_eq!(c["height"], o["height"]);
                            assert!(o["radius"].as_f64().unwrap() > 0.0);
                            assert_eq!(c["radiusBottom"], o["radius"]);
                            assert_eq!(c["radiusTop"], o["radius"]);
                            cylinders += 1;
                        }
                        other => panic!("{game}: {name}: a {other}"),
                    }
                }
                (None, Some(node)) => {
                    assert_eq!(omi_shape["type"], "trimesh", "{game}: {name}");
                    let node = &nodes[node.as_u64().unwrap() as usize];
                    assert_eq!(node["mesh"], omi_shape["trimesh"]["mesh"], "{game}: {name}");
                    assert_eq!(
                        format!("{}_collider", node["name"].as_str().unwrap()),
                        *name
                    );
                }
                _ => panic!("{game}: {name}: {body}"),
            }
        }
        assert_eq!(used, vec![1; shapes.len()], "{game}: each shape used once");
        let solid = bodies.keys().filter(|n| n.ends_with("_collider")).count();
        assert!(solid >= level.piece_count(), "{game}: {solid} colliders");
        let trigger = nodes.iter().find(|n| n["name"] == "finish_zone").unwrap();
        let index = trigger["extensions"][export::KHR_BODY]["trigger"]["geometry"]["shape"]
            .as_u64()
            .unwrap();
        let shape = &shapes[index as usize];
        assert_eq!(shape["type"], "box");
        finish_zone_is_where_the_game_counts_success(&level, trigger, &shape["box"]["size"]);
        for marker in ["start", "goal"] {
            let node = nodes.iter().find(|n| n["name"] == marker).unwrap();
            assert!(node.get("extensions").is_none(), "{game}: {marker}");
        }
    }
    assert!(cylinders > 0, "the obstacle course has cylinders");
}

/// `--physics both`: every node carries the OMI body exactly as the default export writes it
/// and the KHR body exactly as `khr` does, the document both sets of shapes; the default writes
/// OMI alone, as before.
#[test]
fn both_physics_writes_omi_and_khr_on_the_same_nodes_and_the_default_omi_only() {
    for level in [level(3), racing_with_obstacles()] {
        let game = level.game();
        let omi = document_with(&level, PhysicsExtensions::Omi);
        let khr = document_with(&level, PhysicsExtensions::Khr);
        let both = document_with(&level, PhysicsExtensions::Both);
        assert_eq!(
            both["extensionsUsed"],
            serde_json::json!([
                "OMI_physics_body",
                "OMI_physics_shape",
                export::KHR_SHAPES,
                export::KHR_BODY
            ])
        );
        for (name, alone) in [("OMI_physics_body", &omi), (export::KHR_BODY, &khr)] {
            assert_eq!(by_node(&both, name), by_node(alone, name), "{game}: {name}");
        }
        for name in ["OMI_physics_shape", export::KHR_SHAPES] {
            let alone = if name == export::KHR_SHAPES {
                &khr
            } else {
                &omi
            };
            assert_eq!(
                both["extensions"][name], alone["extensions"][name],
                "{game}"
            );
        }
        assert_eq!(
            both["nodes"].as_array().unwrap().len(),
            omi["nodes"].as_array().unwrap().len()
        );
        let default = export::to_gltf(&Scene::of_level(&level), "level.bin").main;
        let default_text = String::from_utf8(default).unwrap();
        assert!(
            !default_text.contains("KHR_"),
            "{game}: OMI only by default"
        );
        assert_eq!(
            serde_json::from_str::<serde_json::Value>(&default_text).unwrap(),
            omi
        );
    }
}

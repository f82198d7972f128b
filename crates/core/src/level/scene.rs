//! A level as a scene of named, placed boxes with materials and metadata: the game-specific part
//! of export. [`super::gltf`] writes any scene as glTF without knowing which game made it.

use serde_json::{Value, json};

use super::platform::{BLOCK_THICKNESS, Platform, PlatformTrack};
use super::racing::{Obstacle, RacingTrack};
use super::road::TriangleMesh;
use super::{Level, Shape};

/// What a node is, which picks its material.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Material {
    /// A platform block.
    Block,
    /// The block the player starts on.
    StartBlock,
    /// The last block, at the goal.
    GoalBlock,
    /// The marker over the start.
    StartMarker,
    /// The marker over the goal.
    GoalMarker,
    /// The road's surface.
    Road,
    /// The road's skirts along its edges.
    RoadEdge,
    /// A box or cylinder obstacle on the road.
    Obstacle,
}

impl Material {
    /// Every material, in the order files list them.
    pub const ALL: [Material; 8] = [
        Material::Block,
        Material::StartBlock,
        Material::GoalBlock,
        Material::StartMarker,
        Material::GoalMarker,
        Material::Road,
        Material::RoadEdge,
        Material::Obstacle,
    ];

    /// The material's name in files (`block`, `start_block`, ...).
    pub fn name(self) -> &'static str {
        match self {
            Material::Block => "block",
            Material::StartBlock => "start_block",
            Material::GoalBlock => "goal_block",
            Material::StartMarker => "start_marker",
            Material::GoalMarker => "goal_marker",
            Material::Road => "road",
            Material::RoadEdge => "road_edge",
            Material::Obstacle => "obstacle",
        }
    }

    /// Linear RGBA base colour.
    pub fn colour(self) -> [f32; 4] {
        match self {
            Material::Block => [0.55, 0.57, 0.62, 1.0],
            Material::StartBlock => [0.20, 0.55, 0.25, 1.0],
            Material::GoalBlock => [0.85, 0.65, 0.10, 1.0],
            Material::StartMarker => [0.10, 0.80, 0.20, 1.0],
            Material::GoalMarker => [0.95, 0.15, 0.10, 1.0],
            Material::Road => [0.18, 0.18, 0.20, 1.0],
            Material::RoadEdge => [0.45, 0.40, 0.35, 1.0],
            Material::Obstacle => [0.60, 0.30, 0.20, 1.0],
        }
    }
}

/// A box in the world.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneNode {
    /// The node's name in files (`start_block`, `block_000`, ...).
    pub name: String,
    /// Centre of the box.
    pub centre: [f64; 3],
    /// Rotation about +Y, degrees.
    pub heading: f64,
    /// Full extents along the box's own x, y, z.
    pub extents: [f64; 3],
    /// What the box is, which picks its colour.
    pub material: Material,
    /// Metadata carried into the file (the block's generator parameters).
    pub extras: Option<Value>,
    /// What the box is to an engine's physics.
    pub physics: Physics,
}

/// A node of its own geometry (a piece of road, a cylinder), in world coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneMesh {
    /// The node's name in files (`segment_000`, `obstacle_000`, ...).
    pub name: String,
    /// Its parts, each drawn with one material.
    pub primitives: Vec<(TriangleMesh, Material)>,
    /// Metadata carried into the file (the segment's generator parameters).
    pub extras: Option<Value>,
    /// What the node is to an engine's physics.
    pub physics: Physics,
}

/// What a node is to an engine's physics (written as the glTF physics extensions that
/// [`PhysicsExtensions`] names).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Physics {
    /// Solid and static: the node's own box (its extents).
    SolidBox,
    /// Solid and static: the node's own mesh, as a triangle mesh.
    SolidMesh,
    /// Solid and static: an upright cylinder standing on `base`.
    SolidCylinder {
        /// The centre of the cylinder's base, m.
        base: [f64; 3],
        /// The cylinder's radius, m.
        radius: f64,
        /// The cylinder's height, m.
        height: f64,
    },
    /// Not solid: a box (its size in the node's own frame, local +Z along the heading) that an
    /// engine reports entering: the finish, where the game counts a run a success.
    TriggerBox {
        /// The box's full extents along its own x, y, z, m.
        size: [f64; 3],
    },
    /// Only to look at (markers).
    None,
}

/// A place without geometry (where to spawn, where the finish is), in world coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct ScenePoint {
    /// The point's name in files (`spawn`, `finish`).
    pub name: String,
    /// Where the point is, m.
    pub position: [f64; 3],
    /// The level's heading there, degrees: the node is turned so that its local +Z (glTF's
    /// forward) points along it.
    pub heading: f64,
    /// Metadata carried into the file (what the point is, its heading).
    pub extras: Value,
    /// What the point is to an engine's physics (the finish is a trigger).
    pub physics: Physics,
}

/// Which glTF physics extensions an export writes its colliders and trigger in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PhysicsExtensions {
    /// `OMI_physics_shape` and `OMI_physics_body` (Godot 4 reads them).
    #[default]
    Omi,
    /// The Khronos drafts `KHR_implicit_shapes` and `KHR_physics_rigid_bodies` (three.js with
    /// Rapier, Babylon.js with Havok, the Khronos sample viewer).
    Khr,
    /// Both, on the same collider nodes.
    Both,
}

/// A level ready to export.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// The scene's name in files (`platform_level`, `racing_level`).
    pub name: String,
    /// Boxes (blocks, markers, box obstacles).
    pub nodes: Vec<SceneNode>,
    /// Nodes with their own geometry, after the boxes.
    pub meshes: Vec<SceneMesh>,
    /// Empty nodes (spawn, finish), after the meshes.
    pub points: Vec<ScenePoint>,
    /// Metadata of the whole level (game, seed, aux).
    pub extras: Value,
    /// The glTF physics extensions the export writes (OMI unless asked).
    pub physics_extensions: PhysicsExtensions,
}

/// The suffix Godot's import hints read as "this mesh also collides" (a static body with the
/// mesh's triangles as its shape, the mesh kept), in Godot 3 and 4 alike.
pub const COLLISION_SUFFIX: &str = "-col";

impl Scene {
    /// The scene with every solid node and mesh named for Godot's import hints
    /// ([`COLLISION_SUFFIX`]): colliders for tools that read names and not the physics
    /// extension (Godot 3). Godot 4.3 and later read the extension too, and would make both.
    pub fn with_collision_names(mut self) -> Scene {
        for node in &mut self.nodes {
            if node.physics == Physics::SolidBox {
                node.name.push_str(COLLISION_SUFFIX);
            }
        }
        for mesh in &mut self.meshes {
            if matches!(
                mesh.physics,
                Physics::SolidMesh | Physics::SolidCylinder { .. }
            ) {
                mesh.name.push_str(COLLISION_SUFFIX);
            }
        }
        self
    }

    /// The scene with its colliders and trigger written in `extensions` (`--physics`).
    pub fn with_physics_extensions(mut self, extensions: PhysicsExtensions) -> Scene {
        self.physics_extensions = extensions;
        self
    }

    /// The scene of a level: every block or piece of road, obstacles, start and goal markers.
    pub fn of_level(level: &Level) -> Scene {
        let mut scene = match level.shape() {
            Shape::Blocks(track) => platform_scene(level, track),
            Shape::Road(track) => racing_scene(level, track),
        };
        if let Some(pacing) = &level.pacing {
            scene.extras["aux_curve"] = json!(pacing.curve.to_string());
            scene.extras["aux_by_piece"] = json!(pacing.piece_aux);
        }
        // The abilities the level was made for, so an engine's character can match them.
        if let Some(profile) = &level.profile {
            scene.extras["profile"] = json!(profile.record());
        }
        if let Some(stats) = &level.stats {
            scene.extras["success_ratio"] = json!(stats.success_ratio);
            scene.extras["success_ci95"] = json!(stats.ci95);
            scene.extras["trials"] = json!(stats.trials);
            scene.extras["certificate"] = json!(stats.certificate);
        }
        scene.points = spawn_and_finish(level);
        scene
    }
}

/// Where a player starts (position and heading) and the finish: the goal, with the distances
/// within which reaching it counts (docs/spec.md §1: the goal reach of each game).
fn spawn_and_finish(level: &Level) -> Vec<ScenePoint> {
    let (start, start_heading, finish, finish_heading, horizontal, vertical, finish_kind) =
        match level.shape() {
            Shape::Blocks(track) => {
                let start = track.start();
                let goal_block = track.last();
                (
                    start.position,
                    start.heading,
                    goal_block.position,
                    goal_block.heading,
                    super::platform::GOAL_REACH_HORIZONTAL,
                    super::platform::GOAL_REACH_VERTICAL,
                    "on the goal block: stand within reach of the goal",
                )
            }
            Shape::Road(track) => {
                let (end, end_heading) = track.road().end();
                (
                    track.position,
                    track.heading,
                    end,
                    end_heading,
                    super::racing::GOAL_REACH_HORIZONTAL,
                    super::racing::GOAL_REACH_VERTICAL,
                    "across the road's end: drive within reach of the goal",
                )
            }
        };
    vec![
        ScenePoint {
            name: "spawn".into(),
            position: start,
            heading: start_heading,
            extras: json!({"kind": "spawn", "heading_degrees": start_heading, "forward": "+Z"}),
            physics: Physics::None,
        },
        ScenePoint {
            name: "finish".into(),
            position: finish,
            heading: finish_heading,
            extras: json!({
                "kind": "finish",
                "where": finish_kind,
                "goal": level.goal,
                "reach_horizontal_m": horizontal,
                "reach_vertical_m": vertical,
            }),
            physics: Physics::None,
        },
        finish_zone(level),
    ]
}

/// How tall the platform finish zone is above the goal block's top, m (the character is 1.8 m).
const PLATFORM_FINISH_ZONE_HEIGHT: f64 = 2.0;
/// How far the racing finish zone reaches below and above the road's centre line, m.
const RACING_FINISH_ZONE_BELOW: f64 = 2.0;
const RACING_FINISH_ZONE_ABOVE: f64 = 4.0;

/// Where the game counts a run a success, as an engine's trigger: the goal block's top (the
/// character stands on it), or the road's last [`super::racing::FINISH_LENGTH`] metres across its
/// width (the car on the road there).
fn finish_zone(level: &Level) -> ScenePoint {
    let (position, heading, size, rule) = match level.shape() {
        Shape::Blocks(track) => {
            let goal = track.last();
            let height = PLATFORM_FINISH_ZONE_HEIGHT;
            (
                [
                    goal.position[0],
                    goal.position[1] + 0.5 * height,
                    goal.position[2],
                ],
                goal.heading,
                [goal.size, height, goal.size],
                "the character stands on the goal block's top".to_string(),
            )
        }
        Shape::Road(track) => {
            let road = track.road();
            let length = super::racing::FINISH_LENGTH;
            // Back from the road's end along its heading (3 m of road bend by at most 4.5°).
            let end = road.samples()[road.samples().len() - 1];
            let forward = end.forward();
            let height = RACING_FINISH_ZONE_BELOW + RACING_FINISH_ZONE_ABOVE;
            let centre = [0, 1, 2].map(|k| end.centre[k] - 0.5 * length * forward[k]);
            (
                [
                    centre[0],
                    centre[1] + 0.5 * height - RACING_FINISH_ZONE_BELOW,
                    centre[2],
                ],
                end.heading.to_degrees(),
                [road.shape().width, height, length],
                format!("the car is on the road within its last {length} m"),
            )
        }
    };
    ScenePoint {
        name: "finish_zone".into(),
        position,
        heading,
        extras: json!({"kind": "finish_zone", "success": rule, "size_m": size}),
        physics: Physics::TriggerBox { size },
    }
}

fn marker(name: &str, base: [f64; 3], height: f64, material: Material) -> SceneNode {
    SceneNode {
        name: name.into(),
        centre: [base[0], base[1] + 0.5 * height, base[2]],
        heading: 0.0,
        extents: [0.3, height, 0.3],
        material,
        // A post to see, not to collide with (it may stand in the road).
        extras: Some(json!({"collides": false})),
        physics: Physics::None,
    }
}

fn platform_scene(level: &Level, track: &PlatformTrack) -> Scene {
    let platforms = track.platforms();
    let block_node = |name: String, p: &Platform, material, extras| SceneNode {
        name,
        centre: [
            p.position[0],
            p.position[1] - 0.5 * BLOCK_THICKNESS,
            p.position[2],
        ],
        heading: p.heading,
        extents: [p.size, BLOCK_THICKNESS, p.size],
        material,
        extras,
        physics: Physics::SolidBox,
    };
    let mut nodes = vec![block_node(
        "start_block".into(),
        &platforms[0],
        Material::StartBlock,
        None,
    )];
    let last = track.block_count() - 1;
    for (i, (params, placed)) in track.block_params().iter().zip(&platforms[1..]).enumerate() {
        let material = if i == last {
            Material::GoalBlock
        } else {
            Material::Block
        };
        let extras = json!({
            "index": i,
            "distance": params.distance,
            "angle": params.angle,
            "size": params.size,
            "height": params.height,
        });
        nodes.push(block_node(
            format!("block_{i:03}"),
            placed,
            material,
            Some(extras),
        ));
    }
    nodes.push(marker(
        "start",
        platforms[0].position,
        2.0,
        Material::StartMarker,
    ));
    nodes.push(marker("goal", level.goal, 3.0, Material::GoalMarker));
    level_scene(
        level,
        nodes,
        Vec::new(),
        json!({ "blocks": track.block_count() }),
    )
}

fn racing_scene(level: &Level, track: &RacingTrack) -> Scene {
    let road = track.road();
    let mut nodes = vec![
        marker("start", track.position, 2.0, Material::StartMarker),
        marker("goal", level.goal, 3.0, Material::GoalMarker),
    ];
    let mut meshes: Vec<SceneMesh> = track
        .segments
        .iter()
        .enumerate()
        .map(|(i, params)| {
            let (first, last) = road.segment_samples(i);
            SceneMesh {
                name: format!("segment_{i:03}"),
                primitives: vec![
                    (road.surface_between(first, last), Material::Road),
                    (road.skirts_between(first, last), Material::RoadEdge),
                ],
                extras: Some(json!({
                    "index": i,
                    "length": params.length,
                    "curve": params.curve,
                    "height": params.height,
                })),
                physics: Physics::SolidMesh,
            }
        })
        .collect();
    for (i, obstacle) in track.obstacles.iter().enumerate() {
        let name = format!("obstacle_{i:03}");
        match *obstacle {
            Obstacle::Box {
                position,
                size,
                heading,
            } => nodes.push(SceneNode {
                name,
                centre: [position[0], position[1] + 0.5 * size[1], position[2]],
                heading,
                extents: size,
                material: Material::Obstacle,
                extras: Some(json!({"kind": "box"})),
                physics: Physics::SolidBox,
            }),
            Obstacle::Cylinder {
                position,
                radius,
                height,
            } => meshes.push(SceneMesh {
                name,
                primitives: vec![(cylinder(position, radius, height), Material::Obstacle)],
                extras: Some(json!({"kind": "cylinder", "radius": radius, "height": height})),
                physics: Physics::SolidCylinder {
                    base: position,
                    radius,
                    height,
                },
            }),
        }
    }
    level_scene(
        level,
        nodes,
        meshes,
        json!({
            "segments": track.segments.len(),
            "road_width": road.shape().width,
            "road_length": road.length(),
        }),
    )
}

/// A level's scene: its nodes and meshes, with the extras every level carries (the format, the
/// game, the seed, λ) followed by its game's own.
fn level_scene(
    level: &Level,
    nodes: Vec<SceneNode>,
    meshes: Vec<SceneMesh>,
    game_extras: Value,
) -> Scene {
    let mut extras = json!({
        "format": super::yaml::FORMAT_NAME,
        "game": level.game().name(),
        "seed": level.seed,
        "aux": level.aux,
    });
    if let (Value::Object(all), Value::Object(own)) = (&mut extras, game_extras) {
        all.extend(own);
    }
    Scene {
        name: format!("{}_level", level.game()),
        nodes,
        meshes,
        points: Vec::new(),
        extras,
        physics_extensions: PhysicsExtensions::Omi,
    }
}

/// Sides of a cylinder's mesh.
const CYLINDER_SIDES: usize = 24;

/// An upright cylinder standing on `base`: side, top and bottom, normals outward.
fn cylinder(base: [f64; 3], radius: f64, height: f64) -> TriangleMesh {
    let mut mesh = TriangleMesh::default();
    let angle = |k: usize| std::f64::consts::TAU * k as f64 / CYLINDER_SIDES as f64;
    // Side: a strip of (bottom, top) pairs around, u around the cylinder.
    for k in 0..=CYLINDER_SIDES {
        let (s, c) = angle(k).sin_cos();
        // Counter-clockwise seen from above is toward -z from +x: (cos a, -sin a).
        let normal = [c as f32, 0.0, -s as f32];
        let x = base[0] + radius * c;
        let z = base[2] - radius * s;
        let u = k as f32 / CYLINDER_SIDES as f32;
        mesh.vertex([x, base[1], z], normal, [u, 1.0]);
        mesh.vertex([x, base[1] + height, z], normal, [u, 0.0]);
    }
    // Top before bottom: seen from outside, top → bottom → next bottom turns counter-clockwise
    // (engines cull the other side).
    mesh.strip(0, CYLINDER_SIDES + 1, 1, 0);
    // Caps: a fan around a centre vertex each.
    for (y, up) in [(base[1] + height, 1.0f32), (base[1], -1.0)] {
        let centre = mesh.positions.len() as u32;
        mesh.vertex([base[0], y, base[2]], [0.0, up, 0.0], [0.5, 0.5]);
        for k in 0..CYLINDER_SIDES {
            let (s, c) = angle(k).sin_cos();
            mesh.vertex(
                [base[0] + radius * c, y, base[2] - radius * s],
                [0.0, up, 0.0],
                [0.5 + 0.5 * c as f32, 0.5 - 0.5 * s as f32],
            );
        }
        for k in 0..CYLINDER_SIDES as u32 {
            let a = centre + 1 + k;
            let b = centre + 1 + (k + 1) % CYLINDER_SIDES as u32;
            mesh.triangles.push(if up > 0.0 {
                [centre, a, b]
            } else {
                [centre, b, a]
            });
        }
    }
    mesh
}

//! A level as a scene of named, placed boxes with materials and metadata: the game-specific part
//! of export. [`super::gltf`] writes any scene as glTF without knowing which game made it.

use serde_json::{Value, json};

use super::platform::{BLOCK_THICKNESS, Platform};
use super::{Level, Track};

/// What a node is, which picks its material.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Material {
    Block,
    StartBlock,
    GoalBlock,
    StartMarker,
    GoalMarker,
}

impl Material {
    pub const ALL: [Material; 5] = [
        Material::Block,
        Material::StartBlock,
        Material::GoalBlock,
        Material::StartMarker,
        Material::GoalMarker,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Material::Block => "block",
            Material::StartBlock => "start_block",
            Material::GoalBlock => "goal_block",
            Material::StartMarker => "start_marker",
            Material::GoalMarker => "goal_marker",
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
        }
    }
}

/// A box in the world.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneNode {
    pub name: String,
    /// Centre of the box.
    pub centre: [f64; 3],
    /// Rotation about +Y, degrees.
    pub heading: f64,
    /// Full extents along the box's own x, y, z.
    pub extents: [f64; 3],
    pub material: Material,
    /// Metadata carried into the file (the block's generator parameters).
    pub extras: Option<Value>,
}

/// A level ready to export.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    pub name: String,
    pub nodes: Vec<SceneNode>,
    /// Metadata of the whole level (game, seed, aux).
    pub extras: Value,
}

/// Why a level cannot be turned into a scene yet.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "exporting {0} levels is not supported yet: the racing game's road geometry lands with the racing game"
)]
pub struct UnsupportedGame(pub &'static str);

impl Scene {
    /// The scene of a level: every block, and start and goal markers.
    pub fn of_level(level: &Level) -> Result<Scene, UnsupportedGame> {
        let Track::Platform(track) = &level.track else {
            return Err(UnsupportedGame("racing"));
        };
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
        let marker = |name: &str, base: [f64; 3], height: f64, material| SceneNode {
            name: name.into(),
            centre: [base[0], base[1] + 0.5 * height, base[2]],
            heading: 0.0,
            extents: [0.3, height, 0.3],
            material,
            extras: None,
        };
        nodes.push(marker(
            "start",
            platforms[0].position,
            2.0,
            Material::StartMarker,
        ));
        nodes.push(marker("goal", level.goal, 3.0, Material::GoalMarker));
        Ok(Scene {
            name: format!("{}_level", level.game()),
            nodes,
            extras: json!({
                "format": super::yaml::FORMAT_NAME,
                "game": level.game().name(),
                "seed": level.seed,
                "aux": level.aux,
                "blocks": track.block_count(),
            }),
        })
    }
}

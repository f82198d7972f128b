//! The glTF physics extensions `OMI_physics_shape` and `OMI_physics_body`: colliders and the
//! finish trigger, for engines that read them.

use gltf_json as json;

use super::box_rotation;
use crate::level::scene::{Physics, Scene};

/// The glTF physics extensions written (Godot 4 reads them; other tools keep or ignore them).
pub const OMI_BODY: &str = "OMI_physics_body";
/// The shapes' extension.
pub const OMI_SHAPE: &str = "OMI_physics_shape";

/// An `OMI_physics_shape` cylinder: `radiusBottom` and `radiusTop` as the current
/// specification reads them, and `radius` as Godot 4 reads them.
fn cylinder(radius: f64, height: f64) -> serde_json::Value {
    serde_json::json!({
        "radius": radius,
        "radiusBottom": radius,
        "radiusTop": radius,
        "height": height,
    })
}

/// Colliders and the finish trigger as the `OMI_physics_shape` / `OMI_physics_body` extensions
/// (used, not required; Godot 4 imports them as static bodies and areas): a box collider node
/// beside each block and box obstacle (unscaled, as physics engines want), a cylinder beside each
/// cylinder obstacle, the road segments' own meshes as triangle meshes beside each segment, a
/// box trigger on the finish zone (where the game counts success). Collider nodes are pushed
/// after `nodes`' existing ones.
pub(super) fn physics(
    scene: &Scene,
    root: &mut json::Root,
    nodes: &mut Vec<json::Index<json::Node>>,
    mesh_nodes: &[(json::Index<json::Node>, json::Index<json::Mesh>)],
    point_nodes: &[json::Index<json::Node>],
) {
    let mut shapes: Vec<serde_json::Value> = Vec::new();
    let mut shape = |value: serde_json::Value| {
        shapes.push(value);
        shapes.len() - 1
    };
    let body = |role: &str, shape: usize| {
        let mut extensions = json::extensions::scene::Node::default();
        extensions.others.insert(
            OMI_BODY.into(),
            serde_json::json!({ role: { "shape": shape } }),
        );
        Some(extensions)
    };
    let mut extra_nodes = Vec::new();
    for node in &scene.nodes {
        if node.physics == Physics::SolidBox {
            let index = shape(serde_json::json!({"type": "box", "box": {"size": node.extents}}));
            extra_nodes.push(json::Node {
                name: Some(format!("{}_collider", node.name)),
                translation: Some(node.centre.map(|c| c as f32)),
                rotation: box_rotation(node.heading),
                extensions: body("collider", index),
                ..Default::default()
            });
        }
    }
    for (mesh, &(node, mesh_index)) in scene.meshes.iter().zip(mesh_nodes) {
        match mesh.physics {
            Physics::SolidMesh => {
                // On a node of its own beside the visible one, as the boxes: Godot 4 turns a
                // node that holds a collider into a body and drops the mesh on it.
                let index = shape(serde_json::json!({
                    "type": "trimesh",
                    "trimesh": {"mesh": mesh_index.value()},
                }));
                let visible = &root.nodes[node.value()];
                extra_nodes.push(json::Node {
                    name: Some(format!("{}_collider", mesh.name)),
                    translation: visible.translation,
                    rotation: visible.rotation,
                    scale: visible.scale,
                    extensions: body("collider", index),
                    ..Default::default()
                });
            }
            Physics::SolidCylinder {
                base,
                radius,
                height,
            } => {
                let index = shape(serde_json::json!({
                    "type": "cylinder",
                    "cylinder": cylinder(radius, height),
                }));
                extra_nodes.push(json::Node {
                    name: Some(format!("{}_collider", mesh.name)),
                    translation: Some([base[0], base[1] + 0.5 * height, base[2]].map(|c| c as f32)),
                    extensions: body("collider", index),
                    ..Default::default()
                });
            }
            _ => {}
        }
    }
    for (point, &node) in scene.points.iter().zip(point_nodes) {
        if let Physics::TriggerBox { size } = point.physics {
            let index = shape(serde_json::json!({"type": "box", "box": {"size": size}}));
            root.nodes[node.value()].extensions = body("trigger", index);
        }
    }
    if shapes.is_empty() {
        return;
    }
    for node in extra_nodes {
        nodes.push(root.push(node));
    }
    let mut extensions = json::extensions::root::Root::default();
    extensions
        .others
        .insert(OMI_SHAPE.into(), serde_json::json!({ "shapes": shapes }));
    root.extensions = Some(extensions);
    root.extensions_used = vec![OMI_BODY.into(), OMI_SHAPE.into()];
}

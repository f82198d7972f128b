//! The glTF physics extensions: colliders and the finish trigger, for engines that read them, as
//! `OMI_physics_shape` / `OMI_physics_body`, as the Khronos drafts `KHR_implicit_shapes` /
//! `KHR_physics_rigid_bodies`, or both ([`PhysicsExtensions`]).

use gltf_json as json;
use serde_json::{Value, json};

use super::box_rotation;
use crate::level::scene::{Physics, PhysicsExtensions, Scene};

/// The glTF physics extensions written (Godot 4 reads them; other tools keep or ignore them).
pub const OMI_BODY: &str = "OMI_physics_body";
/// The shapes' extension.
pub const OMI_SHAPE: &str = "OMI_physics_shape";
/// The Khronos draft of rigid bodies (colliders, triggers), written with `--physics khr|both`.
pub const KHR_BODY: &str = "KHR_physics_rigid_bodies";
/// The Khronos draft of implicit shapes (boxes, cylinders) that [`KHR_BODY`] colliders name.
pub const KHR_SHAPES: &str = "KHR_implicit_shapes";

/// What a collider or the trigger is made of, before an extension writes it.
enum Geometry {
    /// A box of these full extents, centred on its node.
    Box([f64; 3]),
    /// An upright cylinder centred on its node.
    Cylinder { radius: f64, height: f64 },
    /// The triangles of `mesh`, which `node` (the visible node, untransformed) draws.
    Mesh {
        node: json::Index<json::Node>,
        mesh: json::Index<json::Mesh>,
    },
}

/// Where a collider or the trigger goes.
enum Target {
    /// A `<name>_collider` node of its own, pushed after the scene's nodes.
    New(Box<json::Node>),
    /// A node that is already there (`finish_zone`).
    Existing(json::Index<json::Node>),
}

/// One collider or trigger: its node, `collider` or `trigger`, and its geometry.
struct Body {
    target: Target,
    role: &'static str,
    geometry: Geometry,
}

/// An `OMI_physics_shape` cylinder: `radiusBottom` and `radiusTop` as the current
/// specification reads them, and `radius` as Godot 4 reads them.
fn cylinder(radius: f64, height: f64) -> Value {
    json!({
        "radius": radius,
        "radiusBottom": radius,
        "radiusTop": radius,
        "height": height,
    })
}

/// Pushes `value` onto `list` and gives its index.
fn push(list: &mut Vec<Value>, value: Value) -> usize {
    list.push(value);
    list.len() - 1
}

/// The `OMI_physics_shape` shape of `geometry` (a mesh is a `trimesh` of its mesh index).
fn omi_shape(geometry: &Geometry) -> Value {
    match *geometry {
        Geometry::Box(size) => json!({"type": "box", "box": {"size": size}}),
        Geometry::Cylinder { radius, height } => {
            json!({"type": "cylinder", "cylinder": cylinder(radius, height)})
        }
        Geometry::Mesh { mesh, .. } => {
            json!({"type": "trimesh", "trimesh": {"mesh": mesh.value()}})
        }
    }
}

/// The `KHR_physics_rigid_bodies` `geometry` of `geometry`: a box or cylinder is a
/// `KHR_implicit_shapes` shape pushed onto `shapes`, a mesh is the node that draws it (the
/// draft's `geometry.node`; without `convexHull`, its triangles as they are).
fn khr_geometry(geometry: &Geometry, shapes: &mut Vec<Value>) -> Value {
    let shape = match *geometry {
        Geometry::Box(size) => json!({"type": "box", "box": {"size": size}}),
        Geometry::Cylinder { radius, height } => json!({
            "type": "cylinder",
            "cylinder": {"height": height, "radiusBottom": radius, "radiusTop": radius},
        }),
        Geometry::Mesh { node, .. } => return json!({"node": node.value()}),
    };
    json!({"shape": push(shapes, shape)})
}

/// The scene's colliders and its trigger, in the order the files list them: a box collider node
/// beside each block and box obstacle (unscaled, as physics engines want), a cylinder beside
/// each cylinder obstacle, the road segments' own meshes as triangle meshes beside each segment,
/// a box trigger on the finish zone (where the game counts success).
fn bodies(
    scene: &Scene,
    root: &json::Root,
    mesh_nodes: &[(json::Index<json::Node>, json::Index<json::Mesh>)],
    point_nodes: &[json::Index<json::Node>],
) -> Vec<Body> {
    let collider = |name: &str, node: json::Node, geometry| Body {
        target: Target::New(Box::new(json::Node {
            name: Some(format!("{name}_collider")),
            ..node
        })),
        role: "collider",
        geometry,
    };
    let mut bodies = Vec::new();
    for node in &scene.nodes {
        if node.physics == Physics::SolidBox {
            let placed = json::Node {
                translation: Some(node.centre.map(|c| c as f32)),
                rotation: box_rotation(node.heading),
                ..Default::default()
            };
            bodies.push(collider(&node.name, placed, Geometry::Box(node.extents)));
        }
    }
    for (mesh, &(node, mesh_index)) in scene.meshes.iter().zip(mesh_nodes) {
        match mesh.physics {
            Physics::SolidMesh => {
                // On a node of its own beside the visible one, as the boxes: Godot 4 turns a
                // node that holds a collider into a body and drops the mesh on it.
                let visible = &root.nodes[node.value()];
                let placed = json::Node {
                    translation: visible.translation,
                    rotation: visible.rotation,
                    scale: visible.scale,
                    ..Default::default()
                };
                let geometry = Geometry::Mesh {
                    node,
                    mesh: mesh_index,
                };
                bodies.push(collider(&mesh.name, placed, geometry));
            }
            Physics::SolidCylinder {
                base,
                radius,
                height,
            } => {
                let placed = json::Node {
                    translation: Some([base[0], base[1] + 0.5 * height, base[2]].map(|c| c as f32)),
                    ..Default::default()
                };
                let geometry = Geometry::Cylinder { radius, height };
                bodies.push(collider(&mesh.name, placed, geometry));
            }
            _ => {}
        }
    }
    for (point, &node) in scene.points.iter().zip(point_nodes) {
        if let Physics::TriggerBox { size } = point.physics {
            bodies.push(Body {
                target: Target::Existing(node),
                role: "trigger",
                geometry: Geometry::Box(size),
            });
        }
    }
    bodies
}

/// Colliders and the finish trigger ([`bodies`]) as the physics extensions the scene asks for,
/// used and not required (Godot 4 imports the OMI ones as static bodies and areas). With both,
/// each collider node carries both. Collider nodes are pushed after `nodes`' existing ones.
pub(super) fn physics(
    scene: &Scene,
    root: &mut json::Root,
    nodes: &mut Vec<json::Index<json::Node>>,
    mesh_nodes: &[(json::Index<json::Node>, json::Index<json::Mesh>)],
    point_nodes: &[json::Index<json::Node>],
) {
    let bodies = bodies(scene, root, mesh_nodes, point_nodes);
    if bodies.is_empty() {
        return;
    }
    let (omi, khr) = match scene.physics_extensions {
        PhysicsExtensions::Omi => (true, false),
        PhysicsExtensions::Khr => (false, true),
        PhysicsExtensions::Both => (true, true),
    };
    let mut omi_shapes = Vec::new();
    let mut khr_shapes = Vec::new();
    for body in bodies {
        let mut extensions = json::extensions::scene::Node::default();
        if omi {
            let shape = push(&mut omi_shapes, omi_shape(&body.geometry));
            let value = json!({ body.role: { "shape": shape } });
            extensions.others.insert(OMI_BODY.into(), value);
        }
        if khr {
            let geometry = khr_geometry(&body.geometry, &mut khr_shapes);
            let value = json!({ body.role: { "geometry": geometry } });
            extensions.others.insert(KHR_BODY.into(), value);
        }
        match body.target {
            Target::New(node) => nodes.push(root.push(json::Node {
                extensions: Some(extensions),
                ..*node
            })),
            Target::Existing(node) => root.nodes[node.value()].extensions = Some(extensions),
        }
    }
    let mut extensions = json::extensions::root::Root::default();
    let mut used: Vec<&str> = Vec::new();
    if omi {
        let value = json!({ "shapes": omi_shapes });
        extensions.others.insert(OMI_SHAPE.into(), value);
        used.extend([OMI_BODY, OMI_SHAPE]);
    }
    if khr {
        // The draft's shapes array has at least one shape: none when every collider is a mesh.
        if !khr_shapes.is_empty() {
            let value = json!({ "shapes": khr_shapes });
            extensions.others.insert(KHR_SHAPES.into(), value);
            used.push(KHR_SHAPES);
        }
        used.push(KHR_BODY);
    }
    root.extensions = Some(extensions);
    root.extensions_used = used.into_iter().map(String::from).collect();
}

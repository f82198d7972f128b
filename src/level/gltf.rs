//! glTF 2.0 export of a [`Scene`] with gltf-json: `.glb` (one binary file) or `.gltf` with a
//! separate `.bin`. Y up, metres. All boxes share one unit-cube mesh per material; each node
//! places, turns and scales it, and carries the block's parameters in its `extras`.

use std::collections::BTreeMap;

use gltf_json as json;
use json::validation::{Checked::Valid, USize64};

use super::scene::{Material, Scene};

/// A `.gltf` document and the `.bin` buffer it refers to.
#[derive(Debug, Clone, PartialEq)]
pub struct GltfOutput {
    /// The `.gltf` JSON text.
    pub main: Vec<u8>,
    /// The `.bin` buffer.
    pub bin: Vec<u8>,
}

/// The scene as a single `.glb`.
pub fn to_glb(scene: &Scene) -> Vec<u8> {
    let buffer = cube_buffer();
    let root = document(scene, buffer.len(), None);
    let json = json::serialize::to_vec(&root).expect("a glTF document always serializes");
    glb_container(json, buffer)
}

/// The scene as `.gltf` JSON whose buffer is the file `bin_uri` (a name relative to it).
pub fn to_gltf(scene: &Scene, bin_uri: &str) -> GltfOutput {
    let buffer = cube_buffer();
    let root = document(scene, buffer.len(), Some(bin_uri.to_string()));
    let json = json::serialize::to_vec_pretty(&root).expect("a glTF document always serializes");
    GltfOutput {
        main: json,
        bin: buffer,
    }
}

const CUBE_VERTICES: usize = 24;
const CUBE_INDICES: usize = 36;
const VEC3_BYTES: usize = 12;

/// Positions, then normals, then u16 indices of a unit cube centred on the origin: four
/// vertices per face so that each face has its own normal.
fn cube_buffer() -> Vec<u8> {
    let mut positions = Vec::with_capacity(CUBE_VERTICES);
    let mut normals = Vec::with_capacity(CUBE_VERTICES);
    let mut indices: Vec<u16> = Vec::with_capacity(CUBE_INDICES);
    for axis in 0..3 {
        for sign in [1.0f32, -1.0] {
            let mut n = [0.0f32; 3];
            n[axis] = sign;
            // (u, v, n) right-handed, so the corners below run counter-clockwise seen from outside.
            let (u, v) = if sign > 0.0 {
                ((axis + 1) % 3, (axis + 2) % 3)
            } else {
                ((axis + 2) % 3, (axis + 1) % 3)
            };
            let base = positions.len() as u16;
            for (su, sv) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                let mut p = [0.0f32; 3];
                p[axis] = 0.5 * sign;
                p[u] = 0.5 * su;
                p[v] = 0.5 * sv;
                positions.push(p);
                normals.push(n);
            }
            indices.extend([0, 1, 2, 0, 2, 3].map(|k| base + k));
        }
    }
    let mut bytes = Vec::with_capacity(2 * CUBE_VERTICES * VEC3_BYTES + 2 * CUBE_INDICES);
    for v in positions.iter().chain(&normals).flatten() {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    for i in &indices {
        bytes.extend_from_slice(&i.to_le_bytes());
    }
    bytes
}

fn document(scene: &Scene, buffer_length: usize, uri: Option<String>) -> json::Root {
    let mut root = json::Root {
        asset: json::Asset {
            generator: Some(format!("arlpcg {}", env!("CARGO_PKG_VERSION"))),
            ..Default::default()
        },
        ..Default::default()
    };
    let buffer = root.push(json::Buffer {
        byte_length: USize64::from(buffer_length),
        name: Some("unit_cube".into()),
        uri,
        extensions: None,
        extras: None,
    });
    let vertex_bytes = CUBE_VERTICES * VEC3_BYTES;
    let mut view = |offset: usize, length: usize, target, name: &str| {
        root.push(json::buffer::View {
            buffer,
            byte_length: USize64::from(length),
            byte_offset: Some(USize64::from(offset)),
            byte_stride: None,
            name: Some(name.into()),
            target: Some(Valid(target)),
            extensions: None,
            extras: None,
        })
    };
    let positions_view = view(
        0,
        vertex_bytes,
        json::buffer::Target::ArrayBuffer,
        "positions",
    );
    let normals_view = view(
        vertex_bytes,
        vertex_bytes,
        json::buffer::Target::ArrayBuffer,
        "normals",
    );
    let indices_view = view(
        2 * vertex_bytes,
        2 * CUBE_INDICES,
        json::buffer::Target::ElementArrayBuffer,
        "indices",
    );
    let accessor =
        |view, count: usize, component, type_, bounds: Option<(f32, f32)>, name: &str| {
            json::Accessor {
                buffer_view: Some(view),
                byte_offset: None,
                count: USize64::from(count),
                component_type: Valid(json::accessor::GenericComponentType(component)),
                extensions: None,
                extras: None,
                type_: Valid(type_),
                min: bounds.map(|(lo, _)| json::Value::from(vec![lo; 3])),
                max: bounds.map(|(_, hi)| json::Value::from(vec![hi; 3])),
                name: Some(name.into()),
                normalized: false,
                sparse: None,
            }
        };
    use json::accessor::{ComponentType, Type};
    let positions = root.push(accessor(
        positions_view,
        CUBE_VERTICES,
        ComponentType::F32,
        Type::Vec3,
        Some((-0.5, 0.5)),
        "positions",
    ));
    let normals = root.push(accessor(
        normals_view,
        CUBE_VERTICES,
        ComponentType::F32,
        Type::Vec3,
        None,
        "normals",
    ));
    let indices = root.push(accessor(
        indices_view,
        CUBE_INDICES,
        ComponentType::U16,
        Type::Scalar,
        None,
        "indices",
    ));

    let mut meshes = BTreeMap::new();
    for material in Material::ALL {
        if !scene.nodes.iter().any(|n| n.material == material) {
            continue;
        }
        let material_index = root.push(json::Material {
            name: Some(material.name().into()),
            pbr_metallic_roughness: json::material::PbrMetallicRoughness {
                base_color_factor: json::material::PbrBaseColorFactor(material.colour()),
                metallic_factor: json::material::StrengthFactor(0.0),
                roughness_factor: json::material::StrengthFactor(0.8),
                ..Default::default()
            },
            ..Default::default()
        });
        let mesh = root.push(json::Mesh {
            name: Some(material.name().into()),
            primitives: vec![json::mesh::Primitive {
                attributes: BTreeMap::from([
                    (Valid(json::mesh::Semantic::Positions), positions),
                    (Valid(json::mesh::Semantic::Normals), normals),
                ]),
                extensions: None,
                extras: None,
                indices: Some(indices),
                material: Some(material_index),
                mode: Valid(json::mesh::Mode::Triangles),
                targets: None,
            }],
            weights: None,
            extensions: None,
            extras: None,
        });
        meshes.insert(material, mesh);
    }

    let nodes = scene
        .nodes
        .iter()
        .map(|node| {
            let half = (node.heading.to_radians() / 2.0) as f32;
            root.push(json::Node {
                name: Some(node.name.clone()),
                mesh: Some(meshes[&node.material]),
                translation: Some(node.centre.map(|c| c as f32)),
                rotation: (node.heading != 0.0)
                    .then(|| json::scene::UnitQuaternion([0.0, half.sin(), 0.0, half.cos()])),
                scale: Some(node.extents.map(|e| e as f32)),
                extras: node.extras.as_ref().map(raw),
                ..Default::default()
            })
        })
        .collect();
    let scene_index = root.push(json::Scene {
        name: Some(scene.name.clone()),
        nodes,
        extensions: None,
        extras: Some(raw(&scene.extras)),
    });
    root.scene = Some(scene_index);
    root
}

fn raw(value: &serde_json::Value) -> Box<serde_json::value::RawValue> {
    serde_json::value::to_raw_value(value).expect("JSON values always serialize")
}

/// Wraps JSON and binary chunks in the GLB container (glTF 2.0, section 4.4).
fn glb_container(mut json: Vec<u8>, mut bin: Vec<u8>) -> Vec<u8> {
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}

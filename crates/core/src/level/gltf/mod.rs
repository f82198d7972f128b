//! glTF 2.0 export of a [`Scene`] with gltf-json: `.glb` (one binary file) or `.gltf` with a
//! separate `.bin`. Y up, metres. All boxes share one unit-cube mesh per material; each node
//! places, turns and scales it, and carries the block's parameters in its `extras`.

use std::collections::BTreeMap;

use gltf_json as json;
use json::validation::{Checked::Valid, USize64};

mod physics;

use super::scene::{Material, Scene};
use physics::physics;
pub use physics::{KHR_BODY, KHR_SHAPES, OMI_BODY, OMI_SHAPE};

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
    let (buffer, layout) = scene_buffer(scene);
    let root = document(scene, buffer.len(), &layout, None);
    let json = json::serialize::to_vec(&root).expect("a glTF document always serializes");
    glb_container(json, buffer)
}

/// The scene as `.gltf` JSON whose buffer is the file `bin_uri` (a name relative to it).
pub fn to_gltf(scene: &Scene, bin_uri: &str) -> GltfOutput {
    let (buffer, layout) = scene_buffer(scene);
    let root = document(scene, buffer.len(), &layout, Some(bin_uri.to_string()));
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

/// Where one primitive of a [`SceneMesh`](super::scene::SceneMesh) lies in the buffer.
struct PrimitiveLayout {
    vertices: usize,
    triangles: usize,
    positions: usize,
    normals: usize,
    uvs: usize,
    indices: usize,
    /// Bounds of its positions.
    min: [f32; 3],
    max: [f32; 3],
}

/// The unit cube, then each mesh primitive's positions, normals, UVs and u32 indices (every
/// piece a multiple of 4 bytes, so each stays aligned).
fn scene_buffer(scene: &Scene) -> (Vec<u8>, Vec<Vec<PrimitiveLayout>>) {
    let mut bytes = cube_buffer();
    let mut put = |values: &mut dyn Iterator<Item = [u8; 4]>| {
        let start = bytes.len();
        for v in values {
            bytes.extend_from_slice(&v);
        }
        start
    };
    let layout = scene
        .meshes
        .iter()
        .map(|mesh| {
            mesh.primitives
                .iter()
                .map(|(m, _)| {
                    let mut min = [f32::INFINITY; 3];
                    let mut max = [f32::NEG_INFINITY; 3];
                    for p in &m.positions {
                        for k in 0..3 {
                            min[k] = min[k].min(p[k]);
                            max[k] = max[k].max(p[k]);
                        }
                    }
                    PrimitiveLayout {
                        vertices: m.positions.len(),
                        triangles: m.triangles.len(),
                        positions: put(&mut m.positions.iter().flatten().map(|v| v.to_le_bytes())),
                        normals: put(&mut m.normals.iter().flatten().map(|v| v.to_le_bytes())),
                        uvs: put(&mut m.uvs.iter().flatten().map(|v| v.to_le_bytes())),
                        indices: put(&mut m.triangles.iter().flatten().map(|v| v.to_le_bytes())),
                        min,
                        max,
                    }
                })
                .collect()
        })
        .collect();
    (bytes, layout)
}

fn document(
    scene: &Scene,
    buffer_length: usize,
    layout: &[Vec<PrimitiveLayout>],
    uri: Option<String>,
) -> json::Root {
    let mut root = json::Root {
        asset: json::Asset {
            generator: Some(format!("arlpcg {}", env!("CARGO_PKG_VERSION"))),
            ..Default::default()
        },
        ..Default::default()
    };
    let buffer = root.push(json::Buffer {
        byte_length: USize64::from(buffer_length),
        name: Some(
            if scene.meshes.is_empty() {
                "unit_cube"
            } else {
                "geometry"
            }
            .into(),
        ),
        uri,
        extensions: None,
        extras: None,
    });
    let (materials, cube_meshes) = materials_and_cube_meshes(scene, &mut root, buffer);
    let mut nodes: Vec<json::Index<json::Node>> = scene
        .nodes
        .iter()
        .map(|node| {
            root.push(json::Node {
                name: Some(node.name.clone()),
                mesh: Some(cube_meshes[&node.material]),
                translation: Some(node.centre.map(|c| c as f32)),
                rotation: box_rotation(node.heading),
                scale: Some(node.extents.map(|e| e as f32)),
                extras: node.extras.as_ref().map(raw),
                ..Default::default()
            })
        })
        .collect();
    let mut mesh_nodes = Vec::with_capacity(scene.meshes.len());
    for (mesh, parts) in scene.meshes.iter().zip(layout) {
        let primitives = mesh
            .primitives
            .iter()
            .zip(parts)
            .map(|((_, material), part)| {
                mesh_primitive(&mut root, buffer, &mesh.name, part, materials[material])
            })
            .collect();
        let mesh_index = root.push(json::Mesh {
            name: Some(mesh.name.clone()),
            primitives,
            weights: None,
            extensions: None,
            extras: None,
        });
        let node = root.push(json::Node {
            name: Some(mesh.name.clone()),
            mesh: Some(mesh_index),
            extras: mesh.extras.as_ref().map(raw),
            ..Default::default()
        });
        nodes.push(node);
        mesh_nodes.push((node, mesh_index));
    }
    let mut point_nodes = Vec::with_capacity(scene.points.len());
    for point in &scene.points {
        let node = root.push(json::Node {
            name: Some(point.name.clone()),
            translation: Some(point.position.map(|c| c as f32)),
            // Turned so that local +Z (glTF's forward) points along the heading.
            rotation: Some(about_y(point.heading + 90.0)),
            extras: Some(raw(&point.extras)),
            ..Default::default()
        });
        nodes.push(node);
        point_nodes.push(node);
    }
    physics(scene, &mut root, &mut nodes, &mesh_nodes, &point_nodes);
    let scene_index = root.push(json::Scene {
        name: Some(scene.name.clone()),
        nodes,
        extensions: None,
        extras: Some(raw(&scene.extras)),
    });
    root.scene = Some(scene_index);
    root
}

type MaterialIndices = BTreeMap<Material, json::Index<json::Material>>;
type MeshIndices = BTreeMap<Material, json::Index<json::Mesh>>;

/// The unit cube's views and accessors; a material and a cube mesh for each material the boxes
/// use, then a material for each further one the meshes use.
fn materials_and_cube_meshes(
    scene: &Scene,
    root: &mut json::Root,
    buffer: json::Index<json::Buffer>,
) -> (MaterialIndices, MeshIndices) {
    use json::accessor::{ComponentType, Type};
    use json::buffer::Target;
    let vertex_bytes = CUBE_VERTICES * VEC3_BYTES;
    let positions_view = push_view(
        root,
        buffer,
        0,
        vertex_bytes,
        Target::ArrayBuffer,
        "positions",
    );
    let normals_view = push_view(
        root,
        buffer,
        vertex_bytes,
        vertex_bytes,
        Target::ArrayBuffer,
        "normals",
    );
    let indices_view = push_view(
        root,
        buffer,
        2 * vertex_bytes,
        2 * CUBE_INDICES,
        Target::ElementArrayBuffer,
        "indices",
    );
    let positions = root.push(accessor(
        positions_view,
        CUBE_VERTICES,
        ComponentType::F32,
        Type::Vec3,
        Some((vec![-0.5; 3], vec![0.5; 3])),
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
    let mut materials = BTreeMap::new();
    let mut meshes = BTreeMap::new();
    for material in Material::ALL {
        if !scene.nodes.iter().any(|n| n.material == material) {
            continue;
        }
        let material_index = push_material(root, material);
        materials.insert(material, material_index);
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
    for material in Material::ALL {
        let used = scene
            .meshes
            .iter()
            .any(|m| m.primitives.iter().any(|(_, pm)| *pm == material));
        if used && !materials.contains_key(&material) {
            let index = push_material(root, material);
            materials.insert(material, index);
        }
    }
    (materials, meshes)
}

fn push_material(root: &mut json::Root, material: Material) -> json::Index<json::Material> {
    root.push(json::Material {
        name: Some(material.name().into()),
        pbr_metallic_roughness: json::material::PbrMetallicRoughness {
            base_color_factor: json::material::PbrBaseColorFactor(material.colour()),
            metallic_factor: json::material::StrengthFactor(0.0),
            roughness_factor: json::material::StrengthFactor(0.8),
            ..Default::default()
        },
        ..Default::default()
    })
}

/// One primitive of a mesh of the scene: its four views and accessors into the buffer.
fn mesh_primitive(
    root: &mut json::Root,
    buffer: json::Index<json::Buffer>,
    mesh_name: &str,
    part: &PrimitiveLayout,
    material: json::Index<json::Material>,
) -> json::mesh::Primitive {
    use json::accessor::{ComponentType, Type};
    use json::buffer::Target;
    let n = part.vertices;
    let name = |what: &str| format!("{mesh_name}_{what}");
    let positions_view = push_view(
        root,
        buffer,
        part.positions,
        n * 12,
        Target::ArrayBuffer,
        &name("positions"),
    );
    let normals_view = push_view(
        root,
        buffer,
        part.normals,
        n * 12,
        Target::ArrayBuffer,
        &name("normals"),
    );
    let uvs_view = push_view(
        root,
        buffer,
        part.uvs,
        n * 8,
        Target::ArrayBuffer,
        &name("uvs"),
    );
    let indices_view = push_view(
        root,
        buffer,
        part.indices,
        part.triangles * 12,
        Target::ElementArrayBuffer,
        &name("indices"),
    );
    let positions = root.push(accessor(
        positions_view,
        n,
        ComponentType::F32,
        Type::Vec3,
        Some((part.min.to_vec(), part.max.to_vec())),
        "positions",
    ));
    let normals = root.push(accessor(
        normals_view,
        n,
        ComponentType::F32,
        Type::Vec3,
        None,
        "normals",
    ));
    let uvs = root.push(accessor(
        uvs_view,
        n,
        ComponentType::F32,
        Type::Vec2,
        None,
        "uvs",
    ));
    let indices = root.push(accessor(
        indices_view,
        3 * part.triangles,
        ComponentType::U32,
        Type::Scalar,
        None,
        "indices",
    ));
    json::mesh::Primitive {
        attributes: BTreeMap::from([
            (Valid(json::mesh::Semantic::Positions), positions),
            (Valid(json::mesh::Semantic::Normals), normals),
            (Valid(json::mesh::Semantic::TexCoords(0)), uvs),
        ]),
        extensions: None,
        extras: None,
        indices: Some(indices),
        material: Some(material),
        mode: Valid(json::mesh::Mode::Triangles),
        targets: None,
    }
}

fn push_view(
    root: &mut json::Root,
    buffer: json::Index<json::Buffer>,
    offset: usize,
    length: usize,
    target: json::buffer::Target,
    name: &str,
) -> json::Index<json::buffer::View> {
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
}

/// An accessor of `count` elements in `view`; `bounds` its min and max, where given.
fn accessor(
    view: json::Index<json::buffer::View>,
    count: usize,
    component: json::accessor::ComponentType,
    type_: json::accessor::Type,
    bounds: Option<(Vec<f32>, Vec<f32>)>,
    name: &str,
) -> json::Accessor {
    let (min, max) = bounds
        .map(|(lo, hi)| (json::Value::from(lo), json::Value::from(hi)))
        .unzip();
    json::Accessor {
        buffer_view: Some(view),
        byte_offset: None,
        count: USize64::from(count),
        component_type: Valid(json::accessor::GenericComponentType(component)),
        extensions: None,
        extras: None,
        type_: Valid(type_),
        min,
        max,
        name: Some(name.into()),
        normalized: false,
        sparse: None,
    }
}

/// A rotation of `degrees` about +Y.
fn about_y(degrees: f64) -> json::scene::UnitQuaternion {
    let half = (degrees.to_radians() / 2.0) as f32;
    json::scene::UnitQuaternion([0.0, half.sin(), 0.0, half.cos()])
}

/// A box's rotation by its heading (none when it is not turned).
fn box_rotation(heading: f64) -> Option<json::scene::UnitQuaternion> {
    (heading != 0.0).then(|| about_y(heading))
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

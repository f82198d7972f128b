"""Checks the Khronos physics extensions of glTF exports (`arlpcg export --physics khr|both`)
against the drafts' JSON schemas vendored in .ci/khr-physics (see its README.md).

Usage: python check-khr-physics.py FILE.glb|FILE.gltf...

For each file: the document's `KHR_implicit_shapes` and `KHR_physics_rigid_bodies` objects and
every node's `KHR_physics_rigid_bodies` object validate against their schemas (JSON Schema
2020-12, with the `jsonschema` package); no object carries a property its schema does not
declare (the schemas allow any, so a misspelt field would pass them); a shape gives the
parameters of its own type only; every `geometry.shape` names an existing shape and every
`geometry.node` an existing node with a mesh; both extensions are in `extensionsUsed` and
neither in `extensionsRequired`; the file has at least one collider and one trigger. Each error
names the file and the JSON pointer. Exits 1 if any file has an error; ends with a summary line.
"""

import json
import struct
import sys
from pathlib import Path

from jsonschema import Draft202012Validator
from referencing import Registry, Resource

SCHEMA_DIR = Path(__file__).resolve().parent / "khr-physics"
SCHEMAS = {
    path.name: json.loads(path.read_text()) for path in SCHEMA_DIR.glob("*.schema.json")
}
REGISTRY = Registry().with_resources(
    (name, Resource.from_contents(schema)) for name, schema in SCHEMAS.items()
)
SHAPES = "KHR_implicit_shapes"
BODIES = "KHR_physics_rigid_bodies"
SHAPE_TYPES = ["plane", "sphere", "box", "capsule", "cylinder"]


def validator(name):
    return Draft202012Validator(SCHEMAS[name], registry=REGISTRY)


DOCUMENT_SHAPES = validator("glTF.KHR_implicit_shapes.schema.json")
DOCUMENT_BODIES = validator("glTF.KHR_physics_rigid_bodies.schema.json")
NODE_BODY = validator("node.KHR_physics_rigid_bodies.schema.json")


def referenced(prop):
    """The schema a property points at (`$ref`, or the first `$ref` of its `allOf`)."""
    refs = [prop.get("$ref")] + [part.get("$ref") for part in prop.get("allOf", [])]
    return next((SCHEMAS[r] for r in refs if r), None)


def properties(schema):
    """Every property a schema declares, with those of the schemas its `allOf` refers to."""
    declared = dict(schema.get("properties", {}))
    for part in schema.get("allOf", []):
        if "$ref" in part:
            declared = {**properties(SCHEMAS[part["$ref"]]), **declared}
    return declared


def undeclared(instance, schema, pointer):
    """Pointers to the properties of `instance` (and of the objects in it) that `schema` and the
    schemas it refers to do not declare."""
    if not isinstance(instance, dict):
        return []
    declared = properties(schema)
    found = []
    for key, value in instance.items():
        if key not in declared:
            found.append(f"{pointer}/{key}: not a property of {schema['$id']}")
            continue
        if key in ("extensions", "extras"):
            continue
        prop = declared[key]
        items = prop.get("items", {}) if prop.get("type") == "array" else None
        if items is not None and isinstance(value, list) and referenced(items):
            for i, item in enumerate(value):
                found += undeclared(item, referenced(items), f"{pointer}/{key}/{i}")
        elif referenced(prop):
            found += undeclared(value, referenced(prop), f"{pointer}/{key}")
    return found


def schema_errors(check, instance, pointer):
    return [
        f"{pointer}{''.join(f'/{p}' for p in error.absolute_path)}: {error.message}"
        for error in check.iter_errors(instance)
    ]


def read_document(path):
    data = path.read_bytes()
    if path.suffix == ".glb":
        length, kind = struct.unpack_from("<I4s", data, 12)
        if kind != b"JSON":
            raise ValueError("the first GLB chunk is not JSON")
        return json.loads(data[20 : 20 + length])
    return json.loads(data)


def shape_errors(shapes):
    errors = []
    for i, shape in enumerate(shapes):
        pointer = f"/extensions/{SHAPES}/shapes/{i}"
        kind = shape.get("type")
        others = [t for t in SHAPE_TYPES if t != kind and t in shape]
        if others:
            errors.append(f"{pointer}: a {kind} also gives {', '.join(others)}")
        for radii in (shape.get("cylinder"), shape.get("capsule")):
            if radii and radii.get("radiusTop", 0.25) == 0 and radii.get("radiusBottom", 0.25) == 0:
                errors.append(f"{pointer}: both radii are zero (a degenerate shape)")
    return errors


def check(path):
    root = read_document(path)
    errors = []
    extensions = root.get("extensions", {})
    shapes = extensions.get(SHAPES, {}).get("shapes", [])
    if SHAPES in extensions:
        errors += schema_errors(DOCUMENT_SHAPES, extensions[SHAPES], f"/extensions/{SHAPES}")
        schema = SCHEMAS["glTF.KHR_implicit_shapes.schema.json"]
        errors += undeclared(extensions[SHAPES], schema, f"/extensions/{SHAPES}")
        errors += shape_errors(shapes)
    if BODIES in extensions:
        errors += schema_errors(DOCUMENT_BODIES, extensions[BODIES], f"/extensions/{BODIES}")
        schema = SCHEMAS["glTF.KHR_physics_rigid_bodies.schema.json"]
        errors += undeclared(extensions[BODIES], schema, f"/extensions/{BODIES}")
    nodes = root.get("nodes", [])
    roles = {"collider": 0, "trigger": 0}
    for n, node in enumerate(nodes):
        body = node.get("extensions", {}).get(BODIES)
        if body is None:
            continue
        pointer = f"/nodes/{n}/extensions/{BODIES}"
        errors += schema_errors(NODE_BODY, body, pointer)
        errors += undeclared(body, SCHEMAS["node.KHR_physics_rigid_bodies.schema.json"], pointer)
        for role in roles:
            geometry = body.get(role, {}).get("geometry")
            if geometry is None:
                continue
            roles[role] += 1
            shape, mesh_node = geometry.get("shape"), geometry.get("node")
            if shape is not None and not (isinstance(shape, int) and 0 <= shape < len(shapes)):
                errors.append(f"{pointer}/{role}/geometry/shape: {shape} of {len(shapes)} shapes")
            if mesh_node is not None and not (
                isinstance(mesh_node, int)
                and 0 <= mesh_node < len(nodes)
                and "mesh" in nodes[mesh_node]
            ):
                errors.append(f"{pointer}/{role}/geometry/node: {mesh_node} is no node with a mesh")
    used, required = root.get("extensionsUsed", []), root.get("extensionsRequired", [])
    for name, present in [(SHAPES, SHAPES in extensions), (BODIES, sum(roles.values()) > 0)]:
        if present and name not in used:
            errors.append(f"/extensionsUsed: {name} is used but not listed")
        if name in required:
            errors.append(f"/extensionsRequired: {name} (the level loads without physics)")
    for role, count in roles.items():
        if count == 0:
            errors.append(f"/nodes: no {BODIES} {role}")
    return errors, roles


def main(files):
    bad = 0
    totals = {"collider": 0, "trigger": 0}
    for file in files:
        try:
            errors, roles = check(Path(file))
        except (OSError, ValueError, KeyError, struct.error) as error:
            errors, roles = [f"unreadable: {error}"], {}
        for role, count in roles.items():
            totals[role] += count
        if errors:
            bad += 1
            print(f"{file}:")
            for error in errors:
                print(f"  {error}")
    print(
        f"{len(files) - bad} of {len(files)} glTF files' KHR physics valid against the drafts' "
        f"schemas ({totals['collider']} colliders, {totals['trigger']} triggers)"
    )
    if bad or not files:
        print(f"{bad} file(s) failed the KHR physics check", file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main(sys.argv[1:])

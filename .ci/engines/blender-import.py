# Imports glTF exports into Blender headless and reports what a designer gets: mesh objects,
# empties (spawn, finish, colliders), and for every closed mesh whether it faces outward (signed
# volume > 0 with Blender's own normals from the winding). Exits 1 if a closed mesh faces inward
# or spawn/finish are missing.
#
#   blender --background --factory-startup --python .ci/engines/blender-import.py -- FILE.glb...
import sys

import bmesh
import bpy
import numpy

# Debian's Blender 3.4 glTF importer still uses `numpy.bool`, which numpy 1.24 removed.
if not hasattr(numpy, "bool"):
    numpy.bool = bool

files = sys.argv[sys.argv.index("--") + 1:]
bad = 0
for path in files:
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=path)
    meshes = [o for o in bpy.data.objects if o.type == "MESH"]
    empties = [o.name for o in bpy.data.objects if o.type == "EMPTY"]
    closed, inward = 0, []
    for obj in meshes:
        bm = bmesh.new()
        bm.from_mesh(obj.data)
        bmesh.ops.remove_doubles(bm, verts=bm.verts, dist=1e-5)
        if all(e.is_manifold for e in bm.edges):
            closed += 1
            if bm.calc_volume(signed=True) <= 0:
                inward.append(obj.name)
        bm.free()
    missing = [n for n in ("spawn", "finish", "finish_zone") if n not in empties]
    colliders = sum(1 for n in empties if n.endswith("_collider"))
    print(f"{path}: {len(meshes)} mesh objects ({closed} closed, {len(inward)} facing inward), "
          f"{len(empties)} empties ({colliders} colliders), missing: {missing or 'none'}")
    if inward or missing:
        bad += 1
        print(f"  inward: {inward}")
sys.exit(1 if bad else 0)

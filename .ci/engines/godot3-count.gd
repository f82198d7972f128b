# Run by godot3-import.sh inside a Godot 3 project whose glTF files are imported: reports per
# file the nodes Godot made (counts by class) and checks that every mesh named with the `-col`
# import hint got a static body with a collision shape, and that `spawn` and `finish` are there.
extends SceneTree

func tally(node, counts, problems):
	var kind = node.get_class()
	counts[kind] = counts.get(kind, 0) + 1
	if node is MeshInstance and node.name.ends_with("-col"):
		var bodies = 0
		for child in node.get_children():
			if child is StaticBody:
				for shape in child.get_children():
					if shape is CollisionShape and shape.shape != null:
						bodies += 1
		if bodies == 0:
			problems.append(node.name + " has no static body with a shape")
	for child in node.get_children():
		tally(child, counts, problems)

func _init():
	var failed = false
	var dir = Directory.new()
	dir.open("res://")
	dir.list_dir_begin(true, true)
	var name = dir.get_next()
	while name != "":
		if name.ends_with(".glb") or name.ends_with(".gltf"):
			var root = load("res://" + name).instance()
			var counts = {}
			var problems = []
			tally(root, counts, problems)
			for wanted in ["spawn", "finish"]:
				if root.find_node(wanted, true, false) == null:
					problems.append("no " + wanted + " node")
			print(name, ": ", to_json(counts))
			for problem in problems:
				print("  ", problem)
				failed = true
			root.free()
		name = dir.get_next()
	quit(1 if failed else 0)

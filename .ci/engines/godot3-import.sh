#!/usr/bin/env bash
# Imports glTF exports into Godot 3 headless (Debian's godot3-server) and reports what a
# designer gets: the nodes Godot made, by class (StaticBody and CollisionShape for the meshes
# exported with --collision-names). Exits 1 if a `-col` mesh got no collider or spawn/finish
# are missing.
#
#   bash .ci/engines/godot3-import.sh FILE.glb...
set -euo pipefail
godot="${GODOT:-godot3-server}"
project="$(mktemp -d)"
trap 'rm -rf "$project"' EXIT
printf 'config_version=4\n\n[application]\n\nconfig/name="arlpcg import check"\n' > "$project/project.godot"
cp "$@" "$project/"
cp "$(dirname "$0")/godot3-count.gd" "$project/"
# The editor imports every file it finds within seconds, but Godot 3.2's headless editor does
# not always come back from --quit (it spins in its shutdown): a time limit ends it.
timeout 60 "$godot" --path "$project" --editor --quit > "$project/import.log" 2>&1 || true
"$godot" --path "$project" -s godot3-count.gd 2> "$project/run.log"

#!/usr/bin/env bash
# make demo: summarise the bundled sample meshes (the extraction demo replaces this once
# `dispex extract` exists).
set -euo pipefail
build="${1:-build}"
root="$(cd "$(dirname "$0")/.." && pwd)"
dispex="$build/tools/dispex"
for mesh in tests/data/meshes/keenan_spot/spot_control_mesh.obj \
            tests/data/meshes/jerry_the_ogre/controlmesh.obj; do
  "$dispex" info "$root/$mesh"
  echo
done

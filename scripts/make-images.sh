#!/usr/bin/env bash
# Regenerates the README images docs/images/spot_atlas.png and docs/images/spot_compare.png
# from the demo asset: Spot's cage, a sculpt of it made by `dispex make-sculpt` (4 levels,
# 'detail' pattern, amplitude 0.005) and the map `dispex extract` takes from that sculpt.
# Usage: scripts/make-images.sh [build-dir]   (default: build; the dispex binary must exist)
set -euo pipefail
build="${1:-build}"
root="$(cd "$(dirname "$0")/.." && pwd)"
dispex="$root/$build/tools/dispex"
cage="$root/tests/data/meshes/keenan_spot/spot_control_mesh.obj"
images="$root/docs/images"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
mkdir -p "$images"

"$dispex" make-sculpt "$cage" --levels 4 --pattern detail --amplitude 0.005 \
  -o "$work/spot_sculpt.obj" -q
"$dispex" extract "$cage" "$work/spot_sculpt.obj" -o "$work/spot.ptx" -q
"$dispex" preview "$work/spot.ptx" -o "$images/spot_atlas.png" --mode signed
"$dispex" render "$cage" "$work/spot.ptx" --compare --sculpt "$work/spot_sculpt.obj" \
  --size 960x360 --view iso --ao 16 -o "$images/spot_compare.png"
ls -l "$images/spot_atlas.png" "$images/spot_compare.png"

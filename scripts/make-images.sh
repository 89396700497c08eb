#!/usr/bin/env bash
# Regenerates the README images docs/images/spot_atlas.png and docs/images/spot_compare.png
# from the demo asset: Spot's cage, a sculpt of it made by `dispex make-sculpt` (4 levels,
# 'detail' pattern, amplitude 0.005) and the map `dispex extract` takes from that sculpt; and
# docs/images/overhang_scalar.png, overhang_vector.png (docs/VECTOR.md): the 'overhang' sculpt
# (4 levels, amplitude 0.01) beside the base displaced by its scalar and its vector map.
# docs/images/spot_blender.png: the same asset rendered by Blender (Cycles, CPU): the limit
# surface, the base displaced by the UV-space map through Blender's modifiers, the sculpt
# (scripts/blender-render.py; skipped with a note when Blender is not installed).
# docs/images/spot_view.png: the review page `dispex view` writes of that asset, as Chromium
# headless draws it (scripts/view-screenshot.py; skipped with a note without Chromium).
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
"$dispex" extract "$cage" "$work/spot_sculpt.obj" -o "$work/spot.ptx" --uv-maps "$work/uv" \
  --report "$work/spot_report.json" -q
"$dispex" preview "$work/spot.ptx" -o "$images/spot_atlas.png" --mode signed
"$dispex" render "$cage" "$work/spot.ptx" --compare --sculpt "$work/spot_sculpt.obj" \
  --size 960x360 --view iso --ao 16 -o "$images/spot_compare.png"

"$dispex" verify "$cage" "$work/spot_sculpt.obj" "$work/spot.ptx" \
  --truth "$work/spot_sculpt.obj.truth" --report "$work/spot_verify.json" >/dev/null
"$dispex" view "$cage" "$work/spot.ptx" --sculpt "$work/spot_sculpt.obj" \
  --verify "$work/spot_verify.json" --extract-report "$work/spot_report.json" \
  -o "$work/spot_view.html" -q
status=0
python3 "$root/scripts/view-screenshot.py" "$work/spot_view.html" "$images/spot_view.png" \
  --state 'colour=displacement&azimuth=60&elevation=20&face=120' --size 960x540 || status=$?
if [[ $status == 77 ]]; then
  echo "make-images: chromium not installed: docs/images/spot_view.png left as it is" >&2
elif [[ $status != 0 ]]; then
  exit "$status"
fi

"$dispex" make-sculpt "$cage" --levels 4 --pattern overhang --amplitude 0.01 \
  -o "$work/overhang.obj" -q
"$dispex" extract "$cage" "$work/overhang.obj" -o "$work/overhang_scalar.ptx" -q
"$dispex" extract "$cage" "$work/overhang.obj" --vector object -o "$work/overhang_vector.ptx" -q
for kind in scalar vector; do
  "$dispex" render "$cage" "$work/overhang_$kind.ptx" --compare --sculpt "$work/overhang.obj" \
    --size 1050x350 --view left --elevation 10 -o "$images/overhang_$kind.png"
done
if command -v blender >/dev/null; then
  blender -b --factory-startup --python "$root/scripts/blender-render.py" -- "$cage" \
    "$work/uv/spot.<UDIM>.exr" "$work/spot_sculpt.obj" "$images/spot_blender.png" >/dev/null
else
  echo "make-images: blender not installed: docs/images/spot_blender.png left as it is" >&2
fi
ls -l "$images/spot_atlas.png" "$images/spot_compare.png" "$images"/overhang_*.png \
  "$images/spot_view.png"

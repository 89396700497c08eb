#!/usr/bin/env bash
# Regenerates the table of docs/ACCURACY.md: for each cage and pattern, a sculpt with known
# displacement is made, extracted with default options, and measured with verify --truth; then
# the image pattern (a height image through the cage's UVs) on the UV-mapped test cage.
#   scripts/accuracy.sh [build-dir]   (prints the Markdown table on stdout)
set -euo pipefail
build="${1:-build}"
root="$(cd "$(dirname "$0")/.." && pwd)"
dispex="$root/$build/tools/dispex"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
data="$root/tests/data/meshes"

# name | cage | levels | amplitude (object units)
cases=(
  "spot|keenan_spot/spot_control_mesh.obj|4|0.005"
  "blub|keenan_blub/blub_control_mesh.obj|4|0.004"
  "ogre|jerry_the_ogre/controlmesh.obj|3|0.0005"
  "torus_creases0|opensubdiv/catmark_torus_creases0.obj|4|0.01"
  "tent|opensubdiv/catmark_tent.obj|4|0.005"
  "bunny|stanford_bunny/bun_zipper_quadriflow_1000.obj|4|0.0005"
)
# name | cage under tests/data | levels | amplitude | height image under tests/data
image_cases=(
  "wavy_plane|image_pattern/wavy_plane.obj|4|0.02|image_pattern/heights.png"
)
json() { python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print($2)" "$1"; }

# One row: row NAME CAGE-PATH LEVELS AMPLITUDE PATTERN [LABEL]
row() {
  local name="$1" cage="$2" levels="$3" amplitude="$4" pattern="$5" label="${6:-$5}"
  local sculpt="$work/$name-${label//[^a-z]/_}.obj"
  local made linear folded quads tol misses texels tmax trms bound
  made=$("$dispex" make-sculpt "$cage" --levels "$levels" --pattern "$pattern" \
           --amplitude "$amplitude" -o "$sculpt" 2>&1)
  linear=$(sed -n 's/.*piecewise-linear error \([^,]*\),.*/\1/p' <<<"$made")
  folded=$(sed -n 's/.* \([0-9]*\) folded faces.*/\1/p' <<<"$made")
  quads=$(sed -n 's/.*vertices, \([0-9]*\) quads.*/\1/p' <<<"$made")
  "$dispex" extract "$cage" "$sculpt" -o "$work/map.ptx" --report "$work/r.json" -q
  "$dispex" verify "$cage" "$work/map.ptx" --truth "$sculpt.truth" \
    --report "$work/v.json" -q
  tol=$(json "$work/r.json" "d['statistics']['tolerance']")
  misses=$(json "$work/r.json" "d['statistics']['misses']")
  texels=$(json "$work/r.json" "'%d → %d (%.0f%%)' % (d['statistics']['texels']['oversampled'], d['statistics']['texels']['written'], 100*d['statistics']['texels']['written_fraction'])")
  tmax=$(json "$work/v.json" "'%.3g' % d['truth']['max']")
  trms=$(json "$work/v.json" "'%.3g' % d['truth']['rms']")
  bound=$(python3 -c "print('%.3g' % ($tol + 2*$linear))")
  printf '| %s | %s | %s | %s | %s | %s | %s | %.3g | %s | %s | %s | %s | %s |\n' \
    "$name" "$label" "$levels" "$amplitude" "$quads" "$folded" "$linear" "$tol" "$tmax" \
    "$trms" "$bound" "$misses" "$texels"
}

echo "| cage | pattern | level | amplitude | sculpt quads | folded | linear error e | tolerance τ | truth max | truth RMS | bound τ+2e | misses | texels oversampled → written |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|"
for c in "${cases[@]}"; do
  IFS='|' read -r name cage levels amplitude <<<"$c"
  for pattern in smooth detail ridges; do
    row "$name" "$data/$cage" "$levels" "$amplitude" "$pattern"
  done
done
for c in "${image_cases[@]}"; do
  IFS='|' read -r name cage levels amplitude image <<<"$c"
  row "$name" "$root/tests/data/$cage" "$levels" "$amplitude" "image:$root/tests/data/$image" \
    "image:$(basename "$image")"
done

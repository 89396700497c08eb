#!/usr/bin/env bash
# Regenerates the table of docs/ACCURACY.md: for each cage and pattern, a sculpt with known
# displacement is made (the cage refined L times, or a jittered triangulated grid of N x N cells
# per Ptex face), extracted with default options, and measured with verify --truth, whose
# bounds (docs/ACCURACY.md) every row must meet; then the image pattern (a height image through
# the cage's UVs) on the UV-mapped test cage.
#   scripts/accuracy.sh [--quick] [build-dir]
# Prints the Markdown table on stdout; exits 1, naming the rows, when a row breaks its bound.
# --quick: a reduced set (one refined and one jittered sculpt per small cage) for CI.
# ACCURACY_VERIFY_ARGS: more options for verify (e.g. "--truth-rms-factor 0.1" to see it fail).
set -euo pipefail
quick=0
if [[ "${1:-}" == "--quick" ]]; then
  quick=1
  shift
fi
build="${1:-build}"
root="$(cd "$(dirname "$0")/.." && pwd)"
dispex="$root/$build/tools/dispex"
[[ "$build" = /* ]] && dispex="$build/tools/dispex"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
data="$root/tests/data/meshes"

# name | cage | layout (L levels, or jN: jittered, density N) | amplitude (object units)
cases=(
  "spot|keenan_spot/spot_control_mesh.obj|4|0.005"
  "blub|keenan_blub/blub_control_mesh.obj|4|0.004"
  "ogre|jerry_the_ogre/controlmesh.obj|3|0.0005"
  "torus_creases0|opensubdiv/catmark_torus_creases0.obj|4|0.01"
  "tent|opensubdiv/catmark_tent.obj|4|0.005"
  "bunny|stanford_bunny/bun_zipper_quadriflow_1000.obj|4|0.0005"
  "spot|keenan_spot/spot_control_mesh.obj|j12|0.005"
  "blub|keenan_blub/blub_control_mesh.obj|j22|0.004"
  "torus_creases0|opensubdiv/catmark_torus_creases0.obj|j23|0.01"
  "tent|opensubdiv/catmark_tent.obj|j12|0.005"
)
patterns=(smooth detail ridges)
if ((quick)); then
  cases=(
    "tent|opensubdiv/catmark_tent.obj|3|0.005"
    "tent|opensubdiv/catmark_tent.obj|j12|0.005"
    "spot|keenan_spot/spot_control_mesh.obj|j6|0.005"
  )
  patterns=(detail)
fi
# name | cage under tests/data | layout | amplitude | height image under tests/data
image_cases=(
  "wavy_plane|image_pattern/wavy_plane.obj|4|0.02|image_pattern/heights.png"
  "wavy_plane|image_pattern/wavy_plane.obj|j12|0.02|image_pattern/heights.png"
)
((quick)) && image_cases=()
json() { python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print($2)" "$1"; }
failures=()

# One row: row NAME CAGE-PATH LAYOUT AMPLITUDE PATTERN [LABEL]
row() {
  local name="$1" cage="$2" layout="$3" amplitude="$4" pattern="$5" label="${6:-$5}"
  local sculpt="$work/$name-${label//[^a-z]/_}.obj"
  local made linear folded faces tol misses texels rule tmax trms tp99 over worst status
  local layout_args=(--levels "$layout") layout_label="L$layout"
  if [[ "$layout" == j* ]]; then
    layout_args=(--layout jittered --density "${layout#j}")
    layout_label="jittered ${layout#j}²"
  fi
  made=$("$dispex" make-sculpt "$cage" "${layout_args[@]}" --pattern "$pattern" \
           --amplitude "$amplitude" -o "$sculpt" 2>&1)
  linear=$(sed -n 's/.*piecewise-linear error \([^,]*\),.*/\1/p' <<<"$made")
  folded=$(sed -n 's/.* \([0-9]*\) folded faces.*/\1/p' <<<"$made")
  faces=$(sed -n 's/.*vertices, \([0-9]* [a-z]*\);.*/\1/p' <<<"$made")
  "$dispex" extract "$cage" "$sculpt" -o "$work/map.ptx" --report "$work/r.json" -q
  status=ok
  # shellcheck disable=SC2086
  if ! "$dispex" verify "$cage" "$work/map.ptx" --truth "$sculpt.truth" \
         --report "$work/v.json" -q ${ACCURACY_VERIFY_ARGS:-} 2>"$work/verify.err"; then
    [[ -s "$work/v.json" ]] || { cat "$work/verify.err" >&2; exit 2; }
    status="**FAILED**"
    failures+=("$name $label $layout_label: $(cat "$work/verify.err")")
  fi
  tol=$(json "$work/r.json" "d['statistics']['tolerance']")
  misses=$(json "$work/r.json" "d['statistics']['misses']")
  rule=$(json "$work/r.json" "d['statistics']['oversample_rule']")
  texels=$(json "$work/r.json" "'%d → %d (%.0f%%)' % (d['statistics']['texels']['oversampled'], d['statistics']['texels']['written'], 100*d['statistics']['texels']['written_fraction'])")
  tmax=$(json "$work/v.json" "'%.3g' % d['truth']['max']")
  trms=$(json "$work/v.json" "'%.2f' % (d['truth']['rms'] / d['truth']['bound']['tolerance'])")
  tp99=$(json "$work/v.json" "'%.2f' % (d['truth']['p99'] / d['truth']['bound']['tolerance'])")
  over=$(json "$work/v.json" "d['truth']['bound']['records_over']")
  worst=$(json "$work/v.json" "'%.2f' % d['truth']['bound']['worst_ratio']")
  printf '| %s | %s | %s | %s | %s | %s | %s | %.3g | %s | %s | %s | %s / %s | %s | %s | %s | %s |\n' \
    "$name" "$label" "$layout_label" "$amplitude" "$faces" "$folded" "$linear" "$tol" "$tmax" \
    "$trms" "$tp99" "$worst" "$over" "$misses" "$rule" "$texels" "$status"
}

echo "| cage | pattern | layout | amplitude | sculpt faces | folded | linear error e (max) | tolerance τ | truth max | RMS / τ | p99 / τ | worst \|err\| / (1.5τ+2e_v) / records over | misses | oversampling | texels oversampled → written | bounds |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
for c in "${cases[@]}"; do
  IFS='|' read -r name cage layout amplitude <<<"$c"
  for pattern in "${patterns[@]}"; do
    row "$name" "$data/$cage" "$layout" "$amplitude" "$pattern"
  done
done
for c in "${image_cases[@]}"; do
  IFS='|' read -r name cage layout amplitude image <<<"$c"
  row "$name" "$root/tests/data/$cage" "$layout" "$amplitude" "image:$root/tests/data/$image" \
    "image:$(basename "$image")"
done
if ((${#failures[@]})); then
  echo "accuracy.sh: ${#failures[@]} row(s) break their bound:" >&2
  printf '  %s\n' "${failures[@]}" >&2
  exit 1
fi

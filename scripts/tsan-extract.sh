#!/usr/bin/env bash
# make test-tsan: the TBB pipeline under ThreadSanitizer. A small sculpt is made, extracted (with
# watertight edges for the filter, then for both readers) and verified at 4 threads (more than this machine's cores, so tasks interleave) with the dispex
# binary of a -DDISPEX_TSAN=ON build, loading a libtbb built with TSan
# (scripts/build-tsan-tbb.sh) so that TBB's own hand-offs between threads are seen; any data
# race reported fails the run. Nothing is suppressed: libembree3 is not instrumented, so a TSan
# build runs Embree's BVH build on the calling thread alone, and one build or release of a scene
# at a time across threads (src/trace/embree_scene.cpp).
#   scripts/tsan-extract.sh [build-dir]
set -euo pipefail
build="${1:-build-tsan}"
root="$(cd "$(dirname "$0")/.." && pwd)"
dispex="$root/$build/tools/dispex"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
tbb="$root/$build/tbb/install/lib"
[[ -f "$tbb/libtbb.so.12" ]] || { echo "tsan-extract: no TSan libtbb in $tbb (scripts/build-tsan-tbb.sh)" >&2; exit 1; }
export LD_LIBRARY_PATH="$tbb${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
# ldd's list is read whole before it is searched: `ldd | grep -q` fails under pipefail whenever
# grep's early exit kills ldd with SIGPIPE (1 run in 11 on a busy 2-core machine).
libs=$(ldd "$dispex")
[[ $libs == *"=> $tbb/libtbb.so.12 "* ]] || { echo "tsan-extract: dispex does not load $tbb/libtbb.so.12" >&2; exit 1; }
export TSAN_OPTIONS="halt_on_error=1 exitcode=66 second_deadlock_stack=1"
cage="$root/tests/data/meshes/keenan_spot/spot_control_mesh.obj"
"$dispex" make-sculpt "$cage" --levels 3 --pattern detail --amplitude 0.005 \
  -o "$work/sculpt.obj" --threads 4 -q
"$dispex" extract "$cage" "$work/sculpt.obj" -o "$work/map.ptx" --threads 4 -q \
  --report "$work/report.json"
"$dispex" verify "$cage" "$work/sculpt.obj" "$work/map.ptx" --truth "$work/sculpt.obj.truth" \
  --threads 4 -q
# Watertight edges for both readers: faces re-extracted in rounds, edges measured in parallel.
"$dispex" extract "$cage" "$work/sculpt.obj" -o "$work/all.ptx" --watertight all --threads 4 -q
"$dispex" verify "$cage" "$work/all.ptx" --threads 4 -q
# Incremental: the previous map's faces copied in parallel, the local BVH (given search
# distance) after an edit of the sculpt.
"$dispex" extract "$cage" "$work/sculpt.obj" -o "$work/inc.ptx" --search-distance 1% \
  --incremental --threads 4 -q
sed -i '0,/^v /s/^v \([^ ]*\) /v 0.001 /' "$work/sculpt.obj"
"$dispex" extract "$cage" "$work/sculpt.obj" -o "$work/inc.ptx" --search-distance 1% \
  --incremental --threads 4 -q
# Shards and their merge; UV-space tiles rasterized in parallel.
for i in 1 2; do
  "$dispex" extract "$cage" "$work/sculpt.obj" -o "$work/part$i.ptx" --search-distance 1% \
    --shard $i/2 --threads 4 -q
done
"$dispex" merge "$work/part1.ptx" "$work/part2.ptx" -o "$work/merged.ptx" -q
"$dispex" extract "$cage" "$work/sculpt.obj" -o "$work/uv.ptx" --uv-maps "$work/uv" \
  --uv-resolution 128 --threads 4 -q
# An asset of two shapes: shapes in parallel, each extraction parallel inside.
# Two copies of a mesh as the o groups $2 and $3 (faces without their /vt/vn parts).
two_groups() {
  local n
  n=$(grep -c '^v ' "$1")
  for k in 0 1; do
    [[ $k == 0 ]] && echo "o $2" || echo "o $3"
    grep '^v ' "$1"
    awk -v n=$((k * n)) '/^f /{printf "f"; for (i = 2; i <= NF; ++i) printf " %d", $i + n; print ""}' "$1"
  done
}
two_groups "$cage" one two > "$work/asset.obj"
two_groups "$work/sculpt.obj" two one > "$work/asset_sculpt.obj"
"$dispex" extract "$work/asset.obj" "$work/asset_sculpt.obj" --out-dir "$work/maps" --threads 4 -q
# A vector map (its edge rounds re-extract faces in parallel), and the sculpt wound the other
# way (matched reversed, its faces reversed in place).
"$dispex" extract "$cage" "$work/sculpt.obj" -o "$work/vector.ptx" --vector tangent --threads 4 -q
awk '/^f /{printf "f"; for (i = NF; i >= 2; --i) printf " %s", $i; print ""; next} {print}' \
  "$work/sculpt.obj" > "$work/flipped.obj"
"$dispex" extract "$cage" "$work/flipped.obj" -o "$work/flipped.ptx" --threads 4 -q
echo "tsan-extract: make-sculpt, extract (filter and all, incremental, shards and merge, UV maps, two shapes, a vector map, a flipped sculpt) and verify at 4 threads ran without a data race"

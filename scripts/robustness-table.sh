#!/usr/bin/env bash
# Prints, for each class of bad input or option, the command run, its exit status and the
# one line dispex prints, then the count of the mesh readers' malformed test files: the block
# of docs/ROBUSTNESS.md between `<!-- robustness-table:begin` and `<!-- robustness-table:end -->`.
#   scripts/robustness-table.sh [--write] [build-dir]
# --write replaces that block of docs/ROBUSTNESS.md instead of printing it.
set -uo pipefail
write=0
build=build
for arg in "$@"; do
  case "$arg" in
    --write) write=1 ;;
    -*) echo "robustness-table: unknown option $arg" >&2; exit 2 ;;
    *) build="$arg" ;;
  esac
done
root="$(cd "$(dirname "$0")/.." && pwd)"
doc="$root/docs/ROBUSTNESS.md"
begin_marker='<!-- robustness-table:begin'
end_marker='<!-- robustness-table:end -->'
dispex="$root/$build/tools/dispex"
w="$(mktemp -d)"
trap 'chmod -R u+w "$w"; rm -rf "$w"' EXIT
cd "$w" || exit 1
cage="$root/tests/data/meshes/keenan_blub/blub_control_mesh.obj"
"$dispex" make-sculpt "$cage" --levels 2 --amplitude 0.004 -o sculpt.obj -q
printf '' > empty.obj
printf '\x7fELF\x02\x01\x01\x00\xff\xfe\x00\x13' > garbage.obj
printf 'solid x\nendsolid x\n' > mesh.stl
printf 'v 0 0 0\nv 1 0 nan\nv 0 1 0\nf 1 2 3\n' > nan.obj
printf 'v 0 0 0\nv 1 0 0\nv 0 inf 0\nv 1 1 0\nf 1 2 4 3\n' > inf.obj
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 2 4\nf 1 2 3 4\n' > degenerate.obj
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\n' > points.obj
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nf 1 2 3 4\nf 2 1 5 6\nf 1 2 6 5\nf 2 1 3 4\n' > nonmanifold.obj
# The sculpt's faces whose first vertex lies left of the middle: it covers half the base.
awk '/^v /{x[++n]=$2; lo=(n==1||$2<lo)?$2:lo; hi=(n==1||$2>hi)?$2:hi; print; next}
     /^f /{f[++m]=$0; split($2,a,"/"); k[m]=a[1]; next}
     END{for(i=1;i<=m;i++) if (x[k[i]] < (lo+hi)/2) print f[i]}' sculpt.obj > half.obj
printf 'v 100 100 100\nv 101 100 100\nv 101 101 100\nv 100 101 100\nf 1 2 3 4\n' > far.obj
printf 'ply\nformat binary_little_endian 1.0\nelement vertex 4294967295\nproperty float x\nend_header\n' > huge.ply
printf 'Ptex garbage' > garbage.ptx
mkdir -p adir
# One row. A failed run must leave nothing behind: no output and no temporary file (a
# successful run's output is removed before the next row).
leftovers=0
run() {
  local what="$1"; shift
  local err code
  err=$("$dispex" "$@" 2>&1 >/dev/null | head -n 3)
  code=${PIPESTATUS[0]}
  local command="$*"
  printf '| %s | `dispex %s` | %s | `%s` |\n' "$what" "${command//$root\//}" "$code" \
    "${err//$root\//}"
  if [[ $code -ne 0 ]] && ls | grep -qE '\.tmp\.|^out\.ptx$'; then
    echo "robustness-table: '$what' left files behind: $(ls | grep -E '\.tmp\.|^out\.ptx$')" >&2
    leftovers=1
  fi
  rm -f out.ptx
}
table() {
echo "| input class | command | exit | message |"
echo "|---|---|---|---|"
run "missing file" extract "$cage" missing.obj -o out.ptx
run "directory instead of a file" extract "$cage" adir -o out.ptx
run "empty file" extract "$cage" empty.obj -o out.ptx
run "binary garbage" extract "$cage" garbage.obj -o out.ptx
run "wrong extension / unknown format" extract "$cage" mesh.stl -o out.ptx
run "NaN coordinate" extract "$cage" nan.obj -o out.ptx
run "Inf coordinate" extract inf.obj sculpt.obj -o out.ptx
run "degenerate base face" extract degenerate.obj sculpt.obj -o out.ptx
run "base without faces" extract points.obj sculpt.obj -o out.ptx
run "non-manifold base" extract nonmanifold.obj sculpt.obj -o out.ptx
run "PLY claiming 4 billion vertices" info huge.ply
run "garbage Ptex" info garbage.ptx
run "sculpt not overlapping the base" extract "$cage" far.obj -o out.ptx
run "sculpt covering half the base" extract "$cage" half.obj -o out.ptx
run "zero search distance" extract "$cage" sculpt.obj -o out.ptx --search-distance 0
run "negative tolerance" extract "$cage" sculpt.obj -o out.ptx --tolerance -1
run "zero tolerance" extract "$cage" sculpt.obj -o out.ptx --tolerance 0
run "zero amplitude" make-sculpt "$cage" -o s.obj --amplitude 0
run "sculpt of another cage (match)" match "$root/tests/data/meshes/keenan_spot/spot_control_mesh.obj" sculpt.obj
run "sculpt off the limit surface (match)" match "$cage" sculpt.obj --max-offset 1e-9
run "non-manifold base (match)" match nonmanifold.obj sculpt.obj
run "unknown option" extract "$cage" sculpt.obj -o out.ptx --frobnicate
run "too little memory" extract "$cage" sculpt.obj -o out.ptx --max-memory 1K
run "output in a missing directory" extract "$cage" sculpt.obj -o nodir/out.ptx
run "output equal to an input" extract "$cage" sculpt.obj -o sculpt.obj
run "output is a directory" extract "$cage" sculpt.obj -o adir
if [[ $(id -u) -ne 0 ]]; then
  chmod 555 adir
  run "read-only output directory" extract "$cage" sculpt.obj -o adir/out.ptx
fi
# The malformed files tests/mesh/malformed_test.cpp reads, one expected message each (its
# EveryFileHasACase fails when a file there has none), counted rather than written down.
local malformed="$root/tests/data/malformed" total=0 obj=0 ply=0 f
for f in "$malformed"/*; do
  case "$f" in
    */README.md) continue ;;
    *.obj) obj=$((obj + 1)) ;;
    *.ply) ply=$((ply + 1)) ;;
  esac
  total=$((total + 1))
done
echo
echo "The mesh readers have their own suite of $total hand-made broken files in"
echo "\`tests/data/malformed/\` ($obj OBJ, $ply PLY, $((total - obj - ply)) of another format), each read at 1 and 2"
echo "threads and checked for its one-line message (\`tests/mesh/malformed_test.cpp\`)."
}

if [[ $write == 0 ]]; then
  table
  exit $leftovers
fi
if [[ $(grep -c "^$begin_marker" "$doc") != 1 || $(grep -c "^$end_marker" "$doc") != 1 ]]; then
  echo "robustness-table: $doc: needs one line starting '$begin_marker' and one '$end_marker'" >&2
  exit 1
fi
table >"$w/block.md"
[[ $leftovers == 0 ]] || exit $leftovers
new="$(mktemp "$doc.tmp.XXXXXX")"
awk -v begin="$begin_marker" -v end="$end_marker" -v block="$w/block.md" '
  index($0, begin) == 1 { print; print ""; while ((getline line < block) > 0) print line; print ""; skip = 1; next }
  skip && index($0, end) == 1 { skip = 0 }
  !skip { print }' "$doc" >"$new"
chmod --reference="$doc" "$new"
mv "$new" "$doc"
echo "robustness-table: $doc rewritten" >&2

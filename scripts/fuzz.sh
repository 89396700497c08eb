#!/usr/bin/env bash
# Builds the libFuzzer targets of fuzz/ with clang and runs each for a while, side by side.
#
#   scripts/fuzz.sh [SECONDS] [TARGET...]      TARGET: obj ply ptex (default: all three)
#
# SECONDS per target (default $FUZZ_SECONDS, else 300). Environment:
#   FUZZ_BUILD           build directory (default build-fuzz)
#   FUZZ_JOBS            build jobs (default 2)
#   FUZZ_PARALLEL        targets fuzzed at once (default: the number of cores)
#   FUZZ_WORK            where corpora, crash artifacts and logs go; kept and reused across
#                        runs when set (default: a temporary directory removed at exit)
#   FUZZ_SEED_MAX_BYTES  seed files larger than this are left out (default 65536)
#   FUZZ_MAX_LEN         longest input libFuzzer makes; longer seeds are truncated
#                        (default 16384: the readers' logic shows in small inputs, and short
#                        inputs run many times faster)
#   FUZZ_ARGS            extra libFuzzer flags (e.g. "-jobs=2 -workers=2")
#
# Seeds come from tests/data (meshes, malformed*, ptex*), fuzz/seeds and tests/fuzz_regressions;
# they are copied into the work directory, never written to. Exit status: 0 when no target
# crashed, 1 otherwise; every crash, timeout, leak or out-of-memory input is copied to
# tests/fuzz_regressions/<target>_fuzzer-<sha1 prefix> for triage (see fuzz/README.md).
set -euo pipefail

cd "$(dirname "$0")/.."
root=$(pwd)

seconds=${1:-${FUZZ_SECONDS:-300}}
[[ $# -gt 0 ]] && shift
targets=("$@")
[[ ${#targets[@]} -eq 0 ]] && targets=(obj ply ptex)
for t in "${targets[@]}"; do
  case $t in
    obj | ply | ptex) ;;
    *) echo "fuzz: unknown target '$t' (obj, ply or ptex)" >&2; exit 2 ;;
  esac
done
if ! [[ $seconds =~ ^[0-9]+$ ]] || [[ $seconds -eq 0 ]]; then
  echo "fuzz: SECONDS must be a positive integer (got '$seconds')" >&2
  exit 2
fi

build=${FUZZ_BUILD:-build-fuzz}
jobs=${FUZZ_JOBS:-2}
seed_max=${FUZZ_SEED_MAX_BYTES:-65536}
max_len=${FUZZ_MAX_LEN:-16384}
read -r -a extra_args <<<"${FUZZ_ARGS:-}"

if [[ -n ${FUZZ_WORK:-} ]]; then
  work=$FUZZ_WORK
  mkdir -p "$work"
else
  work=$(mktemp -d "${TMPDIR:-/tmp}/dispex-fuzz.XXXXXX")
  trap 'rm -rf "$work"' EXIT
fi

# clang and its libFuzzer runtime (Debian: clang, libclang-rt-14-dev), then the build.
DISPEX_WITH_FUZZ=1 scripts/install-deps.sh
CC=clang CXX=clang++ cmake -S . -B "$build" -DDISPEX_BUILD_FUZZ=ON -DDISPEX_BUILD_TESTS=OFF \
  -DDISPEX_BUILD_BENCH=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" \
  -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" >/dev/null  # line tables: as Makefile's sanitizers
cmake --build "$build" -j"$jobs" --target "${targets[@]/%/_fuzzer}" >/dev/null

# seed_files TARGET: the seed files of a target, one per line.
seed_files() {
  local ext=$1
  [[ $1 == ptex ]] && ext=ptx
  find tests/data -type f -name "*.$ext" -size "-$((seed_max + 1))c"
  [[ -d fuzz/seeds/$1 ]] && find "fuzz/seeds/$1" -type f
  [[ -d tests/fuzz_regressions ]] && find tests/fuzz_regressions -type f -name "$1_fuzzer-*"
  return 0
}

# fuzz_target TARGET: runs one target's fuzzer for $seconds; writes "ok" into its status file
# when it ran to the end and left no artifact (a missing "ok" is a failure).
fuzz_target() {
  local t=$1
  local name=${t}_fuzzer
  local corpus=$work/$t/corpus seeds=$work/$t/seeds artifacts=$work/$t/artifacts log=$work/$t/fuzz.log
  mkdir -p "$corpus" "$seeds" "$artifacts"
  rm -f "$artifacts"/* "$work/$t/status"
  seed_files "$t" | while read -r f; do cp "$f" "$seeds/"; done
  echo "fuzz: $name for ${seconds}s ($(ls "$seeds" | wc -l) seeds," \
    "$(ls "$corpus" | wc -l) in the working corpus)"

  # New inputs go to the first corpus directory; the seeds are read only.
  local rc=0
  "$build/fuzz/$name" -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=10 \
    -max_len="$max_len" -dict="fuzz/$t.dict" -artifact_prefix="$artifacts/" -print_final_stats=1 \
    "${extra_args[@]}" "$corpus" "$seeds" >"$log" 2>&1 || rc=$?

  local runs rss cov
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rss=$(sed -n 's/^stat::peak_rss_mb: *//p' "$log" | tail -1)
  cov=$(grep -aEo 'cov: [0-9]+ ft: [0-9]+ corp: [0-9]+/[0-9]+[a-zA-Z]*' "$log" | tail -1 || true)
  echo "fuzz: $name: ${runs:-?} runs, ${cov:-no coverage line}, $(ls "$corpus" | wc -l) files" \
    "in the working corpus, peak RSS ${rss:-?} MB, exit $rc"

  local found=0 a dest
  for a in "$artifacts"/crash-* "$artifacts"/leak-* "$artifacts"/timeout-* "$artifacts"/oom-*; do
    [[ -e $a ]] || continue
    found=1
    mkdir -p tests/fuzz_regressions
    dest=tests/fuzz_regressions/$name-$(sha1sum "$a" | cut -c1-16)
    cp "$a" "$dest"
    echo "fuzz: $name: $(basename "$a" | cut -d- -f1) input saved as $dest" >&2
  done
  if [[ $rc -ne 0 || $found -ne 0 ]]; then
    echo "fuzz: $name failed; from its log ($log):" >&2
    grep -a -m 30 -E 'contract broken|runtime error|ERROR:|SUMMARY:|#[0-9]+ 0x[0-9a-f]+ in dispex' \
      "$log" >&2 || true
  else
    echo ok >"$work/$t/status"
  fi
  return 0
}

# The targets run side by side, FUZZ_PARALLEL at a time (default: one per core), each on a
# core of its own for its $seconds: the same fuzzing as one after the other, in less time.
parallel=${FUZZ_PARALLEL:-$(nproc)}
running=0
for t in "${targets[@]}"; do
  if ((running >= parallel)); then
    wait -n || true
    running=$((running - 1))
  fi
  fuzz_target "$t" &
  running=$((running + 1))
done
wait || true
failed=()
for t in "${targets[@]}"; do
  [[ "$(cat "$work/$t/status" 2>/dev/null)" == ok ]] || failed+=("${t}_fuzzer")
done

if [[ -n ${FUZZ_WORK:-} ]]; then echo "fuzz: corpora and logs kept in $work"; fi
if [[ ${#failed[@]} -gt 0 ]]; then
  echo "fuzz: FAILED: ${failed[*]}" \
    "(reproduce: $build/fuzz/<target> tests/fuzz_regressions/<file>)" >&2
  exit 1
fi
echo "fuzz: no crash in ${targets[*]}"

#!/usr/bin/env bash
# Measures the README's figures and writes them into README.md, between the lines
# `<!-- figures:begin ...` and `<!-- figures:end -->`: in a fresh clone of the current commit (in
# a temporary folder), the wall time of `make demo`, then of `make test` after it, the number
# of tests ctest ran and their own time, with the date, the commit and the machine (cores, CPU
# model, memory, system, compiler).
#   scripts/readme-figures.sh [--dry-run] [--readme FILE] [--numbers TESTS:DEMO:TEST:CTEST]
# --dry-run            print the block, leave README.md as it is
# --readme FILE        the file to rewrite (default: README.md of this checkout)
# --numbers T:D:S:C    skip the measurement and use these figures (tests, then seconds of
#                      `make demo`, `make test` and ctest), to check the rewriting
# Only committed work is measured (the clone is of HEAD). The run takes both cores for about as
# long as the figures say; run it on an otherwise idle machine with the Debian packages already
# installed (`scripts/install-deps.sh`), as the README states. Exits non-zero, writing nothing,
# when a step or a test fails.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
readme="$root/README.md"
dry_run=0
numbers=""
while [[ $# -gt 0 ]]; do
  case "$1" in
    --dry-run) dry_run=1; shift ;;
    --readme) readme="$2"; shift 2 ;;
    --numbers) numbers="$2"; shift 2 ;;
    -h|--help) sed -n '2,15p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "readme-figures: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
done
begin_marker='<!-- figures:begin'
end_marker='<!-- figures:end -->'
if [[ $dry_run == 0 ]]; then
  [[ -f $readme ]] || { echo "readme-figures: $readme: no such file" >&2; exit 1; }
  if [[ $(grep -c "^$begin_marker" "$readme") != 1 || $(grep -c "^$end_marker" "$readme") != 1 ]]; then
    echo "readme-figures: $readme: needs one line starting '$begin_marker' and one '$end_marker'" >&2
    exit 1
  fi
fi

commit="$(git -C "$root" rev-parse HEAD)"
short="$(git -C "$root" rev-parse --short HEAD)"
if [[ -n "$(git -C "$root" status --porcelain --untracked-files=no)" ]]; then
  echo "readme-figures: the checkout has uncommitted changes; measuring $short as committed" >&2
fi

# Seconds as "3 min 33 s" (or "48 s").
duration() {
  local s
  s=$(printf '%.0f' "$1")
  if ((s >= 60)); then echo "$((s / 60)) min $((s % 60)) s"; else echo "$s s"; fi
}

now() { date +%s.%N; }

if [[ -n $numbers ]]; then
  IFS=: read -r tests demo_s test_s ctest_s <<<"$numbers"
  for v in "$tests" "$demo_s" "$test_s" "$ctest_s"; do
    [[ $v =~ ^[0-9]+(\.[0-9]+)?$ ]] || { echo "readme-figures: --numbers TESTS:DEMO:TEST:CTEST, got '$numbers'" >&2; exit 2; }
  done
else
  work="$(mktemp -d "${TMPDIR:-/tmp}/dispex-figures.XXXXXX")"
  trap 'rm -rf "$work"' EXIT
  echo "readme-figures: cloning $short into $work (load average $(cut -d' ' -f1-3 /proc/loadavg))" >&2
  git clone --quiet "$root" "$work/dispex"
  git -C "$work/dispex" checkout --quiet --detach "$commit"
  step() {  # step NAME: time `make NAME` in the clone into $elapsed; its output in $work/NAME.log
    echo "readme-figures: make $1 (log: $work/$1.log)" >&2
    local t0 status=0
    t0=$(now)
    make -C "$work/dispex" "$1" >"$work/$1.log" 2>&1 || status=$?
    if [[ $status != 0 ]]; then
      tail -n 30 "$work/$1.log" >&2
      echo "readme-figures: make $1 failed (exit $status); README not changed; logs kept in $work" >&2
      trap - EXIT
      exit 1
    fi
    elapsed=$(awk -v a="$t0" -v b="$(now)" 'BEGIN { printf "%.1f", b - a }')
  }
  step demo
  demo_s=$elapsed
  step test
  test_s=$elapsed
  # ctest's summary: "100% tests passed, 0 tests failed out of 1228", "Total Test time (real) = 108.35 sec"
  tests=$(sed -n 's/.*tests passed, 0 tests failed out of \([0-9][0-9]*\).*/\1/p' "$work/test.log" | tail -n 1)
  ctest_s=$(sed -n 's/^Total Test time (real) = *\([0-9.][0-9.]*\) sec.*/\1/p' "$work/test.log" | tail -n 1)
  if [[ -z $tests || -z $ctest_s ]]; then
    echo "readme-figures: no ctest summary in $work/test.log; README not changed; logs kept in $work" >&2
    trap - EXIT
    exit 1
  fi
fi

cores=$(nproc)
cpu=$(sed -n 's/^model name[[:space:]]*: *//p' /proc/cpuinfo | head -n 1)
memory=$(awk '/^MemTotal:/ {printf "%.1f GiB", $2 / 1048576}' /proc/meminfo)
# shellcheck disable=SC1091  # the running system's file
system=$(. /etc/os-release 2>/dev/null && echo "${PRETTY_NAME:-Linux}" || echo Linux)
cxx="${CXX:-c++}"
if "$cxx" --version 2>/dev/null | head -n 1 | grep -qi clang; then
  compiler="Clang $("$cxx" -dumpversion)"
else
  compiler="GCC $("$cxx" -dumpfullversion 2>/dev/null || "$cxx" -dumpversion)"
fi

block="$begin_marker: written by scripts/readme-figures.sh; run it again instead of editing -->

| in a fresh clone, packages installed | wall time |
|---|---|
| \`make demo\` (configure, build \`dispex\`, run the demo) | $(duration "$demo_s") |
| then \`make test\` (build the rest, run the $tests tests) | $(duration "$test_s") |
| of which the $tests tests (ctest) | $(duration "$ctest_s") |

Measured $(date +%Y-%m-%d) at commit $short on $cores cores ($cpu), $memory of memory,
$system, $compiler.

$end_marker"

if [[ $dry_run == 1 ]]; then
  echo "$block"
  exit 0
fi
tmp="$(mktemp "$readme.tmp.XXXXXX")"
BLOCK="$block" awk -v begin="$begin_marker" -v end="$end_marker" '
  index($0, begin) == 1 { print ENVIRON["BLOCK"]; skip = 1; next }
  skip && index($0, end) == 1 { skip = 0; next }
  !skip { print }' "$readme" >"$tmp"
chmod --reference="$readme" "$tmp"
mv "$tmp" "$readme"
echo "readme-figures: $readme: $tests tests, make demo $(duration "$demo_s"), make test $(duration "$test_s") at $short" >&2

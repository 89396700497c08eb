#!/usr/bin/env bash
# The farm on a real Slurm (docs/FARM.md): a one-node cluster on localhost (munged, slurmctld,
# slurmd; slurm_cluster.sh), a two-asset manifest submitted with `dispex farm slurm --shards 3
# --mem 3M`, one shard killed mid-run and put back in the queue (scontrol requeue: what a
# pre-emption or a failed node does), and the merged maps checked byte for byte against
# `dispex extract` on this machine. Both assets take the automatic search distance; spot goes
# through the subdivision correspondence with shards of the whole sculpt, blub through rays
# and is estimated at more than 3M, so its shards -- the killed one among them -- keep only
# their part of the sculpt. Skips (exit 77) when not root or when Slurm or munge is missing; always stops the
# daemons it started.
#   slurm_test.sh DISPEX DATA_DIR
set -u
dispex=$1
data=$2
here=$(cd "$(dirname "$0")" && pwd)

skip() {
  echo "SKIP: $*"
  exit 77
}
[ "$(id -u)" = 0 ] || skip "the Slurm test starts slurmd and munged, which need root"
for tool in munged slurmctld slurmd sbatch scontrol sinfo; do
  command -v "$tool" >/dev/null || skip "$tool is missing (Debian: slurm-wlm munge)"
done

fail() {
  echo "FAIL: $*"
  if [ -n "${array:-}" ]; then
    scontrol show job 2>/dev/null | grep -E 'JobId|JobState|Dependency|Restarts'
    tail -n 5 "$tmp"/jobs/logs/* 2>/dev/null
  fi
  exit 1
}

tmp=$(mktemp -d "${TMPDIR:-/tmp}/dispex-slurm.XXXXXX")
# shellcheck source=slurm_cluster.sh
source "$here/slurm_cluster.sh"
cleanup() {
  slurm_stop
  rm -rf "$tmp"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

slurm_start "$tmp/slurm" || fail "the Slurm cluster did not start"

# Two assets, their sculpts made here: spot's 2,928 quads, blub's 28,416.
cd "$tmp" || fail "no $tmp"
for asset in spot:2 blub:4; do
  name=${asset%:*}
  cp "$data/meshes/keenan_$name/${name}_control_mesh.obj" "$name.obj"
  "$dispex" make-sculpt "$name.obj" -o "${name}_sculpt.obj" --levels "${asset#*:}" \
    --amplitude 0.004 -q || fail "make-sculpt $name"
done
cat >manifest.json <<'JSON'
{"assets": [
   {"name": "spot", "base": "spot.obj", "sculpt": "spot_sculpt.obj", "output_dir": "maps"},
   {"name": "blub", "base": "blub.obj", "sculpt": "blub_sculpt.obj", "output_dir": "maps",
    "options": {"method": "rays", "data_type": "half"}}]}
JSON

# The jobs run dispex through a wrapper that holds shard task 4 (blub, shard 2/3) on its first
# run long enough to kill it mid-run; its re-run (SLURM_RESTART_COUNT 1) goes straight through.
cat >slow-dispex <<WRAP
#!/bin/bash
if [ "\${SLURM_ARRAY_TASK_ID:-}" = 4 ] && [ "\${SLURM_RESTART_COUNT:-0}" = 0 ]; then
  touch "$tmp/task4-started"
  sleep 60
fi
exec "$dispex" "\$@"
WRAP
chmod +x slow-dispex

ids=$("$dispex" farm slurm manifest.json --shards 3 --mem 3M --dispex "$tmp/slow-dispex" \
  --work-dir "$tmp/jobs" 2>farm.err) || fail "dispex farm slurm: $ids $(cat farm.err)"
echo "$ids"
cat farm.err
grep -q "asset blub: one extraction is estimated at .* more than --mem 3M" farm.err ||
  fail "the farm did not say that blub's shards keep their part"
grep -qx "sculpts=(whole part)" "$tmp/jobs/shards.sbatch" ||
  fail "shards.sbatch: expected spot's shards whole and blub's part: $(grep sculpts= "$tmp/jobs/shards.sbatch")"
array=$(awk '$1 == "shards" {print $2}' <<<"$ids")
merges=$(awk '$1 == "merge" {print $3}' <<<"$ids")
[ -n "$array" ] && [ "$(wc -w <<<"$merges")" = 2 ] || fail "unexpected output: $ids"

state() { scontrol show job "$1" 2>/dev/null | grep -o 'JobState=[A-Z_]*' | head -n 1 | cut -d= -f2; }

# Kill shard task 4 mid-run and put it back in the queue at once (a requeued job otherwise
# waits a while before it may start again).
for _ in $(seq 1 120); do
  [ -e "$tmp/task4-started" ] && [ "$(state "${array}_4")" = RUNNING ] && break
  sleep 0.5
done
[ "$(state "${array}_4")" = RUNNING ] || fail "shard task ${array}_4 never ran"
scontrol requeue "${array}_4" || fail "scontrol requeue ${array}_4"
for _ in $(seq 1 60); do
  if scontrol show job "${array}_4" | grep -q 'Reason=BeginTime'; then
    scontrol update JobId="${array}_4" StartTime=now
  fi
  [ "$(state "${array}_4")" = COMPLETED ] && break
  sleep 0.5
done

for merge in $merges; do
  for _ in $(seq 1 80); do
    case $(state "$merge") in
      COMPLETED) break ;;
      FAILED | CANCELLED | TIMEOUT | NODE_FAIL | OUT_OF_MEMORY)
        cat "$tmp"/jobs/logs/* 2>/dev/null
        fail "merge job $merge: $(state "$merge")"
        ;;
    esac
    sleep 0.5
  done
  [ "$(state "$merge")" = COMPLETED ] || fail "merge job $merge did not finish: $(state "$merge")"
done
restarts=$(scontrol show job "${array}_4" | grep -o 'Restarts=[0-9]*' | cut -d= -f2)
[ "${restarts:-0}" -ge 1 ] || fail "shard task ${array}_4 was not run again (restarts ${restarts:-0})"

# The maps one extraction writes, byte for byte.
"$dispex" extract spot.obj spot_sculpt.obj -o spot_expected.ptx -q || fail "extract spot"
"$dispex" extract blub.obj blub_sculpt.obj -o blub_expected.ptx --method rays --data-type half \
  -q || fail "extract blub"
for asset in spot blub; do
  cmp -s "maps/$asset.ptx" "${asset}_expected.ptx" ||
    fail "maps/$asset.ptx differs from a single-machine extraction"
done
ls "$tmp"/jobs/parts/*.ptx | wc -l | grep -qx 6 || fail "expected 6 parts"
echo "PASS: 2 assets x 3 shards on Slurm (blub's of part of its sculpt), shard ${array}_4" \
  "killed mid-run and requeued (restarts $restarts); merged maps identical to single-machine" \
  "extractions"

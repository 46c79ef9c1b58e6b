#!/usr/bin/env bash
# Benchmark of `surftex batch` (issue 20 goals): 50 jobs, the 22 meshes of
# ../shared/data/meshes and 3 swatch meshes, each by two methods (patches and
# subdiv at cheap settings, a few seconds a job), one job's input replaced by a
# broken mesh; run on --jobs 2, then again with nothing changed. Prints one
# JSON line per run: wall time, the sum of the job times (their own wall-clock
# seconds from summary.json), wall / (sum / jobs), counts, and the load.
# Usage: bench/bench_batch.sh [SURFTEX_BINARY] [WORK_DIR]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
surftex="${1:-$root/build/bin/surftex}"
work="${2:-$(mktemp -d /tmp/surftex-bench-batch.XXXXXX)}"
data="${SURFTEX_SHARED_DATA:-$root/../shared/data}"
jobs="${SURFTEX_BENCH_JOBS:-2}"
mkdir -p "$work"
manifest="$work/jobs.txt"
tex="$data/textures/leather_64.png"
{
  echo "# bench_batch.sh: 25 meshes x (patches, subdiv), one broken input"
  n=0
  for m in "$data"/meshes/* "$data"/swatches/rock_1.obj "$data"/swatches/torus_ring.obj "$data"/swatches/wingnut.obj; do
    name="$(basename "${m%.*}")"
    n=$((n + 1))
    pm="$m"
    # One broken input among the 50 jobs: the patches job of the last mesh.
    if [[ $n == 25 ]]; then pm="$data/broken/truncated.off"; fi
    echo "${name}_patches: patches '$pm' '$tex' --patch-res 48 --rotations 16 --window 7 --max-patch-faces 400"
    echo "${name}_subdiv: subdiv '$m' '$tex' --levels 0 --passes 1 --region 5 --pyramid --atlas-size 256"
  done
} > "$manifest"
out="$work/out"
run() {
  local label="$1"
  local load
  load="$(cut -d' ' -f1-3 /proc/loadavg)"
  local t0 t1
  t0=$(date +%s.%N)
  set +e
  /usr/bin/time -o "$work/$label.time" -f "%U %S" \
    "$surftex" batch "$manifest" -o "$out" --jobs "$jobs" > "$work/$label.stdout" 2> "$work/$label.stderr"
  local rc=$?
  set -e
  t1=$(date +%s.%N)
  python3 - "$out/summary.json" "$label" "$rc" "$t0" "$t1" "$load" "$jobs" "$work/$label.time" <<'EOF'
import json, sys
summary, label, rc, t0, t1, load, jobs, timefile = sys.argv[1:]
user, system = (float(x) for x in open(timefile).read().split()[-2:])
s = json.load(open(summary))
wall = float(t1) - float(t0)
ran = [j for j in s["jobs"] if j.get("seconds") is not None]
total = sum(j["seconds"] for j in ran)
failed = [j for j in s["jobs"] if j["status"] == "failed"]
print(json.dumps({"bench": "batch", "run": label, "exit_code": int(rc), "wall_seconds": round(wall, 2),
                  "job_seconds_sum": round(total, 2), "jobs": int(jobs),
                  "wall_over_ideal": round(wall / (total / int(jobs)), 3) if label == "first" and total > 0 else None,
                  "cpu_seconds_sum": round(s.get("cpu_seconds_sum", 0), 2),
                  "batch_cpu_seconds": round(user + system, 2),
                  "ok": s["counts"]["ok"], "failed": s["counts"]["failed"], "total": s["counts"]["total"],
                  "failed_errors": [f"{j['name']}: {j['error']}" for j in failed],
                  "load_before": load}))
EOF
}
rm -rf "$out"
run first
run unchanged
# SIGTERM to the batch while the two largest jobs run: no folder of theirs may
# appear, and the next run completes them.
for j in bunny_75k_patches bunny_75k_subdiv; do rm -rf "${out:?}/$j"; done
"$surftex" batch "$manifest" -o "$out" --jobs "$jobs" > "$work/sigterm.stdout" 2> "$work/sigterm.stderr" &
pid=$!
for _ in $(seq 1 600); do
  n=$(find "$out/.surftex/stage" -mindepth 1 -maxdepth 1 2>/dev/null | wc -l)
  [[ $n -ge 2 ]] && break
  sleep 0.1
done
sleep 1
kill -TERM "$pid"
set +e
wait "$pid"
rc=$?
set -e
left="$(ls "$out/.surftex/stage" 2>/dev/null | wc -l)"
folders="$( (ls -d "$out/bunny_75k_patches" "$out/bunny_75k_subdiv" 2>/dev/null || true) | wc -l)"
echo "{\"bench\": \"batch\", \"run\": \"sigterm\", \"exit_code\": $rc, \"stage_entries_left\": $left, \"interrupted_job_folders\": $folders}"
run after_sigterm

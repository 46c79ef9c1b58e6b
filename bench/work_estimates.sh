#!/usr/bin/env bash
# Measures every texturing subcommand at the CLI's defaults on tori of
# increasing face counts and prints one JSON line per run: peak RSS and CPU
# time next to the estimate the subcommand printed (geometry/work_budget.h),
# so the estimate's coefficients can be checked and refitted
# (docs/decisions/602-work-estimates.md). One run at a time, niced, each
# bounded by `timeout`.
# Usage: bench/work_estimates.sh BUILD_DIR [FACES...] (default 2000 8000 32000)
# SURFTEX_EXTRA_ARGS is appended to every command (e.g. "--max-memory 4G" for
# the issue's goal: at 500K faces every texturing subcommand finishes within
# 4 GB or refuses up front). SURFTEX_ONLY_MESH=1 skips the image-only ones.
set -euo pipefail
build="$1"; shift
sizes=("$@"); ((${#sizes[@]})) || sizes=(2000 8000 32000)
bin="$build/bin/surftex"
[[ -x "$bin" ]] || { echo "error: no surftex binary at $bin" >&2; exit 2; }
data="${SURFTEX_SHARED_DATA:-$(dirname "$0")/../../shared/data}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
ex="$data/textures/fabric_brown_256.png"
torus() {  # torus FACES PATH: an nu x nv torus with 2*nu*nv triangles
  python3 - "$1" "$2" <<'PY'
import math, sys
F, path = int(sys.argv[1]), sys.argv[2]
nv = max(3, int(math.sqrt(F / 2 / 4)))
nu = max(3, F // (2 * nv))
R, r = 2.0, 0.7
with open(path, "w") as f:
    f.write("OFF\n%d %d 0\n" % (nu * nv, 2 * nu * nv))
    for i in range(nu):
        for j in range(nv):
            u, v = 2 * math.pi * i / nu, 2 * math.pi * j / nv
            f.write("%.8f %.8f %.8f\n" % ((R + r * math.cos(v)) * math.cos(u), (R + r * math.cos(v)) * math.sin(u), r * math.sin(v)))
    for i in range(nu):
        for j in range(nv):
            a, b = i * nv + j, ((i + 1) % nu) * nv + j
            c, d = ((i + 1) % nu) * nv + (j + 1) % nv, i * nv + (j + 1) % nv
            f.write("3 %d %d %d\n3 %d %d %d\n" % (a, b, c, a, c, d))
PY
}
measure() {  # measure NAME FACES ARGS...
  local name="$1" faces="$2"; shift 2
  rm -rf "$work/out"; mkdir -p "$work/out"
  local t0 rc=0
  t0=$(date +%s.%N)
  # shellcheck disable=SC2086
  nice -n 10 timeout 1800 /usr/bin/time -f "%M %U %S" -o "$work/time" "$bin" "$@" ${SURFTEX_EXTRA_ARGS:-} >"$work/stdout" 2>"$work/stderr" || rc=$?
  local wall; wall=$(echo "$(date +%s.%N) - $t0" | bc)
  # GNU time writes "Command exited with non-zero status N" before its figures.
  read -r rss user sys < <(tail -n 1 "$work/time") || true
  local est; est=$(grep -m1 "^note: estimate" "$work/stderr" | sed 's/"/\\"/g' || true)
  local err; err=$(grep -m1 "^error" "$work/stderr" | sed 's/"/\\"/g' | cut -c1-300 || true)
  echo "{\"bench\":\"work_estimates\",\"command\":\"$name\",\"faces\":$faces,\"exit\":$rc,\"max_rss_mib\":$((${rss:-0} / 1024)),\"user_s\":${user:-0},\"sys_s\":${sys:-0},\"wall_s\":$wall,\"load\":$(cut -d' ' -f1 /proc/loadavg),\"estimate\":\"$est\",\"error\":\"$err\"}"
}
# Image-only subcommands once (they do not depend on a mesh).
if [[ "${SURFTEX_ONLY_MESH:-0}" != 1 ]]; then
  measure synth 0 synth "$ex" -o "$work/out/s.png"
  measure tile 0 tile "$ex" -o "$work/out/t.png"
fi
# material-map needs a tile (made without the extra arguments).
SURFTEX_EXTRA_ARGS="" measure material-tile 0 material-tile "$data/textures/fabric_brown_256.png" "$data/textures/denim_256.png" -o "$work/tile"
for F in "${sizes[@]}"; do
  torus "$F" "$work/torus.off"
  measure patches "$F" patches "$work/torus.off" "$ex" -o "$work/out/p"
  measure subdiv "$F" subdiv "$work/torus.off" "$ex" -o "$work/out/s"
  measure material-map "$F" material-map "$work/torus.off" --tile "$work/tile" -o "$work/out/m"
  measure quilt "$F" quilt "$work/torus.off" weave -o "$work/out/q.obj"
done

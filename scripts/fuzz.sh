#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/, Debian clang with ASan+UBSan) and runs
# each one for a while, seeded from ../shared/data and fuzz/seeds (issue 21
# item 6). A crash, a sanitizer report, a hang (> 10 s on one input) or an
# input that needs more than 2 GiB is a finding: the input is saved in
# fuzz/regressions/TARGET/ (keep it there: the test suite replays every file
# of that folder, tests/apps/test_fuzz_regressions.cpp) and the script exits 1.
# Usage: scripts/fuzz.sh [--seconds N (default 60)] [--jobs J (default 2)] [TARGET...]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
seconds=60
jobs=2
targets=()
while (($#)); do
  case "$1" in
    --seconds) seconds="$2"; shift 2 ;;
    --jobs) jobs="$2"; shift 2 ;;
    -h|--help) sed -n '2,9p' "$0"; exit 0 ;;
    *) targets+=("$1"); shift ;;
  esac
done
all=(fuzz_obj fuzz_off fuzz_ply fuzz_stl fuzz_glb fuzz_image_header fuzz_constraints fuzz_tile_json)
((${#targets[@]})) || targets=("${all[@]}")

SURFTEX_FUZZ=1 bash "$root/scripts/setup.sh"
build="${SURFTEX_FUZZ_BUILD_DIR:-$root/build-fuzz}"
export CCACHE_BASEDIR="$root" CCACHE_COMPRESS=1
gen=()
if command -v ninja >/dev/null 2>&1; then gen=(-G Ninja); fi
if [[ ! -f "$build/CMakeCache.txt" ]]; then
  CXX=clang++ cmake -S "$root/fuzz" -B "$build" "${gen[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
fi
cmake --build "$build" -j "${SURFTEX_JOBS:-$(nproc)}" --target "${targets[@]}"

data="${SURFTEX_SHARED_DATA:-$root/../shared/data}"
work="$build/corpus"
mkdir -p "$work"
seed() {  # seed TARGET FILES...: copies the files into the target's corpus
  local t="$1"; shift
  mkdir -p "$work/$t"
  for f in "$@"; do [[ -f "$f" ]] && cp -n "$f" "$work/$t/" 2>/dev/null || true; done
}
shopt -s nullglob
seed fuzz_obj "$data"/meshes/*.obj "$data"/broken/*.obj "$data"/swatches/*.obj
seed fuzz_off "$data"/meshes/*.off "$data"/broken/*.off "$data"/swatches/*.off
seed fuzz_ply "$data"/meshes/*.ply "$data"/broken/*.ply
seed fuzz_stl "$data"/broken/*.stl
seed fuzz_glb "$data"/meshes/*.glb "$root"/fuzz/seeds/glb/*.glb
seed fuzz_image_header "$data"/textures/*_64.png "$data"/textures/*_96.png "$data"/textures/*_100.png
if command -v oiiotool >/dev/null 2>&1 && [[ ! -f "$work/fuzz_image_header/small.jpg" ]]; then
  for ext in jpg tif exr bmp tga; do  # one small file per format OpenImageIO reads
    oiiotool "$data/textures/leather_64.png" --resize 16x16 -o "$work/fuzz_image_header/small.$ext" 2>/dev/null || true
  done
fi
seed fuzz_constraints "$root"/fuzz/seeds/constraints/*.json
seed fuzz_tile_json "$root"/fuzz/seeds/tile_json/*.json
# A binary STL seed (the shared data has only ascii ones).
if [[ ! -f "$work/fuzz_stl/tet_binary.stl" ]]; then
  python3 - "$work/fuzz_stl/tet_binary.stl" <<'PY'
import struct, sys
P = [(0,0,0),(1,0,0),(0,1,0),(0,0,1)]; F = [(0,2,1),(0,1,3),(0,3,2),(1,2,3)]
b = b"binary tetrahedron".ljust(80, b" ") + struct.pack("<I", len(F))
for f in F:
    b += struct.pack("<3f", 0, 0, 0) + b"".join(struct.pack("<3f", *P[i]) for i in f) + b"\0\0"
open(sys.argv[1], "wb").write(b)
PY
fi

export ASAN_OPTIONS=detect_leaks=0:abort_on_error=1:allocator_may_return_null=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
status=0
run_one() {
  local t="$1"
  local reg="$root/fuzz/regressions/$t"
  mkdir -p "$reg" "$build/new/$t"
  # New corpus entries go to build/new (not to the repository); findings to fuzz/regressions.
  # A fixed seed (SURFTEX_FUZZ_SEED, default 1) so that a CI run explores the same inputs
  # first each time; 0 asks libFuzzer for a random one.
  if "$build/$t" -seed="${SURFTEX_FUZZ_SEED:-1}" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=2048 \
       -max_len=131072 -print_final_stats=1 -artifact_prefix="$reg/" \
       "$build/new/$t" "$work/$t" >"$build/$t.log" 2>&1; then
    echo "fuzz: $t clean for ${seconds} s ($(grep -m1 -o 'stat::number_of_executed_units: *[0-9]*' "$build/$t.log" | grep -o '[0-9]*$') inputs)"
  else
    echo "fuzz: $t FOUND a problem (input saved in fuzz/regressions/$t/); log: $build/$t.log"
    tail -30 "$build/$t.log"
    return 1
  fi
}
running=0
for t in "${targets[@]}"; do
  run_one "$t" &
  running=$((running + 1))
  if ((running >= jobs)); then wait -n || status=1; running=$((running - 1)); fi
done
while ((running > 0)); do wait -n || status=1; running=$((running - 1)); done
exit "$status"

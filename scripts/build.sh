#!/usr/bin/env bash
# Configures and builds surftex into build/ (or $SURFTEX_BUILD_DIR).
# Usage: scripts/build.sh [extra cmake -D options]
# SURFTEX_BUILD_TARGETS="surftex ..." builds only these targets (default: all,
# i.e. the command, every test suite and every benchmark); SURFTEX_JOBS sets
# the parallel jobs (default: the number of cores).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${SURFTEX_BUILD_DIR:-$root/build}"
export CCACHE_BASEDIR="$root" CCACHE_COMPRESS=1
gen=()
if command -v ninja >/dev/null 2>&1; then gen=(-G Ninja); fi
if [[ ! -f "$build/CMakeCache.txt" ]]; then
  cmake -S "$root" -B "$build" "${gen[@]}" -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
else
  cmake -S "$root" -B "$build" "$@" >/dev/null
fi
jobs="${SURFTEX_JOBS:-$(nproc)}"
targets=()
for t in ${SURFTEX_BUILD_TARGETS:-}; do targets+=(--target "$t"); done
cmake --build "$build" -j "$jobs" "${targets[@]}"

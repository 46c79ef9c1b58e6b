#!/usr/bin/env bash
# Installs every system dependency surftex needs from Debian 12 packages,
# then the Khronos glTF-Validator (npm gltf-validator, pinned) that the tests
# run on every GLB they write, into the build tree:
# ${SURFTEX_BUILD_DIR:-build}/tools/gltf-validator (no global npm install).
# Idempotent: packages already present are not reinstalled; apt and npm are
# only consulted when something is missing.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
GLTF_VALIDATOR_VERSION="2.0.0-dev.3.10"

PKGS=(
  cmake g++ make ninja-build ccache pkg-config
  libcgal-dev libcgal-demo libgmp-dev libmpfr-dev
  libeigen3-dev libtet1.5-dev
  libopenimageio-dev openimageio-tools
  libboost-graph-dev libboost-dev
  libgtest-dev libgmock-dev
  libnanoflann-dev libtbb-dev libcli11-dev nlohmann-json3-dev libtinygltf-dev libstb-dev
  libsuitesparse-dev libmetis-dev
  # An optimised BLAS/LAPACK behind CHOLMOD (PGP): takes over libblas.so.3
  # through Debian's alternatives. The pthread build, pinned to one BLAS
  # thread at run time (its thread count changes the bytes: measured), gives
  # the serial build's bytes and, unlike Debian's serial build (no
  # USE_LOCKING), may be called from two threads at once, so the PGP runs
  # the paper's s and t systems side by side. OpenBLAS 0.3.21 does not know
  # recent Xeons (AVX-512) and falls back to its generic "Prescott" kernels
  # (5x slower dgemm); the PGP switches it to its SkylakeX/Haswell kernels
  # unless OPENBLAS_CORETYPE is set (periodic_global_parameterization.cpp,
  # configure_blas, blas_allows_concurrent_calls).
  libopenblas0-pthread
  # `surftex batch` runs its jobs on Snakemake (local cores, --cluster, --slurm).
  snakemake
  # The glTF-Validator's runtime (the tests call it through node).
  nodejs
)
# Debian's npm, unless an npm is already there (NodeSource's nodejs package
# bundles its own, which Debian's npm package conflicts with).
if ! command -v npm >/dev/null 2>&1; then PKGS+=(npm); fi
# Optional peers used only by benchmarks (bench/): G'MIC.
if [[ "${SURFTEX_BENCH_PEERS:-0}" == "1" ]]; then PKGS+=(gmic); fi
# Only for the tests (`setup.sh --tests`, as scripts/test.sh calls it): a
# headless browser that opens the batch's contact sheet.
for a in "$@"; do
  case "$a" in
    --tests) PKGS+=(chromium) ;;
    -h|--help) echo "usage: scripts/setup.sh [--tests]"; exit 0 ;;
    *) echo "error: unknown option '$a'" >&2; exit 2 ;;
  esac
done
# Only to build the libFuzzer targets (scripts/fuzz.sh): Debian's clang and
# its runtime libraries (libFuzzer, ASan, UBSan).
if [[ "${SURFTEX_FUZZ:-0}" == "1" ]]; then PKGS+=(clang libclang-rt-14-dev); fi

# One dpkg-query for all packages (one call each took ~5 s on a loaded machine).
installed=" $({ dpkg-query -W -f='${Package} ${Status}\n' "${PKGS[@]}" 2>/dev/null || true; } |
  awk '$2 == "install" && $3 == "ok" && $4 == "installed" { printf "%s ", $1 }')"
missing=()
for p in "${PKGS[@]}"; do
  if [[ "$installed" != *" $p "* ]]; then missing+=("$p"); fi
done

if (( ${#missing[@]} == 0 )); then
  echo "setup: all ${#PKGS[@]} packages present"
else
  SUDO=""
  if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
  echo "setup: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# The glTF-Validator, pinned, in the build tree (CMake's
# SURFTEX_GLTF_VALIDATOR_DIR points there by default).
validator="${SURFTEX_BUILD_DIR:-$root/build}/tools/gltf-validator"
installed="$(node -p "require('$validator/node_modules/gltf-validator/package.json').version" 2>/dev/null || true)"
if [[ "$installed" != "$GLTF_VALIDATOR_VERSION" ]]; then
  echo "setup: installing gltf-validator@$GLTF_VALIDATOR_VERSION into $validator"
  mkdir -p "$validator"
  npm install --prefix "$validator" --no-save --no-audit --no-fund --loglevel=error \
    "gltf-validator@$GLTF_VALIDATOR_VERSION"
else
  echo "setup: gltf-validator $installed present in $validator"
fi
echo "setup: done"

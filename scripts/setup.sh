#!/usr/bin/env bash
# Installs every system dependency surftex needs from Debian 12 packages.
# Idempotent: packages already present are not reinstalled; apt is only
# consulted when something is missing.
set -euo pipefail

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
)
# Optional peers used only by benchmarks (bench/): G'MIC.
if [[ "${SURFTEX_BENCH_PEERS:-0}" == "1" ]]; then PKGS+=(gmic); fi
# Only to build the libFuzzer targets (scripts/fuzz.sh): Debian's clang and
# its runtime libraries (libFuzzer, ASan, UBSan).
if [[ "${SURFTEX_FUZZ:-0}" == "1" ]]; then PKGS+=(clang libclang-rt-14-dev); fi

missing=()
for p in "${PKGS[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if (( ${#missing[@]} == 0 )); then
  echo "setup: all ${#PKGS[@]} packages present"
  exit 0
fi

SUDO=""
if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
echo "setup: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
echo "setup: done"

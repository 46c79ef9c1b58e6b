#!/usr/bin/env bash
# The README's test command: installs system packages (scripts/setup.sh),
# builds from scratch if needed, runs every test suite with ctest. With
# --sanitize (or CI=true) it runs the whole suite a second time built with
# AddressSanitizer + UndefinedBehaviorSanitizer.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
sanitize=0
for a in "$@"; do
  case "$a" in
    --sanitize) sanitize=1 ;;
    -h|--help) echo "usage: scripts/test.sh [--sanitize]"; exit 0 ;;
    *) echo "error: unknown option '$a'" >&2; exit 2 ;;
  esac
done
if [[ "${CI:-}" == "true" ]]; then sanitize=1; fi
# The tests read real meshes and textures (tests/test_support.cpp): say where
# they are missing before installing and building for twenty minutes.
data="${SURFTEX_SHARED_DATA:-$root/../shared/data}"
if [[ ! -d "$data/meshes" || ! -d "$data/textures" ]]; then
  echo "error: the test data is not at '$data' (clone surftex beside shared/, or set SURFTEX_SHARED_DATA to the shared/data folder)" >&2
  exit 2
fi

bash "$root/scripts/setup.sh" --tests
SURFTEX_BUILD_DIR="$root/build" bash "$root/scripts/build.sh"
(cd "$root/build" && ctest --output-on-failure -j "$(nproc)")

if [[ $sanitize == 1 ]]; then
  echo "== sanitizer suite (ASan + UBSan) =="
  # -O1 -g1 (line tables only), the usual ASan setting: half the compile time
  # of RelWithDebInfo's -O2 -g. Precompiled headers: ccache cannot reuse this
  # build's objects across checkouts anyway (-g hashes the build folder).
  # The geometry and apps suites only (readers, repair, every subcommand run
  # through the sanitized binary, batch, fuzz regressions): the texture and
  # shell suites' algorithm tests run in the Release suite above
  # (docs/decisions/801-ci-time.md: the whole CI within 60 minutes).
  SURFTEX_BUILD_DIR="$root/build-asan" bash "$root/scripts/build.sh" \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" \
    -DSURFTEX_SANITIZE=ON -DSURFTEX_BUILD_BENCH=OFF -DSURFTEX_PCH=ON -DSURFTEX_TEST_MODULES="geometry;apps" \
    -DSURFTEX_GLTF_VALIDATOR_DIR="$root/build/tools/gltf-validator"
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=0 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  # Fast (frame-pointer) unwinding on malloc, LSan's default: full unwinding
  # made the allocation-heavy quilting tests 6x slower (64 s -> 11 s for
  # PlanarQuiltingScale.SameSeedSameOutput). It records fewer third-party
  # frames, so scripts/lsan.supp matches less; the one known third-party leak
  # (libpng longjmp-ing through OpenImageIO on a damaged PNG) is no longer
  # reached since geometry/image_io checks a PNG's chunks before libpng does.
  export LSAN_OPTIONS="suppressions=$root/scripts/lsan.supp"
  # The two runs of the whole demo and the Snakemake cluster run are left to the
  # Release suite: every subcommand they call runs sanitized in its own tests
  # (docs/decisions/801-ci-time.md).
  (cd "$root/build-asan" && SURFTEX_SANITIZED=1 ctest --output-on-failure -j "$(nproc)" \
     -E '^(CmdDemo\.|BatchCli\.TheDemoEndsWithTheSameContactSheet$|BatchCli\.TheSnakefileRuns)')
fi

#!/usr/bin/env bash
# The test command: installs what is missing, builds, and runs every test (ctest) on 2 cores.
# Usage: scripts/run_tests.sh [--sanitize]    (--sanitize: AddressSanitizer + UBSan build in build-asan/)
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_deps.sh

build=build
flags=()
if [[ "${1:-}" == "--sanitize" ]]; then
  build=build-asan
  flags=(-DDEMMAT_SANITIZE=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDEMMAT_BUILD_BENCH=OFF)
fi
jobs=$(nproc 2>/dev/null || echo 2)
cmake -S . -B "$build" "${flags[@]}"
cmake --build "$build" -j "$jobs"
cd "$build"
ctest --output-on-failure -j "$jobs"

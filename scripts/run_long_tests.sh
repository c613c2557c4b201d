#!/usr/bin/env bash
# The long tests: the full matrices (contact law × search × threads × variant, long trajectories) that
# carry the ctest label `long` (a gtest suite whose name ends in "Long"), in the normal Release build.
# CI (scripts/run_tests.sh) runs a representative slice of each matrix and leaves these out.
# Usage: scripts/run_long_tests.sh [--build-dir DIR] [ctest arguments...]
#   --build-dir DIR  the build folder (default build, or $DEMMAT_BUILD_DIR)
#   anything else goes to ctest, e.g. scripts/run_long_tests.sh -R Memory
source "$(dirname "$0")/lib.sh"
ctest_args=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --build-dir|-h|--help) shared_option "$@"; shift "$SHIFT" ;;
    --*) unknown_option "$1" ;;
    *) ctest_args+=("$1"); shift ;;
  esac
done
install_deps
cmake_build "$BUILD_DIR"
(cd "$BUILD_DIR" && ctest --output-on-failure -j "$JOBS" -L long "${ctest_args[@]}")

#!/usr/bin/env bash
# The test command: installs what is missing, then builds and runs every test (ctest) twice: the normal
# build (build/) and a sanitizer build (build-asan/: AddressSanitizer, UndefinedBehaviorSanitizer and
# LeakSanitizer, every report fatal). Both builds hold every registered variant; the script checks that
# their variant lists agree, so a variant cannot drop out of the sanitizer run unnoticed.
# Documentation: docs/testing.md.
# Usage: scripts/run_tests.sh [--normal | --sanitize] [--build-dir DIR] [ctest arguments...]
#   (no flag)        both builds, normal first
#   --normal         the normal build only
#   --sanitize       the sanitizer build only
#   --build-dir DIR  the normal build folder (default build, or $DEMMAT_BUILD_DIR); the sanitizer build
#                    goes in DIR-asan
#   anything else goes to ctest, e.g. scripts/run_tests.sh --sanitize -R bad_input
# The tests labelled `long` (the full matrices) are left out: scripts/run_long_tests.sh runs them.
source "$(dirname "$0")/lib.sh"
which=both; ctest_args=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --normal) which=normal; shift ;;
    --sanitize) which=sanitize; shift ;;
    --build-dir|-h|--help) shared_option "$@"; shift "$SHIFT" ;;
    *) ctest_args+=("$1"); shift ;;
  esac
done
asan_dir=$BUILD_DIR-asan
install_deps

# Any sanitizer report stops the program with a non-zero exit (the build also has
# -fno-sanitize-recover=all), so the test that ran it fails; leaks are checked at exit.
export ASAN_OPTIONS="halt_on_error=1:abort_on_error=0:detect_leaks=1:detect_stack_use_after_return=1:strict_string_checks=1:check_initialization_order=1:exitcode=86${ASAN_OPTIONS:+:$ASAN_OPTIONS}"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:exitcode=87${UBSAN_OPTIONS:+:$UBSAN_OPTIONS}"
export LSAN_OPTIONS="exitcode=88${LSAN_OPTIONS:+:$LSAN_OPTIONS}"

run_build() {  # run_build DIR [cmake flags...]: every target, then every test
  local dir=$1
  shift
  echo "== run_tests: $dir" >&2
  cmake_build "$dir" -- "$@"
  (cd "$dir" && ctest --output-on-failure -j "$JOBS" -LE long "${ctest_args[@]}")
}

if [[ $which != sanitize ]]; then
  run_build "$BUILD_DIR"
fi
if [[ $which != normal ]]; then
  # RelWithDebInfo, which DEMMAT_SANITIZE turns into -O1 -g1 (CMakeLists.txt): line numbers in the reports.
  # The ends of each chain of specialised models only (every feature off, every feature on): every
  # `if constexpr` on a feature still runs both ways, in a fraction of the compile time (docs/testing.md).
  # The gtest cases as 16 shards, 16 processes, not one per case: an instrumented process takes a third
  # of a second to start (docs/testing.md).
  run_build "$asan_dir" -DDEMMAT_SANITIZE=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDEMMAT_BUILD_BENCH=OFF -DDEMMAT_ALL_MODELS=OFF \
    -DDEMMAT_TEST_SHARDS=16
fi
if [[ $which == both ]]; then
  normal=$("$(demmat_in "$BUILD_DIR")" list | awk '{print $1}' | tr '\n' ' ')
  sanitized=$("$(demmat_in "$asan_dir")" list | awk '{print $1}' | tr '\n' ' ')
  if [[ "$normal" != "$sanitized" ]]; then
    echo "run_tests: the sanitizer build registers other variants ($sanitized) than the normal build ($normal)" >&2
    exit 1
  fi
  echo "run_tests: both builds passed, variants: $normal" >&2
fi

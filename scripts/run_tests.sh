#!/usr/bin/env bash
# The test command: installs what is missing, then builds and runs every test (ctest) twice: the normal
# build (build/) and a sanitizer build (build-asan/: AddressSanitizer, UndefinedBehaviorSanitizer and
# LeakSanitizer, every report fatal). Both builds hold every registered variant; the script checks that
# their variant lists agree, so a variant cannot drop out of the sanitizer run unnoticed.
# Usage: scripts/run_tests.sh [--normal | --sanitize] [ctest arguments...]
#   (no flag) both builds, normal first      --normal: build/ only      --sanitize: build-asan/ only
#   e.g. scripts/run_tests.sh --sanitize -R bad_input
# Documentation: docs/testing.md.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_deps.sh

which=both
case "${1:-}" in
  --normal) which=normal; shift ;;
  --sanitize) which=sanitize; shift ;;
esac
jobs=$(nproc 2>/dev/null || echo 2)

# Any sanitizer report stops the program with a non-zero exit (the build also has
# -fno-sanitize-recover=all), so the test that ran it fails; leaks are checked at exit.
export ASAN_OPTIONS="halt_on_error=1:abort_on_error=0:detect_leaks=1:detect_stack_use_after_return=1:strict_string_checks=1:check_initialization_order=1:exitcode=86${ASAN_OPTIONS:+:$ASAN_OPTIONS}"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:exitcode=87${UBSAN_OPTIONS:+:$UBSAN_OPTIONS}"
export LSAN_OPTIONS="exitcode=88${LSAN_OPTIONS:+:$LSAN_OPTIONS}"

run_build() {  # run_build DIR [cmake flags...]
  local dir=$1
  shift
  echo "== run_tests: $dir" >&2
  cmake -S . -B "$dir" "$@"
  cmake --build "$dir" -j "$jobs"
  (cd "$dir" && ctest --output-on-failure -j "$jobs" "${ctest_args[@]}")
}

ctest_args=("$@")
if [[ $which != sanitize ]]; then
  run_build build
fi
if [[ $which != normal ]]; then
  # RelWithDebInfo: optimised as the real runs are, with line numbers in the reports.
  run_build build-asan -DDEMMAT_SANITIZE=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDEMMAT_BUILD_BENCH=OFF
fi
if [[ $which == both ]]; then
  normal=$(build/app/demmat list | awk '{print $1}' | tr '\n' ' ')
  sanitized=$(build-asan/app/demmat list | awk '{print $1}' | tr '\n' ' ')
  if [[ "$normal" != "$sanitized" ]]; then
    echo "run_tests: the sanitizer build registers other variants ($sanitized) than the normal build ($normal)" >&2
    exit 1
  fi
  echo "run_tests: both builds passed, variants: $normal" >&2
fi

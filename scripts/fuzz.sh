#!/usr/bin/env bash
# Fuzzes the scene reader and the state reader with libFuzzer (clang, ASan + UBSan), each for a given
# time, from the bad-input corpus and the standard scenes as seeds. Prints executions and crashes per
# target and exits non-zero if any target crashed; a crash input is left in build-fuzz/crashes/<target>/
# (make it a tests/bad_input case and fix the reader). Documentation: docs/testing.md.
# Needs clang++-14 and libclang-rt-14-dev (Debian); installs them if missing.
# Usage: scripts/fuzz.sh [--build-dir DIR] [SECONDS_PER_TARGET] [TARGET...]
#   SECONDS_PER_TARGET  default 60;  TARGET: scene, state (default both)
#   --build-dir DIR     the clang build folder (default build-fuzz; not $DEMMAT_BUILD_DIR, a g++ build)
source "$(dirname "$0")/lib.sh"
BUILD_DIR=build-fuzz; seconds=60; targets=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    -*) shared_option "$@"; shift "$SHIFT" ;;
    scene|state) targets+=("$1"); shift ;;
    *) [[ ${#targets[@]} -eq 0 && $1 =~ ^[0-9]+$ ]] || { echo "$SCRIPT: unknown target '$1' (scene, state)" >&2; exit 2; }
       seconds=$1; shift ;;
  esac
done
positive_int SECONDS_PER_TARGET "$seconds"
[[ ${#targets[@]} -eq 0 ]] && targets=(scene state)

install_deps --fuzz
cmake_build -q -S fuzz "$BUILD_DIR" -- -DCMAKE_CXX_COMPILER=clang++-14 -DCMAKE_BUILD_TYPE=RelWithDebInfo

# Seeds (read only) and the working corpus that grows across runs (kept in the build folder).
seeds_scene=(tests/bad_input scenes)
seeds_state=(tests/bad_input/data)
export ASAN_OPTIONS="halt_on_error=1:detect_leaks=1${ASAN_OPTIONS:+:$ASAN_OPTIONS}"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1${UBSAN_OPTIONS:+:$UBSAN_OPTIONS}"

status=0
summary=()
for t in "${targets[@]}"; do
  case $t in
    scene) seeds=("${seeds_scene[@]}"); extra=(-dict=fuzz/scene.dict -max_len=8192) ;;
    state) seeds=("${seeds_state[@]}"); extra=(-max_len=4096) ;;
    *) echo "fuzz.sh: unknown target '$t' (scene, state)" >&2; exit 2 ;;
  esac
  corpus=$BUILD_DIR/corpus/$t
  crashes=$BUILD_DIR/crashes/$t
  mkdir -p "$corpus" "$crashes"
  log=$BUILD_DIR/fuzz_$t.log
  echo "fuzz.sh: fuzz_$t for ${seconds} s (log: $log)" >&2
  rc=0
  # -timeout: an input that takes 10 s is a hang; -rss_limit_mb: a reader that allocates 2 GB for a
  # small input is a defect too.
  "$BUILD_DIR/fuzz_$t" "$corpus" "${seeds[@]}" "${extra[@]}" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
    -artifact_prefix="$crashes/" -print_final_stats=1 >"$log" 2>&1 || rc=$?
  runs=$(grep -oE 'stat::number_of_executed_units: *[0-9]+' "$log" | grep -oE '[0-9]+$' | tail -1)
  found=$(find "$crashes" -type f | wc -l)
  summary+=("fuzz_$t: ${seconds} s, ${runs:-?} executions, corpus $(find "$corpus" -type f | wc -l) inputs, exit $rc, crash files $found")
  if [[ $rc -ne 0 || $found -gt 0 ]]; then
    status=1
    grep -E "ERROR|defect|runtime error|SUMMARY" "$log" | head -5 >&2 || true
  fi
done
printf '%s\n' "${summary[@]}"
exit $status

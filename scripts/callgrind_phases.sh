#!/usr/bin/env bash
# Instruction counts per phase and particle-step with valgrind's callgrind: repeatable on a shared,
# noisy machine where seconds are not. Profiles `demmat run` of SCENE for STEPS steps with one thread,
# from a demmat program already built in the build folder (scripts/run_figures.sh builds a portable one).
# Usage: scripts/callgrind_phases.sh [--build-dir DIR] SCENE STEPS OUT_DIR VARIANT...
#   --build-dir DIR  the build folder holding app/demmat (default build, or $DEMMAT_BUILD_DIR)
source "$(dirname "$0")/lib.sh"
args=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    -*) shared_option "$@"; shift "$SHIFT" ;;
    *) args+=("$1"); shift ;;
  esac
done
[[ ${#args[@]} -ge 4 ]] || { echo "$SCRIPT: needs SCENE STEPS OUT_DIR VARIANT... (scripts/$SCRIPT --help)" >&2; exit 2; }
scene=${args[0]}; steps=${args[1]}; out=${args[2]}; variants=("${args[@]:3}")
positive_int STEPS "$steps"
demmat=$(demmat_in "$BUILD_DIR")
[[ -x $demmat ]] || { echo "$SCRIPT: $demmat is missing (build the demmat target first)" >&2; exit 1; }
command -v valgrind >/dev/null || { echo "$SCRIPT: valgrind is not installed (scripts/install_deps.sh --optional)" >&2; exit 1; }
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
mkdir -p "$out"
for v in "${variants[@]}"; do
  OMP_NUM_THREADS=1 valgrind --tool=callgrind --callgrind-out-file="$tmp/cg.$v" \
    "$demmat" run "$scene" --variant "$v" --steps "$steps" --quiet --json "$tmp/run.$v.json" >/dev/null 2>"$tmp/log.$v" ||
    { cat "$tmp/log.$v" >&2; exit 1; }
  callgrind_annotate --inclusive=yes --threshold=100 "$tmp/cg.$v" >"$tmp/annotate.$v.txt"
  $PYTHON analysis/callgrind_phases.py "$tmp/annotate.$v.txt" "$tmp/run.$v.json" --steps "$steps" -o "$out/callgrind_$v.json"
done

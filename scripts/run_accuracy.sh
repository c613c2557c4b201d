#!/usr/bin/env bash
# The speed–accuracy study (docs/accuracy.md): builds, runs every integrator × precision of the arrays
# variant over a sweep of Δt on two-body impacts and a settling dense bed, and writes
# results/accuracy/accuracy.{json,csv}, results/accuracy/recommendation.md and the figures
# results/figures/accuracy_work_precision.png and accuracy_error_vs_dt.png.
# Usage: scripts/run_accuracy.sh [--long | --memory] [--build-dir DIR]
#   default          a few minutes (two-body sweep t_c/8 … t_c/2048, a bed of 216 grains for 0.2 s)
#   --long           finer sweep (×√2 to t_c/8192), a bed of 1000 grains for 0.4 s, 3 timed repetitions
#                    (an hour or more)
#   --memory         the laws with memory instead (docs/accuracy.md, "Laws with memory"): Chung & Ooi
#                    tests 4 and 8 under each §9 law × integrator × stretch update, t_c/20 … t_c/2000, into
#                    results/accuracy/memory/ and results/figures/memory_*.png (a few minutes); then the
#                    stretch updates' order against the independent integration (analysis/stretch_update.py,
#                    about half an hour of Python)
#   --build-dir DIR  the build folder (default build, or $DEMMAT_BUILD_DIR)
source "$(dirname "$0")/lib.sh"
args=(); memory=0
while [[ $# -gt 0 ]]; do
  case "$1" in
    --long) args+=(--long); shift ;;
    --memory) memory=1; shift ;;
    *) shared_option "$@"; shift "$SHIFT" ;;
  esac
done
install_deps
if ((memory)); then
  [[ ${#args[@]} -eq 0 ]] || { echo "$SCRIPT: --memory and --long do not go together" >&2; exit 2; }
  cmake_build "$BUILD_DIR" demmat_memory_accuracy
  mkdir -p results/accuracy/memory results/figures
  "$BUILD_DIR"/bench/demmat_memory_accuracy --out results/accuracy/memory
  $PYTHON analysis/plot_memory_accuracy.py results/accuracy/memory/memory_accuracy.json --figures results/figures
  (cd analysis && $PYTHON stretch_update.py ../results/accuracy/memory)
  exit 0
fi
cmake_build "$BUILD_DIR" demmat_accuracy
mkdir -p results/accuracy results/figures
"$BUILD_DIR"/bench/demmat_accuracy --out results/accuracy "${args[@]}"
$PYTHON analysis/plot_accuracy.py results/accuracy/accuracy.json --figures results/figures \
  --table results/accuracy/recommendation.md

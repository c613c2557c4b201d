#!/usr/bin/env bash
# The speed–accuracy study (docs/accuracy.md): builds, runs every integrator × precision of the arrays
# variant over a sweep of Δt on two-body impacts and a settling dense bed, and writes
# results/accuracy/accuracy.{json,csv}, results/accuracy/recommendation.md and the figures
# results/figures/accuracy_work_precision.png and accuracy_error_vs_dt.png.
# Usage: scripts/run_accuracy.sh [--long] [--build-dir DIR]
#   default          a few minutes (two-body sweep t_c/8 … t_c/2048, a bed of 216 grains for 0.2 s)
#   --long           finer sweep (×√2 to t_c/8192), a bed of 1000 grains for 0.4 s, 3 timed repetitions
#                    (an hour or more)
#   --build-dir DIR  the build folder (default build, or $DEMMAT_BUILD_DIR)
source "$(dirname "$0")/lib.sh"
args=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --long) args+=(--long); shift ;;
    *) shared_option "$@"; shift "$SHIFT" ;;
  esac
done
install_deps
cmake_build "$BUILD_DIR" demmat_accuracy
mkdir -p results/accuracy results/figures
"$BUILD_DIR"/bench/demmat_accuracy --out results/accuracy "${args[@]}"
$PYTHON analysis/plot_accuracy.py results/accuracy/accuracy.json --figures results/figures \
  --table results/accuracy/recommendation.md

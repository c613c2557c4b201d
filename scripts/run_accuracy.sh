#!/usr/bin/env bash
# The speed–accuracy study (docs/accuracy.md): builds, runs every integrator × precision of the arrays
# variant over a sweep of Δt on two-body impacts and a settling dense bed, and writes
# results/accuracy/accuracy.{json,csv}, results/accuracy/recommendation.md and the figures
# results/figures/accuracy_work_precision.png and accuracy_error_vs_dt.png.
# Usage: scripts/run_accuracy.sh [--long] [--build DIR]
#   default: a few minutes (two-body sweep t_c/8 … t_c/2048, a bed of 216 grains for 0.2 s)
#   --long:  finer sweep (×√2 to t_c/8192), a bed of 1000 grains for 0.4 s, 3 timed repetitions (an hour or more)
set -euo pipefail
cd "$(dirname "$0")/.."
build=build; args=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --long) args+=(--long); shift ;;
    --build) build="$2"; shift 2 ;;
    *) echo "run_accuracy.sh: unknown option $1 (expected --long, --build DIR)" >&2; exit 2 ;;
  esac
done
scripts/install_deps.sh
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release
cmake --build "$build" -j "$(nproc 2>/dev/null || echo 2)" --target demmat_accuracy
mkdir -p results/accuracy results/figures
"$build"/bench/demmat_accuracy --out results/accuracy "${args[@]}"
/usr/bin/python3 analysis/plot_accuracy.py results/accuracy/accuracy.json --figures results/figures \
  --table results/accuracy/recommendation.md

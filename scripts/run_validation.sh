#!/usr/bin/env bash
# The Chung & Ooi (2011) benchmark tests 1–8 (docs/validation.md): builds demmat_validation, runs every test
# with every law that applies, on every variant named by --variants that the registry says supports the
# run's law and integrator (the others are listed as skipped in validation.json), then compares with the
# independent references (analysis/validation_reference.py) and writes results/validation/: test<K>.csv,
# test1_curves.csv, test2_curves.csv, validation.json, table.md, integrators.md, energy.md,
# reference_check.md, errors.csv and the figures test<K>.png.
# Usage: scripts/run_validation.sh [--variants a,b] [--quick] [--out DIR] [--build-dir DIR]
#   --variants a,b   the variants to run (default arrays,fast); each run uses those that support it
#   --quick          every third point of each sweep (a minute; a smoke test of the pipeline)
#   --out DIR        the output folder (default results/validation)
#   --build-dir DIR  the build folder (default build, or $DEMMAT_BUILD_DIR)
source "$(dirname "$0")/lib.sh"
args=()
variants=arrays,fast
out=results/validation
while [[ $# -gt 0 ]]; do
  case "$1" in
    --variants) need_value "$@"; variants=$2; shift 2 ;;
    --quick) args+=(--quick); shift ;;
    --out) need_value "$@"; out=$2; shift 2 ;;
    *) shared_option "$@"; shift "$SHIFT" ;;
  esac
done
install_deps
cmake_build "$BUILD_DIR" demmat_validation
mkdir -p "$out"
"$BUILD_DIR"/bench/demmat_validation --out "$out" --variants "$variants" "${args[@]}"
$PYTHON analysis/plot_validation.py "$out/validation.json" --out "$out"

#!/usr/bin/env bash
# The stability study (docs/stability.md): builds demmat_stability, finds the largest stable Δt
# for every integrator × precision of the arrays variant on a head-on pair, a sphere hitting a wall and a
# dense bed of 125 grains, across restitution and stiffness, and writes results/stability/ (JSON with
# provenance, Markdown table) and results/figures/stability_map.png. About two minutes on two cores;
# --long sweeps 7 stiffnesses × 9 restitutions (about 20 minutes) into stability_long.* and
# results/figures/stability_map_long.png.
# Usage: scripts/run_stability.sh [--long] [--build-dir DIR]
#   --long           7 stiffnesses × 9 restitutions (about 20 minutes)
#   --build-dir DIR  the build folder (default build, or $DEMMAT_BUILD_DIR)
source "$(dirname "$0")/lib.sh"
mode=default; args=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --long) mode=long; args+=(--long); shift ;;
    *) shared_option "$@"; shift "$SHIFT" ;;
  esac
done

install_deps
cmake_build "$BUILD_DIR" demmat_stability

mkdir -p results/stability results/figures
echo "== stability limits ($mode): every integrator x precision, bisection per scene, stiffness and restitution"
"$BUILD_DIR"/bench/demmat_stability --out results/stability "${args[@]}"

echo "== analysis"
$PYTHON analysis/plot_stability.py results/stability/stability_${mode}.json
echo "results: results/stability/stability_${mode}.json, results/stability/stability_${mode}.md, results/figures/stability_map$([[ $mode == long ]] && echo _long).png"

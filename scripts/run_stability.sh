#!/usr/bin/env bash
# The stability study (issue 9; docs/stability.md): builds demmat_stability, finds the largest stable Δt
# for every integrator × precision of the arrays variant on a head-on pair, a sphere hitting a wall and a
# dense bed of 125 grains, across restitution and stiffness, and writes results/stability/ (JSON with
# provenance, Markdown table) and results/figures/stability_map.png. About two minutes on two cores;
# --long sweeps 7 stiffnesses × 9 restitutions (about 20 minutes) into stability_long.* and
# results/figures/stability_map_long.png.
# Usage: scripts/run_stability.sh [--long] [--build-dir DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
mode=default; build=build; args=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --long) mode=long; args+=(--long); shift ;;
    --build-dir) build="$2"; shift 2 ;;
    *) echo "run_stability.sh: unknown option $1 (expected --long, --build-dir)" >&2; exit 2 ;;
  esac
done

scripts/install_deps.sh
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release
cmake --build "$build" -j "$(nproc 2>/dev/null || echo 2)" --target demmat_stability

mkdir -p results/stability results/figures
echo "== stability limits ($mode): every integrator x precision, bisection per scene, stiffness and restitution"
"$build"/bench/demmat_stability --out results/stability "${args[@]}"

echo "== analysis"
/usr/bin/python3 analysis/plot_stability.py results/stability/stability_${mode}.json
echo "results: results/stability/stability_${mode}.json, results/stability/stability_${mode}.md, results/figures/stability_map$([[ $mode == long ]] && echo _long).png"

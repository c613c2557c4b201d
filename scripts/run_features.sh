#!/usr/bin/env bash
# What each model feature costs per step (issue 10; docs/design.md, "Model features"): builds
# demmat_bench_features, settles a monodisperse dense bed once (kept in states/), times the six levels
# (normal force only, + damping, + friction/rotation, + walls, + moving walls, + polydisperse), each with
# the specialised model and with the full model, for arrays and eigen_soa, in interleaved repetitions,
# and writes results/features/ (JSON with provenance, Markdown and CSV tables) and a figure in
# results/figures/. A few minutes on two cores at the default size.
# Usage: scripts/run_features.sh [--n N] [--steps K] [--repetitions R] [--variants a,b] [--build-dir DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
n=2000; steps=300; reps=7; variants=arrays,eigen_soa; build=build
while [[ $# -gt 0 ]]; do
  case "$1" in
    --n) n="$2"; shift 2 ;;
    --steps) steps="$2"; shift 2 ;;
    --repetitions) reps="$2"; shift 2 ;;
    --variants) variants="$2"; shift 2 ;;
    --build-dir) build="$2"; shift 2 ;;
    *) echo "run_features.sh: unknown option $1 (expected --n, --steps, --repetitions, --variants, --build-dir)" >&2; exit 2 ;;
  esac
done

scripts/install_deps.sh
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release
cmake --build "$build" -j "$(nproc 2>/dev/null || echo 2)" --target demmat_bench_features

mkdir -p states results/features results/figures
json=results/features/bench_features_${n}.json
tmp=$(mktemp results/features/.bench_features.XXXXXX)
trap 'rm -f "$tmp"' EXIT
echo "== timing the feature levels: $variants, $n particles, $reps interleaved repetitions of $steps steps"
"$build"/bench/demmat_bench_features --n="$n" --steps="$steps" --variants="$variants" --states-dir=states \
  --benchmark_repetitions="$reps" --benchmark_enable_random_interleaving=true \
  --benchmark_out="$tmp" --benchmark_out_format=json
mv "$tmp" "$json"

echo "== analysis"
/usr/bin/python3 analysis/plot_features.py "$json" --figure results/figures/features_${n}.png \
  --markdown results/features/features_${n}.md --table results/features/features_${n}.csv
echo "results: $json, results/features/features_${n}.md, results/figures/features_${n}.png"

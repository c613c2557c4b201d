#!/usr/bin/env bash
# What each model feature costs per step (docs/design.md, "Model features"): builds
# demmat_bench_features, settles a monodisperse dense bed once (kept in states/), times the six levels
# (normal force only, + damping, + friction/rotation, + walls, + moving walls, + polydisperse), each with
# the specialised model and with the full model, for arrays, eigen_soa and fast (one core), in interleaved repetitions,
# and writes results/features/ (JSON with provenance, Markdown and CSV tables) and a figure in
# results/figures/. A few minutes on two cores at the default size.
# Usage: scripts/run_features.sh [--n N] [--steps K] [--repetitions R] [--variants a,b] [--build-dir DIR]
#   --n N            grains in the bed (default 2000)
#   --steps K        timed steps per repetition (default 300)
#   --repetitions R  interleaved repetitions (default 7)
#   --variants a,b   the variants timed (default arrays,eigen_soa,fast)
#   --build-dir DIR  the build folder (default build, or $DEMMAT_BUILD_DIR)
source "$(dirname "$0")/lib.sh"
n=2000; steps=300; reps=7; variants=arrays,eigen_soa,fast
while [[ $# -gt 0 ]]; do
  case "$1" in
    --n) need_value "$@"; n=$2; shift 2 ;;
    --steps) need_value "$@"; steps=$2; shift 2 ;;
    --repetitions) need_value "$@"; reps=$2; shift 2 ;;
    --variants) need_value "$@"; variants=$2; shift 2 ;;
    *) shared_option "$@"; shift "$SHIFT" ;;
  esac
done
positive_int --n "$n"; positive_int --steps "$steps"; positive_int --repetitions "$reps"

install_deps
cmake_build "$BUILD_DIR" demmat_bench_features

mkdir -p states results/features results/figures
json=results/features/bench_features_${n}.json
tmp=$(mktemp results/features/.bench_features.XXXXXX)
trap 'rm -f "$tmp"' EXIT
echo "== timing the feature levels: $variants, $n particles, $reps interleaved repetitions of $steps steps"
"$BUILD_DIR"/bench/demmat_bench_features --n="$n" --steps="$steps" --variants="$variants" --states-dir=states \
  --benchmark_repetitions="$reps" --benchmark_enable_random_interleaving=true \
  --benchmark_out="$tmp" --benchmark_out_format=json
mv "$tmp" "$json"

echo "== analysis"
$PYTHON analysis/plot_features.py "$json" --figure results/figures/features_${n}.png \
  --markdown results/features/features_${n}.md --table results/features/features_${n}.csv
echo "results: $json, results/features/features_${n}.md, results/figures/features_${n}.png"

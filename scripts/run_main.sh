#!/usr/bin/env bash
# The main job: installs what is missing, builds, writes the standard scenes, settles the dense bed
# once (kept in states/), checks that every registered variant is bit-identical on the compression
# stage, benchmarks every variant per phase, and writes results/ (JSON, CSV, figure).
# Then it draws the figures of scripts/run_figures.sh (Figure 4, cell-size sweep, scaling, where the
# time goes): the short sweep by default, the full one with --full (an hour or more).
# Usage: scripts/run_main.sh [--n N] [--steps K] [--repetitions R] [--full]
set -euo pipefail
cd "$(dirname "$0")/.."
n=2000; steps=500; reps=5; sweep=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --full) sweep=(--full); shift ;;
    --n) n="$2"; shift 2 ;;
    --steps) steps="$2"; shift 2 ;;
    --repetitions) reps="$2"; shift 2 ;;
    *) echo "run_main.sh: unknown option $1 (expected --n, --steps, --repetitions, --full)" >&2; exit 2 ;;
  esac
done

scripts/install_deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j "$(nproc 2>/dev/null || echo 2)"
demmat=build/app/demmat

echo "== variants"; $demmat list

echo "== scenes (scenes/)"
mkdir -p scenes states results/main results/figures
# Written only when missing: the files in scenes/ are the user's to edit.
[[ -f scenes/paper.toml ]] || $demmat scene paper -o scenes/paper.toml
[[ -f scenes/head_on.toml ]] || $demmat scene head-on -o scenes/head_on.toml
[[ -f scenes/drop.toml ]] || $demmat scene drop -o scenes/drop.toml
bed=scenes/dense_bed_${n}.toml
[[ -f "$bed" ]] || $demmat scene dense-bed --n "$n" -o "$bed"

settled=states/dense_bed_${n}_settled.state
if [[ ! -f "$settled" ]]; then
  echo "== settling the dense bed of $n particles (0.4 s simulated; done once, kept in states/)"
  $demmat run "$bed" --variant arrays --time 0.4 --save "$settled" --json results/main/settle_${n}.json
fi
comp=scenes/dense_bed_${n}_compression.toml
[[ -f "$comp" ]] || $demmat scene compression --from "$bed" --state "$settled" -o "$comp"

echo "== equivalence: every variant against every other, bit for bit, every step"
$demmat compare "$comp" --variants all --steps 1000

echo "== benchmark: compression stage, every variant, $reps interleaved repetitions of $steps steps"
json=results/main/bench_compression_${n}.json
$demmat bench "$comp" --variants all --steps "$steps" --repetitions "$reps" --json "$json"

echo "== analysis"
/usr/bin/python3 analysis/plot_phases.py "$json" --figure results/figures/phases_compression_${n}.png \
  --table results/main/phases_compression_${n}.csv --markdown results/main/phases_compression_${n}.md
echo "results: $json, results/main/phases_compression_${n}.csv, results/figures/phases_compression_${n}.png"

echo "== figures: Figure 4, cell-size sweep, scaling, where the time goes"
scripts/run_figures.sh "${sweep[@]}"

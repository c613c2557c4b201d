#!/usr/bin/env bash
# The main job: installs what is missing, builds the demmat program (every variant, nothing else),
# writes the standard scenes, settles the dense bed once (kept in states/), checks that every
# registered variant is bit-identical on the compression stage, benchmarks every variant per phase
# (Figure 7), plots it and writes the report (analysis/make_report.py); the last line printed is the
# report's path. Every stage ends with a line "stage NAME: S s (total T s)".
# Budget: about 3 minutes on 2 cores once the build exists, 10 from a bare clone; the figures' sweeps
# (scripts/run_figures.sh) take longer and run only when asked for.
# Usage: scripts/run_main.sh [--n N] [--steps K] [--repetitions R] [--sweep | --full] [--build-dir DIR]
#   --n N            grains in the dense bed (default 2000)
#   --steps K        timed steps per benchmark repetition (default 1000)
#   --repetitions R  interleaved benchmark repetitions (default 5)
#   --sweep          also the figures' short sweep (Figure 4, cell sizes, scaling, where the time goes)
#   --full           also the full sweep instead: N up to 10^5 settled, 10^6 loose (an hour or more)
#   --build-dir DIR  the build folder (default build, or $DEMMAT_BUILD_DIR)
source "$(dirname "$0")/lib.sh"
n=2000; steps=1000; reps=5; sweep=none
while [[ $# -gt 0 ]]; do
  case "$1" in
    --n) need_value "$@"; n=$2; shift 2 ;;
    --steps) need_value "$@"; steps=$2; shift 2 ;;
    --repetitions) need_value "$@"; reps=$2; shift 2 ;;
    --sweep) sweep=short; shift ;;
    --full) sweep=full; shift ;;
    *) shared_option "$@"; shift "$SHIFT" ;;
  esac
done
positive_int --n "$n"; positive_int --steps "$steps"; positive_int --repetitions "$reps"

# stage NAME [WHAT]: ends the running stage with its seconds and starts NAME ("stage" alone: ends it).
start=$(date +%s.%N); stage_start=$start; stage_name=""
stage() {
  local now; now=$(date +%s.%N)
  [[ -z $stage_name ]] || awk -v s="$stage_name" -v a="$stage_start" -v b="$now" -v t="$start" \
    'BEGIN { printf "stage %s: %.1f s (total %.1f s)\n", s, b - a, b - t }'
  stage_name=${1:-}; stage_start=$now
  [[ -z $stage_name ]] || echo "== $stage_name${2:+: $2}"
}

# Costs, to size the defaults (a stage's time is particle-steps × µs per particle-step, the latter per
# variant in results/main/bench_compression_*.json): the serial variants cost about the same each, fast
# and fast_unordered (two threads) several times less. The settle is 0.4 s / Δt = 40000 steps of N
# grains; compare runs 1000 steps of every variant, bench R × (K + 20 warm-up) steps of every variant.
stage build "installing what is missing, building the demmat program"
install_deps
# The demmat target links every registered variant (C++, f90, pascal) and nothing else: no tests, no
# Google Benchmark programs (those build when a sweep asks for them).
cmake_build "$BUILD_DIR" demmat
demmat=$(demmat_in "$BUILD_DIR")
$demmat --version
$demmat list

stage scenes "the standard scenes (scenes/)"
mkdir -p scenes states results/main results/figures
# Written only when missing: the files in scenes/ are the user's to edit.
[[ -f scenes/paper.toml ]] || $demmat scene paper -o scenes/paper.toml
[[ -f scenes/head_on.toml ]] || $demmat scene head-on -o scenes/head_on.toml
[[ -f scenes/drop.toml ]] || $demmat scene drop -o scenes/drop.toml
bed=scenes/dense_bed_${n}.toml
[[ -f "$bed" ]] || $demmat scene dense-bed --n "$n" -o "$bed"

settled=states/dense_bed_${n}_settled.state
# fast, on every core, where it is registered: it keeps arrays' canonical order of force summation and
# the same IEEE operations (no FMA contraction), so it writes the very state arrays would, bit for bit,
# several times sooner (test_fast.cpp and test_equivalence.cpp check it step by step on this bed at one
# and two threads; the compare stage below checks every variant again from the settled state).
settler=arrays; grep -q "^fast " <<<"$($demmat list)" && settler=fast
stage settle "the dense bed of $n grains for 0.4 s with $settler (once; kept in states/)"
if [[ ! -f "$settled" ]]; then
  $demmat run "$bed" --variant "$settler" --threads "$JOBS" --time 0.4 --save "$settled" -q \
    --json results/main/settle_${n}.json
else
  echo "$settled exists: kept"
fi
comp=scenes/dense_bed_${n}_compression.toml
[[ -f "$comp" ]] || $demmat scene compression --from "$bed" --state "$settled" -o "$comp"

stage compare "every variant against every other, bit for bit, every step"
$demmat compare "$comp" --variants all --steps 1000

stage bench "the compression stage, every variant per phase (Figure 7): $reps interleaved repetitions of $steps steps"
json=results/main/bench_compression_${n}.json
$demmat bench "$comp" --variants all --steps "$steps" --repetitions "$reps" --json "$json"

stage plot "Figure 7"
$PYTHON analysis/plot_phases.py "$json" --figure results/figures/phases_compression_${n}.png \
  --table results/main/phases_compression_${n}.csv --markdown results/main/phases_compression_${n}.md
echo "results: $json, results/main/phases_compression_${n}.csv, results/figures/phases_compression_${n}.png"

if [[ $sweep != none ]]; then
  stage sweep "the figures ($sweep sweep): Figure 4, cell-size sweep, scaling, where the time goes"
  figures=(--build-dir "$BUILD_DIR"); [[ $sweep == full ]] && figures+=(--full)
  scripts/run_figures.sh "${figures[@]}"
fi

report=results/REPORT.md
stage report "$report"
if [[ -f analysis/make_report.py ]]; then
  $PYTHON analysis/make_report.py --results results --out "$report"
  stage
  echo "$report"
else
  stage
  echo "$SCRIPT: no report written: analysis/make_report.py is missing (results are in results/main/)"
fi

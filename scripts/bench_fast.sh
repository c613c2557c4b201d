#!/usr/bin/env bash
# The fast variant's benchmark (docs/variants/fast.md): for each N, the dense bed settled once
# (0.4 s simulated with fast on every core, kept in states/), then `demmat bench` of arrays, fast and
# fast_unordered on the settled bed (walls at rest) at each thread count, interleaved repetitions,
# medians; then the loose lattice of 10^6 particles benchmarked the same way, and run a few steps to show
# that it fits (peak memory from /usr/bin/time).
# Writes results/fast/bench_settled_<N>.json and bench_loose_1000000.json (+ .txt; every thread count,
# interleaved), results/fast/million.txt and the table
# results/fast/summary.md (analysis/summarise_fast.py: the tables, and what the canonical order costs, paired);
# --out DIR writes them in DIR instead (a second machine's run beside the first).
# Timed steps per repetition are 5·10^6/N (at least 20), so each sample is ~10^6–10^7 particle-steps.
# Usage: scripts/bench_fast.sh [--sizes "1000 10000 100000"] [--threads "1 2"] [--repetitions R]
#                              [--settle-time T] [--no-million] [--settle-only] [--out DIR] [--build-dir DIR]
#   --sizes LIST     the bed sizes N (default "1000 10000 100000")
#   --threads LIST   the thread counts, timed interleaved (default "1 2")
#   --repetitions R  interleaved repetitions (default 5)
#   --settle-time T  simulated seconds of settling (default 0.4)
#   --no-million     without the loose lattice of 10^6
#   --settle-only    settle the beds (the slow, once-only part) and stop
#   --out DIR        the results in DIR (default results/fast)
#   --build-dir DIR  the build folder (default build, or $DEMMAT_BUILD_DIR)
source "$(dirname "$0")/lib.sh"
sizes="1000 10000 100000"; threads="1 2"; reps=5; settle=0.4; million=1; settle_only=0; outdir=results/fast
while [[ $# -gt 0 ]]; do
  case "$1" in
    --sizes) need_value "$@"; sizes=$2; shift 2 ;;
    --threads) need_value "$@"; threads=$2; shift 2 ;;
    --repetitions) need_value "$@"; reps=$2; shift 2 ;;
    --settle-time) need_value "$@"; settle=$2; shift 2 ;;
    --no-million) million=0; shift ;;
    --settle-only) settle_only=1; million=0; shift ;;
    --out) need_value "$@"; outdir=$2; shift 2 ;;
    *) shared_option "$@"; shift "$SHIFT" ;;
  esac
done
for n in $sizes; do positive_int "--sizes" "$n"; done
positive_int --repetitions "$reps"

install_deps
cmake_build "$BUILD_DIR" demmat
demmat=$(demmat_in "$BUILD_DIR")
mkdir -p scenes/generated states "$outdir"

for n in $sizes; do
  bed=scenes/generated/dense_bed_${n}.toml
  state=states/dense_bed_${n}_settled_fast.state
  settled=scenes/generated/dense_bed_${n}_settled.toml
  # The state and the settled scene derive from the bed: a bed the generator no longer makes goes, with them.
  $demmat scene dense-bed --n "$n" -o "$bed.new"
  if ! cmp -s "$bed.new" "$bed"; then rm -f "$state" "$settled"; mv "$bed.new" "$bed"; fi
  rm -f "$bed.new"
  if [[ ! -f "$state" ]]; then
    echo "== settling the dense bed of $n particles ($settle s simulated, fast on every core; done once)"
    $demmat run "$bed" --variant fast --time "$settle" --save "$state" -q --json "$outdir"/settle_${n}.json
  fi
  [[ $settle_only == 1 ]] && continue
  # The settled bed continuing from its state, walls at rest (demmat scene settled).
  [[ -f "$settled" ]] || $demmat scene settled --from "$bed" --state "$state" -o "$settled"
  steps=$(( 5000000 / n )); (( steps < 20 )) && steps=20
  # Every thread count in one run, interleaved with the variants, so that the speed-up compares samples
  # taken side by side (separate runs met different moods of the shared machine).
  echo "== N = $n, threads ${threads// /,}: $reps interleaved repetitions of $steps steps"
  out="$outdir"/bench_settled_${n}
  rm -f "$out"_t*.json "$out"_t*.txt  # the earlier layout, one run per thread count
  $demmat bench "$settled" --variants arrays,fast,fast_unordered --steps "$steps" --warmup 10 \
    --repetitions "$reps" --threads "${threads// /,}" --json "$out.json" | tee "$out.txt"
done
[[ $settle_only == 1 ]] && exit 0

if [[ $million == 1 ]]; then
  big=scenes/generated/dense_bed_1000000.toml
  $demmat scene dense-bed --n 1000000 -o "$big"
  # The loose lattice of 10^6 (settling it would take hours): every variant and thread count, interleaved.
  echo "== N = 1000000 (loose lattice), threads ${threads// /,}: 3 interleaved repetitions of 10 steps"
  $demmat bench "$big" --variants arrays,fast,fast_unordered --steps 10 --warmup 2 --repetitions 3 \
    --threads "${threads// /,}" --json "$outdir"/bench_loose_1000000.json | tee "$outdir"/bench_loose_1000000.txt
  echo "== 10^6 particles: 20 steps of fast from the loose lattice (memory and time)"
  /usr/bin/time -v $demmat run "$big" --variant fast --steps 20 -q --json "$outdir"/million.json \
    > "$outdir"/million.txt 2> "$outdir"/million_time.txt
  # time names the command as run: the binary's path on this machine, made relative to the checkout.
  sed -i "s|$PWD/||g" "$outdir"/million_time.txt
  grep -E "Maximum resident|Elapsed" "$outdir"/million_time.txt | tee -a "$outdir"/million.txt
  cat "$outdir"/million.txt
fi
$PYTHON analysis/summarise_fast.py "$outdir" -o "$outdir"/summary.md >/dev/null
echo "results in $outdir/ (table: $outdir/summary.md)"

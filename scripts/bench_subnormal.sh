#!/usr/bin/env bash
# What the rule for negligible derivatives (physics.md §3) changes in speed: two builds of the suite,
# one without the rule and one with it, run alternately (the order swapped every repetition, so that a
# drift of the machine hits both alike), and compared by paired ratios, with/without, per repetition:
#  (a) the main job's settle stage: the dense bed of N grains for 0.4 s from its loose grid, as
#      scripts/run_main.sh settles it (40000 steps), with fast and arrays on one thread: µs per step and
#      the predictor's share of the step;
#  (b) every variant (`demmat bench --variants all`, one thread) on the loose grid (t = 0) and on the
#      settled bed of N_b grains (default 1000, the peers' smallest N, whose timed steps reach furthest
#      into the fall), as run_peers.sh times them (10^6/N_b steps, at least 200, after 20 untimed):
#      µs per particle-step.
# Three streams run side by side, each alternating its two builds: the settle of fast, the settle of
# arrays, and (b), which settles its bed with fast once per build (0.4 s, untimed) and then alternates. The raw JSON goes to OUT/raw/; analysis/subnormal_table.py makes
# OUT/subnormal.md from it, naming both commits and the CPU.
# Usage: scripts/bench_subnormal.sh --before DIR --after DIR [--n N] [--bench-n N] [--parts LIST] [--repetitions R] [--arrays-repetitions R] [--out DIR]
#   --before DIR     the build folder without the rule (e.g. of a worktree at the commit before it)
#   --after DIR      the build folder with the rule
#   --n N            grains in the dense bed of (a) (default 2000, the main job's)
#   --bench-n N      grains of (b) (default 1000)
#   --parts LIST     "settle", "bench" or both (default "settle bench"); each replaces only its own files
#   --repetitions R  interleaved repetitions of each measurement (default 3)
#   --arrays-repetitions R  those of arrays' settle, the slowest (default: --repetitions)
#   --out DIR        where the results go (default results/subnormal)
source "$(dirname "$0")/lib.sh"
before=""; after=""; n=2000; nb=1000; parts="settle bench"; reps=3; areps=""; outdir=results/subnormal
while [[ $# -gt 0 ]]; do
  case "$1" in
    --before) need_value "$@"; before=$2; shift 2 ;;
    --after) need_value "$@"; after=$2; shift 2 ;;
    --n) need_value "$@"; n=$2; shift 2 ;;
    --bench-n) need_value "$@"; nb=$2; shift 2 ;;
    --parts) need_value "$@"; parts=$2; shift 2 ;;
    --repetitions) need_value "$@"; reps=$2; shift 2 ;;
    --arrays-repetitions) need_value "$@"; areps=$2; shift 2 ;;
    --out) need_value "$@"; outdir=$2; shift 2 ;;
    *) shared_option "$@"; shift "$SHIFT" ;;
  esac
done
positive_int --n "$n"
positive_int --bench-n "$nb"
for p in $parts; do [[ $p == settle || $p == bench ]] || { echo "$SCRIPT: --parts takes settle and bench, not '$p'" >&2; exit 2; }; done
positive_int --repetitions "$reps"
areps=${areps:-$reps}
positive_int --arrays-repetitions "$areps"
declare -A bin
for b in before after; do
  dir=${!b}
  [[ -n $dir ]] || { echo "$SCRIPT: --$b DIR is required" >&2; exit 2; }
  bin[$b]=$(demmat_in "$dir")
  [[ -x ${bin[$b]} ]] || { echo "$SCRIPT: no demmat program in '$dir' (build its demmat target first)" >&2; exit 2; }
done

raw=$outdir/raw
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$raw"
# dense_bed N: the scene file of the dense bed of N grains in $work, the same from both builds
dense_bed() {
  local f=$work/dense_bed_$1.toml
  "${bin[after]}" scene dense-bed --n "$1" -o "$f"
  "${bin[before]}" scene dense-bed --n "$1" -o "$f.before"
  cmp -s "$f" "$f.before" || { echo "$SCRIPT: the two builds write different dense beds" >&2; exit 2; }
}
order() { if (( $1 % 2 == 0 )); then echo before after; else echo after before; fi; }

# (a) the settle stage, a stream per variant.
settle() {
  local v=$1 count=$2 r b
  for ((r = 0; r < count; r++)); do
    for b in $(order "$r"); do
      "${bin[$b]}" run "$work/dense_bed_$n.toml" --variant "$v" --threads 1 --time 0.4 -q \
        --json "$raw/settle_${v}_n${n}_${b}_r$r.json" >/dev/null
    done
    echo "== settle stage, $v: repetition $((r + 1))/$count done"
  done
}
pids=()
if [[ " $parts " == *" settle "* ]]; then
  rm -f "$raw"/settle_*.json
  dense_bed "$n"
  settle fast "$reps" & pids+=($!)
  settle arrays "$areps" & pids+=($!)
fi

# (b) every variant on the loose grid and on the settled bed.
bench() {
  local stage=$1 r=$2 b=$3 scene=$work/dense_bed_$nb.toml
  [[ $stage == bed ]] && scene=$work/bed_$b.toml
  "${bin[$b]}" bench "$scene" --variants all --threads 1 --steps "$k" --warmup 20 --repetitions 1 \
    --json "$raw/bench_${stage}_n${nb}_${b}_r$r.json" >/dev/null
}
if [[ " $parts " == *" bench "* ]]; then
  rm -f "$raw"/bench_*.json
  dense_bed "$nb"
  k=$(( (1000000 + nb - 1) / nb )); (( k < 200 )) && k=200
  for b in before after; do
    "${bin[$b]}" run "$work/dense_bed_$nb.toml" --variant fast --time 0.4 -q --save "$work/settled_$b.state" >/dev/null
    "${bin[$b]}" scene settled --from "$work/dense_bed_$nb.toml" --state "$work/settled_$b.state" -o "$work/bed_$b.toml"
  done
  for ((r = 0; r < reps; r++)); do
    for stage in loose bed; do
      for b in $(order "$r"); do bench "$stage" "$r" "$b"; done
    done
    echo "== loose grid and settled bed: repetition $((r + 1))/$reps done"
  done
fi
(( ${#pids[@]} == 0 )) || wait "${pids[@]}"
# The scenes lived in a temporary folder: the results name them by file name alone.
sed -i "s#$work/##g" "$raw"/*.json

$PYTHON analysis/subnormal_table.py "$raw" -o "$outdir/subnormal.md"
echo "$outdir/subnormal.md"

#!/usr/bin/env bash
# What the rule for negligible derivatives (physics.md §3) changes in speed: two builds of the suite,
# one without the rule and one with it, run alternately (the order swapped every repetition, so that a
# drift of the machine hits both alike), and compared by paired ratios, with/without, per repetition:
#  (a) the main job's settle stage: the dense bed of N grains for 0.4 s from its loose grid, as
#      scripts/run_main.sh settles it (40000 steps), with fast and arrays on one thread: µs per step and
#      the predictor's share of the step;
#  (b) every variant (`demmat bench --variants all`, one thread) on the loose grid (t = 0) and on the
#      bed that its build settled in (a), as run_peers.sh times them (10^6/N steps, at least 200, after 20
#      untimed): µs per particle-step.
# Three streams run side by side, each alternating its two builds: the settle of fast, the settle of
# arrays, and (b), which starts on the loose grid and takes up the settled beds once the fast stream's
# first pair has saved them. The raw JSON goes to OUT/raw/; analysis/subnormal_table.py makes
# OUT/subnormal.md from it, naming both commits and the CPU.
# Usage: scripts/bench_subnormal.sh --before DIR --after DIR [--n N] [--repetitions R] [--arrays-repetitions R] [--out DIR]
#   --before DIR     the build folder without the rule (e.g. of a worktree at the commit before it)
#   --after DIR      the build folder with the rule
#   --n N            grains in the dense bed (default 2000, the main job's)
#   --repetitions R  interleaved repetitions of each measurement (default 3)
#   --arrays-repetitions R  those of arrays' settle, the slowest (default: --repetitions)
#   --out DIR        where the results go (default results/subnormal)
source "$(dirname "$0")/lib.sh"
before=""; after=""; n=2000; reps=3; areps=""; outdir=results/subnormal
while [[ $# -gt 0 ]]; do
  case "$1" in
    --before) need_value "$@"; before=$2; shift 2 ;;
    --after) need_value "$@"; after=$2; shift 2 ;;
    --n) need_value "$@"; n=$2; shift 2 ;;
    --repetitions) need_value "$@"; reps=$2; shift 2 ;;
    --arrays-repetitions) need_value "$@"; areps=$2; shift 2 ;;
    --out) need_value "$@"; outdir=$2; shift 2 ;;
    *) shared_option "$@"; shift "$SHIFT" ;;
  esac
done
positive_int --n "$n"
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
rm -f "$raw"/*.json
bed=$work/dense_bed_${n}.toml
"${bin[after]}" scene dense-bed --n "$n" -o "$bed"
"${bin[before]}" scene dense-bed --n "$n" -o "$work/bed_before.toml"
cmp -s "$bed" "$work/bed_before.toml" || { echo "$SCRIPT: the two builds write different dense beds" >&2; exit 2; }

order() { if (( $1 % 2 == 0 )); then echo before after; else echo after before; fi; }

# (a) the settle stage, a stream per variant; fast's first pair also saves each build's settled state.
settle() {
  local v=$1 count=$2 r b save
  for ((r = 0; r < count; r++)); do
    for b in $(order "$r"); do
      save=(); [[ $r == 0 && $v == fast ]] && save=(--save "$work/settled_$b.state")
      "${bin[$b]}" run "$bed" --variant "$v" --threads 1 --time 0.4 -q --json "$raw/settle_${v}_${b}_r$r.json" "${save[@]}" >/dev/null
    done
    echo "== settle stage, $v: repetition $((r + 1))/$count done"
  done
}
settle fast "$reps" & fast_pid=$!
settle arrays "$areps" & arrays_pid=$!

# (b) every variant on the loose grid, then on the settled bed.
k=$(( (1000000 + n - 1) / n )); (( k < 200 )) && k=200
bench() {
  local stage=$1 r=$2 b=$3 scene=$bed
  [[ $stage == bed ]] && scene=$work/bed_$b.toml
  "${bin[$b]}" bench "$scene" --variants all --threads 1 --steps "$k" --warmup 20 --repetitions 1 \
    --json "$raw/bench_${stage}_${b}_r$r.json" >/dev/null
}
for ((r = 0; r < reps; r++)); do
  for b in $(order "$r"); do bench loose "$r" "$b"; done
  echo "== loose grid: repetition $((r + 1))/$reps done"
done
while [[ ! -f $work/settled_before.state || ! -f $work/settled_after.state ]]; do
  kill -0 "$fast_pid" 2>/dev/null || { echo "$SCRIPT: the settle of fast failed" >&2; exit 1; }
  sleep 5
done
for b in before after; do
  "${bin[$b]}" scene settled --from "$bed" --state "$work/settled_$b.state" -o "$work/bed_$b.toml"
done
for ((r = 0; r < reps; r++)); do
  for b in $(order "$r"); do bench bed "$r" "$b"; done
  echo "== settled bed: repetition $((r + 1))/$reps done"
done
wait "$fast_pid" "$arrays_pid"

$PYTHON analysis/subnormal_table.py "$raw" -o "$outdir/subnormal.md"
echo "$outdir/subnormal.md"

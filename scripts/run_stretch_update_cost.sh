#!/usr/bin/env bash
# What the trapezoidal stretch update (physics.md §9) costs against LAMMPS's first-order one, per
# particle-step in `fast`: the dense bed settled under mindlin and mindlin + sds with each update (walls at
# rest) and its compression stage, `demmat bench` of the two updates one after the other in each round,
# the order alternated between rounds; analysis/stretch_update_cost.py takes each round's ratio (a paired
# ratio) and writes results/memory_cost/stretch_update.md.
# Usage: scripts/run_stretch_update_cost.sh [--n N] [--steps K] [--rounds R] [--threads T] [--build-dir DIR]
source "$(dirname "$0")/lib.sh"
n=2000; steps=500; rounds=7; threads=1; settle=0.3; out=results/memory_cost
while [[ $# -gt 0 ]]; do
  case "$1" in
    --n) need_value "$@"; n=$2; shift 2 ;;
    --steps) need_value "$@"; steps=$2; shift 2 ;;
    --rounds) need_value "$@"; rounds=$2; shift 2 ;;
    --threads) need_value "$@"; threads=$2; shift 2 ;;
    *) shared_option "$@"; shift "$SHIFT" ;;
  esac
done
positive_int --n "$n"; positive_int --steps "$steps"; positive_int --rounds "$rounds"; positive_int --threads "$threads"

contact_args() {  # the laws of scripts/run_memory_cost.sh, and the update
  local a="--contact tangential=mindlin --contact tangential_damping_ratio=0.5 --contact stretch_update=$2"
  [[ $1 == mindlin_sds ]] && a+=" --contact rolling=sds --contact kr=50 --contact rolling_damping=0.05 --contact rolling_friction=0.2"
  echo "$a"
}

cmake_build -q "$BUILD_DIR" demmat
demmat=$(demmat_in "$BUILD_DIR")
work=scenes/generated/stretch_update_cost_$n
mkdir -p "$work" states "$out"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
for law in mindlin mindlin_sds; do
  for update in first_order trapezoidal; do
    bed=$work/bed_${law}_$update.toml
    # shellcheck disable=SC2046  # contact_args is a list of words on purpose
    [[ -f $bed ]] || $demmat scene dense-bed --n "$n" $(contact_args "$law" "$update") -o "$bed"
    state=states/stretch_update_cost_${n}_${law}_${update}.state
    [[ -f $state ]] || $demmat run "$bed" --variant fast --threads "$JOBS" --time "$settle" --save "$state" -q >/dev/null
    [[ -f $work/settled_${law}_$update.toml ]] || $demmat scene settled --from "$bed" --state "$state" -o "$work/settled_${law}_$update.toml"
    [[ -f $work/compression_${law}_$update.toml ]] || $demmat scene compression --from "$bed" --state "$state" -o "$work/compression_${law}_$update.toml"
  done
done
printf 'law\tupdate\tstage\tround\tfile\n' >"$tmp/runs.tsv"
for ((r = 1; r <= rounds; r++)); do
  for law in mindlin mindlin_sds; do
    for stage in settled compression; do
      pair=(first_order trapezoidal); ((r % 2)) || pair=(trapezoidal first_order)
      for update in "${pair[@]}"; do
        file=stretch_update_${law}_${stage}_${update}_r$r.json
        $demmat bench "$work/${stage}_${law}_$update.toml" --variants fast --steps "$steps" --repetitions 1 --threads "$threads" \
          --json "$out/$file" >/dev/null 2>"$tmp/bench.log" || { cat "$tmp/bench.log" >&2; exit 1; }
        printf '%s\t%s\t%s\t%d\t%s\n' "$law" "$update" "$stage" "$r" "$file" >>"$tmp/runs.tsv"
      done
    done
  done
  echo "== round $r/$rounds done"
done
mv "$tmp/runs.tsv" "$out/stretch_update_runs.tsv"
$PYTHON analysis/stretch_update_cost.py "$out/stretch_update_runs.tsv" --table "$out/stretch_update.md"
echo "results: $out/stretch_update.md"

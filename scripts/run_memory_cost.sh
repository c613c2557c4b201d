#!/usr/bin/env bash
# What contact memory costs each style: µs per particle-step and bytes per particle of every registered
# variant that runs the law and of the mpi variant at one process (where Open MPI is here), under the paper's law, linear_history, mindlin and mindlin + sds (physics.md
# §9), on the settled dense bed and on the compression stage. Each law's bed is settled once with fast
# (a state carries its law in its fingerprint, so each law settles its own); then R rounds, each timing
# every (law, stage) with `demmat bench` (the variants interleaved inside it, one repetition), the
# (law, stage) order rotated from round to round, so that a shared machine's drift hits all alike; the
# medians over the rounds and the bytes each variant holds (Variant::memory_bytes) go into a table and a
# figure (analysis/plot_memory_cost.py). Every variant runs on one thread (--threads to change it).
# Budget: about 2 minutes of settling and 30 s a round on 2 cores at the defaults, once built.
# Usage: scripts/run_memory_cost.sh [--n N] [--steps K] [--repetitions R] [--settle-time T] [--threads LIST] [--variants LIST] [--out DIR] [--build-dir DIR]
#   --n N            grains in the dense bed (default 2000)
#   --steps K        timed steps per bench run (default 500)
#   --repetitions R  rounds over every (law, stage) (default 5)
#   --settle-time T  simulated seconds of settling per law (default 0.4)
#   --threads LIST   thread counts for the threaded variants, as demmat bench --threads (default 1)
#   --variants LIST  comma-separated variants to consider (default every registered one that runs here)
#   --out DIR        results folder (default results/memory_cost; the figure goes beside the table)
#   --build-dir DIR  the build folder (default build, or $DEMMAT_BUILD_DIR)
source "$(dirname "$0")/lib.sh"
n=2000; steps=500; reps=5; settle=0.4; threads=1; variants=all; out=results/memory_cost
while [[ $# -gt 0 ]]; do
  case "$1" in
    --n) need_value "$@"; n=$2; shift 2 ;;
    --steps) need_value "$@"; steps=$2; shift 2 ;;
    --repetitions) need_value "$@"; reps=$2; shift 2 ;;
    --settle-time) need_value "$@"; settle=$2; shift 2 ;;
    --threads) need_value "$@"; threads=$2; shift 2 ;;
    --variants) need_value "$@"; variants=$2; shift 2 ;;
    --out) need_value "$@"; out=$2; shift 2 ;;
    *) shared_option "$@"; shift "$SHIFT" ;;
  esac
done
positive_int --n "$n"; positive_int --steps "$steps"; positive_int --repetitions "$reps"
if ! [[ $settle =~ ^[0-9]*\.?[0-9]+$ ]] || ! awk -v t="$settle" 'BEGIN { exit !(t > 0) }'; then
  echo "$SCRIPT: --settle-time must be a positive number of seconds, not '$settle'" >&2; exit 2
fi
[[ $threads =~ ^[0-9]+(,[0-9]+)*$ ]] || { echo "$SCRIPT: --threads must be thread counts such as 1 or 1,2, not '$threads'" >&2; exit 2; }

# The laws (their [contact] keys: contact_args, lib.sh).
laws=(paper linear_history mindlin mindlin_sds)

cmake_build -q "$BUILD_DIR" demmat
demmat=$(demmat_in "$BUILD_DIR")
# The mpi variant (not in the registry) at one process, where Open MPI is here: its own style of keeping
# the stretches, without the exchanges. Left out, with a line, where demmat_mpi does not build.
demmat_mpi=
if [[ $variants == all || ,$variants, == *,mpi,* ]]; then
  if cmake --build "$BUILD_DIR" -j "$JOBS" --target demmat_mpi >/dev/null 2>&1; then
    demmat_mpi=${demmat%/demmat}/demmat_mpi
    export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
  else
    echo "$SCRIPT: the mpi variant is left out: demmat_mpi does not build here (Open MPI: scripts/install_deps.sh)" >&2
  fi
  variants=${variants//mpi/}; variants=${variants//,,/,}; variants=${variants#,}; variants=${variants%,}; [[ -n $variants ]] || variants=all
fi
work=scenes/generated/memory_cost_$n
mkdir -p "$work" states "$out"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT

# Per law: the bed, settled once (kept in states/), the settled bed continuing with its walls at rest,
# and the compression stage; and the registered variants that run the law (a one-step probe: a variant
# that does not implement it refuses it with one line; one unavailable here is left out by demmat list).
available=$($demmat list | awk '$2 != "unavailable:" { print $1 }')
if [[ $variants != all ]]; then
  for v in ${variants//,/ }; do
    grep -qx "$v" <<<"$available" || { echo "$SCRIPT: --variants: '$v' is not a variant that runs here ($demmat list)" >&2; exit 2; }
  done
  available=${variants//,/ }
fi
declare -A runs_law
for law in "${laws[@]}"; do
  bed=$work/bed_$law.toml
  # shellcheck disable=SC2046  # contact_args is a list of words on purpose
  [[ -f $bed ]] || $demmat scene dense-bed --n "$n" $(contact_args "$law") -o "$bed"
  state=states/memory_cost_${n}_${law}_settled.state
  if [[ ! -f $state ]]; then
    echo "== settling the bed of $n grains under $law for $settle s (fast, bit-identical to arrays; once, kept in states/)"
    $demmat run "$bed" --variant fast --threads "$JOBS" --time "$settle" --save "$state" -q >/dev/null
  fi
  comp=$work/compression_$law.toml
  [[ -f $comp ]] || $demmat scene compression --from "$bed" --state "$state" -o "$comp"
  # The settled bed: the settled state with every wall still.
  rest=$work/settled_$law.toml
  [[ -f $rest ]] || $demmat scene settled --from "$bed" --state "$state" -o "$rest"
  vs=()
  for v in $available; do
    $demmat run "$rest" --variant "$v" --steps 1 --threads 1 -q >/dev/null 2>"$tmp/probe" && vs+=("$v")
  done
  runs_law[$law]=$(IFS=,; echo "${vs[*]}")
  echo "== $law: ${runs_law[$law]}"
done

# The rounds: every (law, stage) once per round, the order rotated; runs.tsv says which file is which.
cases=()
for law in "${laws[@]}"; do cases+=("$law settled" "$law compression"); done
manifest=$out/runs.tsv
printf 'law\tstage\tround\tfile\n' >"$tmp/runs.tsv"
for ((r = 0; r < reps; r++)); do
  for ((q = 0; q < ${#cases[@]}; q++)); do
    read -r law stage <<<"${cases[(q + r) % ${#cases[@]}]}"
    scene=$work/${stage}_$law.toml
    file=bench_${law}_${stage}_r$((r + 1)).json
    $demmat bench "$scene" --variants "${runs_law[$law]}" --steps "$steps" --repetitions 1 --threads "$threads" \
      --json "$out/$file" >/dev/null 2>"$tmp/bench.log" || { cat "$tmp/bench.log" >&2; exit 1; }
    printf '%s\t%s\t%d\t%s\n' "$law" "$stage" $((r + 1)) "$file" >>"$tmp/runs.tsv"
    if [[ -n $demmat_mpi ]]; then
      file=bench_mpi_${law}_${stage}_r$((r + 1)).json
      mpirun --bind-to core -np 1 "$demmat_mpi" bench "$scene" --steps "$steps" --repetitions 1 --json "$out/$file" >/dev/null 2>"$tmp/bench.log" \
        || { cat "$tmp/bench.log" >&2; exit 1; }
      printf '%s\t%s\t%d\t%s\n' "$law" "$stage" $((r + 1)) "$file" >>"$tmp/runs.tsv"
    fi
  done
  echo "== round $((r + 1))/$reps done"
done
mv "$tmp/runs.tsv" "$manifest"

$PYTHON analysis/plot_memory_cost.py "$manifest" --table "$out/table.md" --csv "$out/table.csv" --figure "$out/memory_cost.png"
echo "results: $out/table.md, $out/table.csv, $out/memory_cost.png"

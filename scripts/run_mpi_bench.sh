#!/usr/bin/env bash
# The mpi variant's benchmark (docs/scaling.md): on the settled dense bed of N particles, in one run with
# the configurations interleaved (their order rotated every repetition),
#   mpi at R = 1 and 2 processes (mpirun -np R demmat_mpi bench),
#   fast on 1 and 2 threads (demmat bench --threads 1,2),
#   LAMMPS on 2 processes (mpirun -np 2 lmp) on the same particles and law (demmat export-lammps),
# each a median of µs per particle-step; then the halo traffic (messages and bytes per step per rank,
# ghosts per rank) of mpi at R = 2 and 4 for every N of --halo-n, measured on the dense bed's lattice
# (a few steps from t = 0: the counts, not the times, are what is kept); the imbalance of the static
# bricks on the bed and the compression stage (cut by count and evenly); then the scaling model of
# docs/scaling.md from these measurements (analysis/mpi_scaling.py). Results in results/mpi/.
# Usage: scripts/run_mpi_bench.sh [--n "100000"] [--halo-n "10000 100000 1000000"] [--steps K] [--repetitions R]
#                                 [--settle-time T] [--imbalance-steps K] [--out DIR] [--build-dir DIR]
#   default          N = 10^5; 200 steps, 5 repetitions; halo at N = 10^4, 10^5, 10^6; beds settled 0.4 s
#   --n LIST         the sizes of the timed comparison;  --halo-n LIST: the sizes of the halo measurement
#   --settle-time T  simulated seconds of settling before the timed runs (0.4; a tiny test passes less)
#   --imbalance-steps K  steps of the imbalance runs (5000: the compression wall moves 2.5 cm)
#   --out DIR        results in DIR instead of results/mpi
#   --build-dir DIR  the build folder (default build, or $DEMMAT_BUILD_DIR); work files in DIR/mpi_bench
source "$(dirname "$0")/lib.sh"
ns="100000"; halo_ns="10000 100000 1000000"; steps=200; reps=5; settle=0.4; warmup=20; out=results/mpi; imb_steps=5000
while [[ $# -gt 0 ]]; do
  case "$1" in
    --n) need_value "$@"; ns=$2; shift 2 ;;
    --halo-n) need_value "$@"; halo_ns=$2; shift 2 ;;
    --steps) need_value "$@"; steps=$2; shift 2 ;;
    --repetitions) need_value "$@"; reps=$2; shift 2 ;;
    --settle-time) need_value "$@"; settle=$2; shift 2 ;;
    --imbalance-steps) need_value "$@"; imb_steps=$2; shift 2 ;;
    --out) need_value "$@"; out=$2; shift 2 ;;
    *) shared_option "$@"; shift "$SHIFT" ;;
  esac
done
for n in $ns $halo_ns; do positive_int --n "$n"; done
positive_int --steps "$steps"; positive_int --repetitions "$reps"; positive_int --imbalance-steps "$imb_steps"
[[ $settle =~ ^[0-9]*\.?[0-9]+([eE]-?[0-9]+)?$ ]] || { echo "$SCRIPT: --settle-time must be a number of seconds, not '$settle'" >&2; exit 2; }
(( steps > warmup )) || warmup=1

install_deps
cmake_build -q "$BUILD_DIR" demmat demmat_mpi
demmat=$(demmat_in "$BUILD_DIR")
demmat_mpi=${demmat%/demmat}/demmat_mpi
lmp=$(command -v lmp || true)
[[ -n $lmp ]] || echo "$SCRIPT: LAMMPS (lmp) is not installed (scripts/install_deps.sh --optional): its column is left out" >&2
# Open MPI refuses root unless told. The timed runs bind each rank to a core (Open MPI's default at R <= 2);
# the halo counts at R = 4 share the 2 cores (--oversubscribe, unbound: their times are not kept).
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMP_NUM_THREADS=1
mpirun=(mpirun --bind-to core)
mpirun_shared=(mpirun --oversubscribe --bind-to none)
work=${demmat%/app/demmat}/mpi_bench
mkdir -p "$work" "$out"
rm -f "$work"/*.json "$work"/lammps_*.out

# The dense bed of N grains: the loose lattice, settled once (fast on every core: bit-identical to arrays),
# the settled bed as a scene of its own, and its LAMMPS data file.
prepare() {
  local n=$1 d=$work/n$1
  mkdir -p "$d"
  $demmat scene dense-bed --n "$n" -o "$d/loose.toml.new"
  if ! cmp -s "$d/loose.toml.new" "$d/loose.toml"; then
    find "$d" -mindepth 1 ! -name loose.toml.new -delete
    mv "$d/loose.toml.new" "$d/loose.toml"
  fi
  rm -f "$d/loose.toml.new"
  if [[ ! -f $d/settled_$settle.state ]]; then
    echo "== settling the dense bed of $n particles ($settle s simulated, once; kept in $d)"
    $demmat run "$d/loose.toml" --variant fast --threads "$JOBS" --time "$settle" --save "$d/settled_$settle.state" --quiet >/dev/null
    rm -f "$d/bed.toml" "$d/bed.data" "$d/bed.lammps" "$d/compression.toml"
  fi
  # The settled bed: the loose scene with its particles from the state (the [particles] table is the last).
  [[ -f $d/bed.toml ]] || { sed '/^\[particles\]/,$d' "$d/loose.toml"; printf '[particles]\nsource = "state"\nfile = "settled_%s.state"\n' "$settle"; } \
    > "$d/bed.toml"
  [[ -f $d/bed.data || -z $lmp ]] || $demmat export-lammps "$d/bed.toml" -o "$d/bed.data"
}

loop_time() { grep "^Loop time of" "$1" | tail -1 | awk '{print $4}'; }

for n in $ns; do prepare "$n"; done
configs=(fast mpi1 mpi2); [[ -n $lmp ]] && configs+=(lammps2)
for ((r = 0; r < reps; r++)); do
  for n in $ns; do
    d=$work/n$n
    for ((q = 0; q < ${#configs[@]}; q++)); do
      c=${configs[$(((q + r) % ${#configs[@]}))]}
      case $c in
        fast) $demmat bench "$d/bed.toml" --variants fast --threads 1,2 --steps "$steps" --warmup "$warmup" --repetitions 1 \
                --json "$work/fast_n${n}_r$r.json" >/dev/null 2>&1 ;;
        mpi1|mpi2) "${mpirun[@]}" -np "${c#mpi}" "$demmat_mpi" bench "$d/bed.toml" --steps "$steps" --warmup "$warmup" --repetitions 1 \
                     --json "$work/mpi${c#mpi}_n${n}_r$r.json" >/dev/null ;;
        lammps2)
          (cd "$d" && "${mpirun[@]}" -np 2 "$lmp" -var frag bed.lammps -var warmup "$warmup" -var steps "$steps" \
             -in "$OLDPWD/peers/lammps/in.bench" -log none -nocite > "$work/lammps_n${n}_r$r.out" 2>&1)
          echo "{\"code\": \"lammps\", \"processes\": 2, \"particles\": $n, \"repetition\": $r, \"steps\": $steps, \"seconds\": $(loop_time "$work/lammps_n${n}_r$r.out")}" \
            > "$work/lammps_n${n}_r$r.json" ;;
      esac
    done
  done
  echo "== repetition $((r + 1))/$reps done"
done

# Halo traffic: counts per step per rank on the lattice of N grains (deterministic: the machine's load
# changes the times, not the counts).
for n in $halo_ns; do
  $demmat scene dense-bed --n "$n" -o "$work/halo_n$n.toml"
  for np in 2 4; do
    "${mpirun_shared[@]}" -np "$np" "$demmat_mpi" run "$work/halo_n$n.toml" --steps 5 --json "$work/halo_n${n}_np$np.json" -q >/dev/null
  done
done

# Imbalance of the static bricks: the settled bed and the compression stage (the x_max wall moving in at
# 0.5 m/s: the bricks by the wall empty), cut by count and evenly, at R = 2 and 4 (the planner's grids);
# the counts per rank, not the times, are what is kept (R = 4 shares the cores).
for n in $ns; do
  d=$work/n$n
  [[ -f $d/compression.toml ]] || $demmat scene compression --from "$d/loose.toml" --state "$d/settled_$settle.state" -o "$d/compression.toml"
  for stage in bed compression; do
    for balance in count even; do
      for np in 2 4; do
        "${mpirun_shared[@]}" -np "$np" "$demmat_mpi" run "$d/$stage.toml" --steps "$imb_steps" --balance "$balance" \
          --json "$work/imbalance_n${n}_${stage}_${balance}_np$np.json" -q >/dev/null
      done
    done
  done
done

versions="$work/versions.json"
{
  echo "{"
  echo "  \"mpi\": \"$(mpirun --version 2>/dev/null | head -1)\","
  echo "  \"lammps_package\": \"$(dpkg-query -W -f='${Version}' lammps 2>/dev/null)\""
  echo "}"
} > "$versions"
$PYTHON analysis/mpi_bench.py --work "$work" --versions "$versions" --out "$out"
# The model of docs/scaling.md from these measurements (the network's figures are its defaults, cited there).
[[ -f $out/halo_mpi.csv ]] && $PYTHON analysis/mpi_scaling.py --bench "$out/bench_mpi.json" --halo "$out/halo_mpi.csv" --out "$out"
echo "$SCRIPT: results in $out"

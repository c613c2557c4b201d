#!/usr/bin/env bash
# The suite side by side with LAMMPS and LIGGGHTS on the same scenes (docs/peers.md): installs the peers
# (Debian's lammps and liggghts) and LAMMPS built on this machine (scripts/build_lammps.sh: -O3
# -march=native, GRANULAR and OPENMP), builds, settles the dense beds, exports every stage as a LAMMPS
# data file so that every code starts from the identical particles, then
#  1. the peer benchmark: every code on one core (OMP_NUM_THREADS=1, no MPI) for the loose grid, the
#     settled bed and the compression stage, N in the list, repetitions interleaved (the codes' order
#     rotated every repetition), timings from each code's own loop time and its phases; results/peers/bench_*.
#     LAMMPS built here is the reference, Debian's binary a second row; with --threads, the suite's
#     threaded variants and LAMMPS built here with its OPENMP package (-sf omp -pk omp T) on T threads too.
#  2. the physics cross-check: an ensemble of perturbed starts per code from the same particles, the
#     kinetic energy and bed height while settling, the wall force while compressing; results/peers/physics_*.
# Usage: scripts/run_peers.sh [--full] [--n "1000 2000"] [--steps K] [--repetitions R] [--variants LIST]
#                             [--threads "1 2"] [--members M] [--physics-n N] [--bench-only] [--physics-only]
#                             [--prepare-only] [--contact "KEY=VALUE ..."] [--diagnose] [--no-liggghts]
#                             [--note TEXT] [--out DIR] [--build-dir DIR]
#   default          N = 1000, 2000, 4000; 200 steps; 3 repetitions; every variant; one thread;
#                    4 ensemble members
#   --full           N = 1000 … 64000 (doubling), 500 steps, 5 repetitions, threads 1 and 2, 8 ensemble
#                    members (the lead's run)
#   --threads LIST   the thread counts of the benchmark: 1 times every code on one core; T > 1 the suite's
#                    threaded variants on T threads beside LAMMPS built here with -sf omp -pk omp T
#   --no-liggghts    LIGGGHTS left out (a run about the suite and LAMMPS alone)
#   --note TEXT      a sentence for the results' header (what the tables cannot say: a shared machine)
#   --steps K        the timed steps of each run, at least: a small N runs more, so that every timed run
#                    holds at least 10^6 particle-steps (1000 steps at N = 1000), long enough that a burst
#                    of another tenant's work on the shared machine is a small part of it
#   --n LIST         the sizes N of the benchmark;  --physics-n N: the size of the physics cross-check (2000)
#   --bench-only, --physics-only   one of the two parts
#   --prepare-only   settle and export the stages of every N (the slow part, done once), then stop
#   --contact LIST   every stage with this contact law of physics.md §9 (the [contact] keys, as for
#                    `demmat scene --contact`), e.g. "tangential=mindlin tangential_damping_ratio=0.5";
#                    the bed settled with the law, every code with the law from the same particles
#                    (LAMMPS's pair_style granular keywords, docs/peers.md); LIGGGHTS is left out
#   --diagnose       three more rows in the physics cross-check, removing the known differences from
#                    LAMMPS (physics.md §9): the suite built with LAMMPS's lever arms and half-step
#                    velocity (DEMMAT_LEVER_ARMS=lammps, DEMMAT_VERLET_VELOCITY=half_step, in DIR-as-lammps
#                    beside the build folder) run with Gear (the arms alone) and with velocity Verlet (every
#                    listed difference removed), and LAMMPS at half the time step (its own time-step error);
#                    and single contacts of the same law, each code against LAMMPS (single_contacts.md)
#   --out DIR        results and figures in DIR instead of results/peers and results/figures (a second,
#                    focused run beside the full one)
#   --build-dir DIR  the build folder (default build, or $DEMMAT_BUILD_DIR); the peers' work files go
#                    in DIR/peers
source "$(dirname "$0")/lib.sh"
ns="1000 2000 4000"; steps=200; reps=3; variants=all; members=4; phys_n=2000; warmup=20
do_bench=1; do_phys=1; prepare_only=0; diagnose=0; out=results/peers; figures=results/figures; contact=""
threads=1; note=""; no_liggghts=0
while [[ $# -gt 0 ]]; do
  case "$1" in
    --full) ns="1000 2000 4000 8000 16000 32000 64000"; steps=500; reps=5; threads="1 2"; members=8; shift ;;
    --n) need_value "$@"; ns=$2; shift 2 ;;
    --steps) need_value "$@"; steps=$2; shift 2 ;;
    --repetitions) need_value "$@"; reps=$2; shift 2 ;;
    --variants) need_value "$@"; variants=$2; shift 2 ;;
    --threads) need_value "$@"; threads=$2; shift 2 ;;
    --note) need_value "$@"; note=$2; shift 2 ;;
    --no-liggghts) no_liggghts=1; shift ;;
    --members) need_value "$@"; members=$2; shift 2 ;;
    --physics-n) need_value "$@"; phys_n=$2; shift 2 ;;
    --bench-only) do_phys=0; shift ;;
    --physics-only) do_bench=0; shift ;;
    --prepare-only) prepare_only=1; shift ;;
    --out) need_value "$@"; out=$2; figures=$2; shift 2 ;;
    --contact) need_value "$@"; contact=$2; shift 2 ;;
    --diagnose) diagnose=1; shift ;;
    *) shared_option "$@"; shift "$SHIFT" ;;
  esac
done
for n in $ns; do positive_int --n "$n"; done
for t in $threads; do positive_int --threads "$t"; done
positive_int --steps "$steps"; positive_int --repetitions "$reps"; positive_int --members "$members"
positive_int --physics-n "$phys_n"

install_deps --optional
# LAMMPS built here: only the benchmark times it (the physics cross-check runs Debian's binary).
lmp_native=""
if [[ $do_bench == 1 && $prepare_only == 0 ]]; then lmp_native=$(scripts/build_lammps.sh --build-dir "$BUILD_DIR"); fi
cmake_build -q "$BUILD_DIR" demmat
demmat=$(demmat_in "$BUILD_DIR")
if [[ $diagnose == 1 && $do_phys == 1 ]]; then
  cmake_build -q "${BUILD_DIR%/}-as-lammps" demmat -- -DDEMMAT_LEVER_ARMS=lammps -DDEMMAT_VERLET_VELOCITY=half_step
  demmat_as_lammps=$(demmat_in "${BUILD_DIR%/}-as-lammps")
fi
lmp=$(command -v lmp || true)
liggghts=$(command -v liggghts || true)
[[ $no_liggghts == 1 ]] && liggghts=""
# A contact law: its stages live in a folder of their own beside the paper's (law_<keys>), its scene
# options are checked now (a scene of one grain), before any settling.
contact_args=(); law_dir=""
if [[ -n $contact ]]; then
  for kv in $contact; do contact_args+=(--contact "$kv"); done
  law_dir=law_$(tr -c 'A-Za-z0-9=._\n-' '_' <<<"$contact" | tr ' =' '_-' | head -c 120)
  check=$(mktemp -d)
  $demmat scene drop "${contact_args[@]}" -o "$check/law.toml" >/dev/null || { rm -rf "$check"; exit 2; }
  rm -rf "$check"
  liggghts=""  # LIGGGHTS's history models take other parameters: the export writes no fragment for a §9 law
fi
[[ -n "$lmp" ]] || { echo "run_peers.sh: LAMMPS (lmp) is not installed; scripts/install_deps.sh --optional installs it" >&2; exit 1; }
export OMP_NUM_THREADS=1   # one core for every code; no mpirun
work=${demmat%/app/demmat}/peers  # scenes, states, data files and raw outputs (large, not kept in the repository)
mkdir -p "$work" "$out"

# Versions of the peers, for the results' provenance.
{
  echo "{"
  echo "  \"lammps\": \"$($lmp -h | sed -n 's/^Large-scale Atomic.Molecular Massively Parallel Simulator - //p' | head -1)\","
  echo "  \"lammps_package\": \"$(dpkg-query -W -f='${Version}' lammps 2>/dev/null)\","
  if [[ -n $lmp_native ]]; then
    echo "  \"lammps_native\": \"$($lmp_native -h | sed -n 's/^Large-scale Atomic.Molecular Massively Parallel Simulator - //p' | head -1)\","
    echo "  \"lammps_native_flags\": \"-O3 -march=native\","
    echo "  \"lammps_native_build\": \"$(scripts/build_lammps.sh --build-dir "$BUILD_DIR" --print-stamp)\","
  fi
  [[ -n $note ]] && echo "  \"note\": $($PYTHON -c 'import json, sys; print(json.dumps(sys.argv[1]))' "$note"),"
  if [[ -n "$liggghts" ]]; then
    echo "  \"liggghts\": \"$($liggghts -h 2>&1 | sed -n 's/^LIGGGHTS (Version \([^,]*\),.*/\1/p' | head -1)\","
    echo "  \"liggghts_package\": \"$(dpkg-query -W -f='${Version}' liggghts 2>/dev/null)\","
  fi
  echo "  \"contact_law\": \"${contact:-paper (physics.md section 2)}\","
  echo "  \"mpi\": \"none (one process per run; OMP_NUM_THREADS=1, more threads only where --threads asks)\""
  echo "}"
} > "$work/versions.json"

# The three stages for N particles: loose grid (t = 0), settled bed (0.4 s, all walls fixed) and the
# compression stage (x_max moving in at 0.5 m/s), each exported for the peers.
settler=arrays; grep -q "^fast " <<<"$($demmat list)" && settler=fast
# The folder of N's stages: n<N> for the paper's law, n<N>_law_<keys> for a §9 law (settled with that law:
# a state belongs to its scene's law, physics.md §9).
stage_dir() { echo "$work/n$1${law_dir:+_$law_dir}"; }
prepare() {
  local n=$1 d; d=$(stage_dir "$1")
  mkdir -p "$d"
  # Everything kept here derives from the bed: a bed the generator no longer makes is dropped, with all of it.
  $demmat scene dense-bed --n "$n" "${contact_args[@]}" -o "$d/loose.toml.new"
  if ! cmp -s "$d/loose.toml.new" "$d/loose.toml"; then
    find "$d" -mindepth 1 ! -name loose.toml.new -delete
    mv "$d/loose.toml.new" "$d/loose.toml"
  fi
  rm -f "$d/loose.toml.new"
  if [[ ! -f $d/settled.state ]]; then
    echo "== settling the dense bed of $n particles (0.4 s simulated, once; kept in $d)"
    # fast on every core where it is built: bit-identical to arrays, so the same settled state, sooner.
    # A variant that does not run the scene's law refuses at once (exit 2): arrays, which runs every law, then.
    local rc=0
    $demmat run "$d/loose.toml" --variant "$settler" --threads "$JOBS" --time 0.4 --save "$d/settled.state" --quiet >/dev/null 2>&1 || rc=$?
    if [[ $rc == 2 && $settler != arrays ]]; then
      $demmat run "$d/loose.toml" --variant arrays --time 0.4 --save "$d/settled.state" --quiet >/dev/null
    elif [[ $rc != 0 ]]; then
      $demmat run "$d/loose.toml" --variant "$settler" --threads "$JOBS" --time 0.4 --save "$d/settled.state" --quiet >/dev/null
    fi
  fi
  [[ -f $d/compression.toml ]] || $demmat scene compression --from "$d/loose.toml" --state "$d/settled.state" -o "$d/compression.toml"
  [[ -f $d/bed.toml ]] || $demmat scene settled --from "$d/loose.toml" --state "$d/settled.state" -o "$d/bed.toml"
  for stage in loose bed compression; do
    # A law's settled state holds stretches, which a data file cannot (export warns on stderr).
    [[ -f $d/$stage.data ]] || $demmat export-lammps "$d/$stage.toml" -o "$d/$stage.data"
  done
}

if [[ $prepare_only == 1 ]]; then
  for n in $ns; do prepare "$n"; done
  echo "run_peers.sh: stages of N = $ns ready in $work"
  exit 0
fi

if [[ $do_bench == 1 ]]; then
  # Each run's raw output stays in $work: the suite's `demmat bench --json`, the peers' logs, whose last
  # loop time and breakdown plot_peers.py reads.
  rm -f "$work"/suite_*.json "$work"/lammps_*.out "$work"/liggghts_*.out
  for n in $ns; do prepare "$n"; done
  # The runs of one repetition: code@threads. The suite times every thread count in one bench run
  # (interleaved inside it); LAMMPS built here runs once per thread count; the others on one core.
  suite_threads=$(tr ' ' ',' <<<"$threads")
  codes=(suite@1 lammps_native@1 lammps@1); [[ -n "$liggghts" ]] && codes+=(liggghts@1)
  for t in $threads; do [[ $t == 1 ]] || codes+=("lammps_native@$t"); done
  for ((r = 0; r < reps; r++)); do
    for n in $ns; do
      d=$(stage_dir "$n")
      k=$(( (1000000 + n - 1) / n )); (( k < steps )) && k=$steps  # the timed steps at this N
      for stage in loose bed compression; do
        for ((q = 0; q < ${#codes[@]}; q++)); do
          run=${codes[$(((q + r) % ${#codes[@]}))]}   # rotated each repetition: drift hits all alike
          code=${run%@*}; t=${run#*@}
          case $code in
            suite)
              $demmat bench "$d/$stage.toml" --variants "$variants" --threads "$suite_threads" --steps "$k" --warmup "$warmup" \
                --repetitions 1 --json "$work/suite_n${n}_${stage}_r${r}.json" >/dev/null 2>&1 ;;
            lammps|lammps_native)
              exe=$lmp; omp=()
              [[ $code == lammps_native ]] && exe=$lmp_native
              (( t > 1 )) && omp=(-sf omp -pk omp "$t")
              (cd "$d" && $exe "${omp[@]}" -var frag "$stage.lammps" -var warmup "$warmup" -var steps "$k" \
                 -in "$OLDPWD/peers/lammps/in.bench" -log none -nocite > "$work/${code}_t${t}_n${n}_${stage}_r${r}.out" 2>&1) ;;
            liggghts)
              (cd "$d" && $liggghts -var frag "$stage.liggghts" -var warmup "$warmup" -var steps "$k" \
                 -in "$OLDPWD/peers/liggghts/in.bench" -log none -nocite > "$work/liggghts_n${n}_${stage}_r${r}.out" 2>&1) ;;
          esac
        done
      done
    done
    echo "== benchmark repetition $((r + 1))/$reps done"
  done
  $PYTHON analysis/plot_peers.py bench --work "$work" --versions "$work/versions.json" \
    --out "$out" --figure "$figures/peers_us_per_particle_step.png"
fi

if [[ $do_phys == 1 ]]; then
  n=$phys_n; prepare "$n"; d=$(stage_dir "$n"); p=$work/physics_n$n${law_dir:+_$law_dir}
  mkdir -p "$p"; rm -f "$p"/*.csv
  settle_steps=30000; settle_every=1000; comp_steps=6000; comp_every=300; amplitude=1e-6
  echo "== physics cross-check: $members perturbed starts per code, $n particles"
  for ((m = 1; m <= members; m++)); do
    for stage in loose compression; do
      if [[ $stage == loose ]]; then k=$settle_steps; e=$settle_every; else k=$comp_steps; e=$comp_every; fi
      base=$p/${stage}_m$m
      # One perturbed start, written once, read by every code: the suite imports the same data file.
      $demmat export-lammps "$d/$stage.toml" -o "$base.data" --perturb "$amplitude" --seed "$m"
      $demmat import-lammps "$base.data" --scene "$d/$stage.toml" -o "$base.state"
      $demmat dump "$d/$stage.toml" --state "$base.state" --steps "$k" --every "$e" -o "$base.suite.dump" 2>/dev/null
      # The same law with velocity Verlet: how much of the suite's distance from LAMMPS is the integrator.
      $demmat dump "$d/$stage.toml" --state "$base.state" --integrator verlet --steps "$k" --every "$e" -o "$base.suite_verlet.dump" 2>/dev/null
      if [[ $diagnose == 1 ]]; then
        # The suite with LAMMPS's lever arms (Gear), with every listed difference removed (velocity Verlet
        # at the half-step velocity too), and LAMMPS at Δt/2 (its own time-step error): what each known
        # difference contributes (docs/peers.md). The half-step run's frames keep the times of the others.
        $demmat_as_lammps dump "$d/$stage.toml" --state "$base.state" --steps "$k" --every "$e" -o "$base.suite_lammps_arms.dump" 2>/dev/null
        $demmat_as_lammps dump "$d/$stage.toml" --state "$base.state" --integrator verlet --steps "$k" --every "$e" -o "$base.suite_as_lammps.dump" 2>/dev/null
        sed "s/^timestep .*/timestep $($PYTHON -c "import sys; print(repr(float(sys.argv[1]) / 2))" "$(awk '/^timestep /{print $2}' "$base.lammps")")/" \
          "$base.lammps" > "$base.half_dt.lammps"
        (cd "$p" && $lmp -var frag "$(basename "$base").half_dt.lammps" -var steps $((2 * k)) -var every $((2 * e)) \
           -var dumpfile "$(basename "$base").lammps_half_dt.dump" -in "$OLDPWD/peers/lammps/in.trace" -log none -nocite > /dev/null 2>&1)
      fi
      (cd "$p" && $lmp -var frag "$(basename "$base").lammps" -var steps "$k" -var every "$e" -var dumpfile "$(basename "$base").lammps.dump" \
         -in "$OLDPWD/peers/lammps/in.trace" -log none -nocite > /dev/null 2>&1)
      [[ -n "$liggghts" ]] && (cd "$p" && $liggghts -var frag "$(basename "$base").liggghts" -var steps "$k" -var every "$e" \
         -var dumpfile "$(basename "$base").liggghts.dump" -in "$OLDPWD/peers/liggghts/in.trace" -log none -nocite > /dev/null 2>&1)
      for code in suite suite_verlet suite_lammps_arms suite_as_lammps lammps lammps_half_dt liggghts; do
        [[ -f $base.$code.dump ]] || continue
        half=(); [[ $code == lammps_half_dt ]] && half=(--step-scale 0.5)
        $PYTHON analysis/plot_peers.py observables --dump "$base.$code.dump" --scene "$d/$stage.toml" "${half[@]}" \
          --code "$code" --member "$m" --stage "$stage" -o "$p/obs_${stage}_${code}_m$m.csv"
        rm -f "$base.$code.dump"   # frames are large; the observables are what is kept
      done
    done
    echo "== member $m/$members done"
  done
  if [[ $diagnose == 1 ]]; then
    # Single contacts, where the codes can be compared contact by contact (in the bed the trajectories
    # separate): the stage's law on four isolated grains, every build and LAMMPS (analysis/peer_contacts.py).
    c=$p/contacts; rm -rf "$c"; mkdir -p "$c"
    $PYTHON analysis/peer_contacts.py scene --stage "$d/compression.toml" -o "$c/contacts.toml"
    $demmat export-lammps "$c/contacts.toml" -o "$c/contacts.data" 2>/dev/null
    $demmat import-lammps "$c/contacts.data" --scene "$c/contacts.toml" -o "$c/contacts.state"
    run_contacts() { "$@" "$c/contacts.toml" --state "$c/contacts.state" --steps 3000 --every 500 2>/dev/null; }
    run_contacts $demmat dump -o "$c/suite.dump"
    run_contacts $demmat dump --integrator verlet -o "$c/suite_verlet.dump"
    run_contacts $demmat_as_lammps dump --integrator verlet -o "$c/suite_as_lammps.dump"
    (cd "$c" && $lmp -var frag contacts.lammps -var steps 3000 -var every 500 -var dumpfile lammps.dump \
       -in "$OLDPWD/peers/lammps/in.trace" -log none -nocite > /dev/null 2>&1)
    $PYTHON analysis/peer_contacts.py compare --work "$c" --versions "$work/versions.json" \
      --build "suite=$demmat" --build "suite built as LAMMPS=$demmat_as_lammps" --out "$out"
  fi
  $PYTHON analysis/plot_peers.py physics --work "$p" --versions "$work/versions.json" --particles "$n" \
    --amplitude "$amplitude" --out "$out" --figure "$figures/peers_physics_${n}.png"
fi

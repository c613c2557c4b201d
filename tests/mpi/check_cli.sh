#!/bin/sh
# demmat_mpi on the command line (ctest mpi.cli): bad input (a process count that leaves a brick thinner
# than the interaction range, a grid that is not one brick per process, another variant, a subcommand
# that stays with demmat) gets one line from rank 0 and a non-zero exit on every rank; compare finds
# arrays and mpi identical; a state saved at R = 3 and continued at R = 2 (a new stage: the compression wall moves) is the state arrays writes,
# byte for byte, under the paper's law and under a law with memory (the stretches saved and reloaded).
# Usage: check_cli.sh DEMMAT DEMMAT_MPI SOURCE_DIR WORK MPIRUN...
set -eu
demmat=$1 demmat_mpi=$2 src=$3 work=$4
shift 4
run_np() { np=$1; shift; "$MPIRUN_CMD" $MPIRUN_FLAGS -np "$np" "$@"; }
MPIRUN_CMD=$1; shift; MPIRUN_FLAGS="$*"
rm -rf "$work" && mkdir -p "$work" && cd "$work"
fail() { echo "check_cli: $*" >&2; exit 1; }

# A bad case: exit non-zero, exactly one line from demmat_mpi, containing the expected text.
refused() {
    want=$1; shift
    if run_np "$@" >out.txt 2>err.txt; then fail "accepted: $*"; fi
    [ "$(grep -c '^demmat_mpi: error' err.txt)" = 1 ] || { cat err.txt >&2; fail "not one error line: $*"; }
    grep -q "$want" err.txt || { cat err.txt >&2; fail "no '$want' in the error of: $*"; }
}
refused "thinner than the interaction range" 3 "$demmat_mpi" run "$src/scenes/head_on.toml" --steps 10
refused "not one per process" 2 "$demmat_mpi" run "$src/scenes/head_on.toml" --grid 3x1x1
refused "is not auto or PxPyPz" 2 "$demmat_mpi" run "$src/scenes/head_on.toml" --grid 2x1
refused "runs the mpi variant only, not 'arrays'" 2 "$demmat_mpi" run "$src/scenes/head_on.toml" --variant arrays
refused "run it with demmat" 2 "$demmat_mpi" scene paper
refused "cannot open" 2 "$demmat_mpi" run no_such_scene.toml
refused "an empty name" 2 "$demmat_mpi" run "$src/scenes/head_on.toml" --json ""
refused "REFERENCE,mpi" 2 "$demmat_mpi" compare "$src/scenes/head_on.toml" --variants mpi,arrays

bed="$src/scenes/dense_bed_2000.toml"
run_np 2 "$demmat_mpi" compare "$bed" --steps 100 >cmp.txt || { cat cmp.txt >&2; fail "compare at 2 processes"; }
grep -q "^identical: arrays, mpi at 2 processes over 100 steps" cmp.txt || fail "compare: $(cat cmp.txt)"

# Save at 3, continue at 2, against arrays on one process.
"$demmat" run "$bed" --steps 300 --save a1.state -q >/dev/null
run_np 3 "$demmat_mpi" run "$bed" --steps 300 --save m1.state -q >m1.txt
cmp a1.state m1.state || fail "the state saved at 3 processes differs from arrays'"
"$demmat" scene compression --from "$bed" --state a1.state -o ca.toml
"$demmat" scene compression --from "$bed" --state m1.state -o cm.toml
"$demmat" run ca.toml --steps 300 --save a2.state -q >/dev/null
run_np 2 "$demmat_mpi" run cm.toml --steps 300 --save m2.state --json m2.json -q >m2.txt
cmp a2.state m2.state || fail "continued at 2 processes, the state differs from arrays'"
grep -q '"communicate"' m2.json || fail "--json has no communicate time"

# The same under a law with memory (physics.md §9): the states carry every live contact's stretches.
"$demmat" scene dense-bed --n 2000 --contact damping=tsuji --contact restitution=0.5 --contact tangential=mindlin \
    --contact tangential_damping_ratio=0.5 --contact rolling=sds --contact kr=50 --contact rolling_damping=0.05 \
    --contact rolling_friction=0.1 -o law.toml
"$demmat" run law.toml --steps 300 --save la1.state -q >/dev/null
run_np 3 "$demmat_mpi" run law.toml --steps 300 --save lm1.state -q >/dev/null
cmp la1.state lm1.state || fail "under a law with memory, the state saved at 3 processes differs from arrays'"
"$demmat" scene compression --from law.toml --state la1.state -o lca.toml
"$demmat" scene compression --from law.toml --state lm1.state -o lcm.toml
"$demmat" run lca.toml --steps 300 --save la2.state -q >/dev/null
run_np 2 "$demmat_mpi" run lcm.toml --steps 300 --save lm2.state -q >/dev/null
cmp la2.state lm2.state || fail "under a law with memory, continued at 2 processes, the state differs from arrays'"
grep -q "^particles per rank max" m2.txt || fail "run reports no particles per rank"
echo "check_cli: all passed"

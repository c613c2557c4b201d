#!/usr/bin/env bash
# The figures of the paper, reproduced and extended (docs/benchmarks.md): Figure 4 (cells against no
# cells), the cell-size sweep, scaling against N per variant and state, memory per particle, and where
# the time goes (phases against the measured memory bandwidth, cost per contact, callgrind instruction
# counts). Builds and runs bench/demmat_bench with randomly interleaved repetitions, then
# analysis/plot_figures.py. The callgrind counts need valgrind and the main job's settled bed
# (scripts/run_main.sh); without them they are left out.
#
# Usage: scripts/run_figures.sh [--full] [--repetitions R] [--build-dir DIR]
#   default          the short sweep (N up to 8000; a few minutes; scripts/run_main.sh --sweep runs it)
#   --full           N up to 10^5 settled and 10^6 on the loose grid, Figure 4 up to 5·10^4 (an hour or
#                    more; settled beds are cached in states/ and reused)
#   --repetitions R  interleaved repetitions (default 3, full 5)
#   --build-dir DIR  the build folder (default build, or $DEMMAT_BUILD_DIR); callgrind's portable build
#                    goes in DIR-portable
source "$(dirname "$0")/lib.sh"
sweep=short; reps=""
while [[ $# -gt 0 ]]; do
  case "$1" in
    --full) sweep=full; shift ;;
    --repetitions) need_value "$@"; reps=$2; shift 2 ;;
    *) shared_option "$@"; shift "$SHIFT" ;;
  esac
done
[[ -n "$reps" ]] || { [[ $sweep == full ]] && reps=5 || reps=3; }
positive_int --repetitions "$reps"
install_deps
cmake_build "$BUILD_DIR" demmat_bench

out=results/sweep_$sweep
mkdir -p "$out" results/figures states
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT

echo "== benchmark ($sweep sweep, $reps randomly interleaved repetitions)"
"$BUILD_DIR/bench/demmat_bench" --sweep="$sweep" --states-dir=states \
  --benchmark_repetitions="$reps" --benchmark_enable_random_interleaving=true \
  --benchmark_out="$tmp/bench.json" --benchmark_out_format=json --benchmark_counters_tabular=false \
  --benchmark_format=console | { grep -E "^(phases|figure4|cellsize|stream)/" | grep -vE "_(mean|median|stddev|cv) " | cut -c1-110 || true; }
mv "$tmp/bench.json" "$out/bench.json"

callgrind=()
if command -v valgrind >/dev/null && [[ -f scenes/dense_bed_2000_compression.toml && -f states/dense_bed_2000_settled.state ]]; then
  echo "== instruction counts (callgrind, 40 steps of the compression stage)"
  # From a portable build of the demmat program (DEMMAT_FAST_NATIVE=OFF): Valgrind 3.19 cannot decode
  # the AVX-512 that variants/fast is compiled to where the CPU has it, and portable counts compare
  # from one machine to the next.
  portable=$BUILD_DIR-portable
  cmake_build -q "$portable" demmat -- -DDEMMAT_FAST_NATIVE=OFF -DDEMMAT_BUILD_BENCH=OFF -DBUILD_TESTING=OFF
  variants=(arrays)
  grep -q "^fast " <<<"$("$portable/app/demmat" list)" && variants+=(fast)
  scripts/callgrind_phases.sh --build-dir "$portable" scenes/dense_bed_2000_compression.toml 40 "$out" "${variants[@]}"
  for v in "${variants[@]}"; do callgrind+=("$out/callgrind_$v.json"); done
else
  echo "== instruction counts left out: they need valgrind (scripts/install_deps.sh --optional) and the settled bed (scripts/run_main.sh)"
fi

echo "== analysis"
$PYTHON analysis/plot_figures.py "$out/bench.json" --out "$out" --figures results/figures --suffix "$sweep" \
  ${callgrind:+--callgrind "${callgrind[@]}"} >"$tmp/summary.md"
echo "tables: $out/*.md, figures: results/figures/*_$sweep.png"

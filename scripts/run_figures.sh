#!/usr/bin/env bash
# The figures of the paper, reproduced and extended (docs/benchmarks.md): Figure 4 (cells against no
# cells), the cell-size sweep, scaling against N per variant and state, memory per particle, and where
# the time goes (phases against the measured memory bandwidth, cost per contact, callgrind instruction
# counts). Runs bench/demmat_bench with randomly interleaved repetitions, then analysis/plot_figures.py.
#
# Usage: scripts/run_figures.sh [--full] [--build DIR] [--repetitions R]
#   default: the short sweep (N up to 8000; a few minutes), as the main command runs it
#   --full:  N up to 10⁵ settled and 10⁶ on the loose grid, Figure 4 up to 5·10⁴ (an hour or more;
#            settled beds are cached in states/ and reused)
set -euo pipefail
cd "$(dirname "$0")/.."
sweep=short; build=build; reps=""
while [[ $# -gt 0 ]]; do
  case "$1" in
    --full) sweep=full; shift ;;
    --build) build="$2"; shift 2 ;;
    --repetitions) reps="$2"; shift 2 ;;
    *) echo "run_figures.sh: unknown option $1 (expected --full, --build DIR, --repetitions R)" >&2; exit 2 ;;
  esac
done
[[ -n "$reps" ]] || { [[ $sweep == full ]] && reps=5 || reps=3; }
[[ -x "$build/bench/demmat_bench" ]] || { echo "run_figures.sh: $build/bench/demmat_bench missing (build first: scripts/run_main.sh)" >&2; exit 1; }

out=results/sweep_$sweep
mkdir -p "$out" results/figures states
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT

echo "== benchmark ($sweep sweep, $reps randomly interleaved repetitions)"
"$build/bench/demmat_bench" --sweep="$sweep" --states-dir=states \
  --benchmark_repetitions="$reps" --benchmark_enable_random_interleaving=true \
  --benchmark_out="$tmp/bench.json" --benchmark_out_format=json --benchmark_counters_tabular=false \
  --benchmark_format=console | grep -E "^(phases|figure4|cellsize|stream)/" | grep -vE "_(mean|median|stddev|cv) " | cut -c1-110 || true
mv "$tmp/bench.json" "$out/bench.json"

callgrind=()
if command -v valgrind >/dev/null && [[ -f scenes/dense_bed_2000_compression.toml ]]; then
  echo "== instruction counts (callgrind, 40 steps of the compression stage)"
  # From a portable build of the demmat program (DEMMAT_FAST_NATIVE=OFF): Valgrind 3.19 cannot decode
  # the AVX-512 that variants/fast is compiled to where the CPU has it, and portable counts compare
  # from one machine to the next.
  portable="$build-portable"
  cmake -S . -B "$portable" -DCMAKE_BUILD_TYPE=Release -DDEMMAT_FAST_NATIVE=OFF -DDEMMAT_BUILD_BENCH=OFF -DBUILD_TESTING=OFF >/dev/null
  cmake --build "$portable" -j "$(nproc 2>/dev/null || echo 2)" --target demmat >/dev/null
  variants=(arrays)
  "$portable/app/demmat" list | grep -q "^fast " && variants+=(fast)
  scripts/callgrind_phases.sh "$portable" scenes/dense_bed_2000_compression.toml 40 "$out" "${variants[@]}"
  for v in "${variants[@]}"; do callgrind+=("$out/callgrind_$v.json"); done
fi

echo "== analysis"
/usr/bin/python3 analysis/plot_figures.py "$out/bench.json" --out "$out" --figures results/figures --suffix "$sweep" \
  ${callgrind:+--callgrind "${callgrind[@]}"} >"$tmp/summary.md"
echo "tables: $out/*.md, figures: results/figures/*_$sweep.png"

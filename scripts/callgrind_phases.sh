#!/usr/bin/env bash
# Instruction counts per phase and particle-step with valgrind's callgrind: repeatable on a shared,
# noisy machine where seconds are not. Profiles `demmat run` of SCENE for STEPS steps with one thread.
# Usage: scripts/callgrind_phases.sh BUILD_DIR SCENE STEPS OUT_DIR VARIANT...
set -euo pipefail
cd "$(dirname "$0")/.."
build="$1"; scene="$2"; steps="$3"; out="$4"; shift 4
command -v valgrind >/dev/null || { echo "callgrind_phases.sh: valgrind is not installed (scripts/install_deps.sh --optional)" >&2; exit 1; }
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
mkdir -p "$out"
for v in "$@"; do
  OMP_NUM_THREADS=1 valgrind --tool=callgrind --callgrind-out-file="$tmp/cg.$v" \
    "$build/app/demmat" run "$scene" --variant "$v" --steps "$steps" --quiet --json "$tmp/run.$v.json" >/dev/null 2>"$tmp/log.$v" ||
    { cat "$tmp/log.$v" >&2; exit 1; }
  callgrind_annotate --inclusive=yes --threshold=100 "$tmp/cg.$v" >"$tmp/annotate.$v.txt"
  /usr/bin/python3 analysis/callgrind_phases.py "$tmp/annotate.$v.txt" "$tmp/run.$v.json" --steps "$steps" -o "$out/callgrind_$v.json"
done

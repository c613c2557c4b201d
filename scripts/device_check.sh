#!/usr/bin/env bash
# The cuda variant's check on a GPU machine (docs/cuda.md, "The device check"). Two modes:
#
#   scripts/device_check.sh --pack      on the build machine: builds build-gpu/ (portable flags) and packs
#                                       build-gpu/dist/ (demmat and the shared libraries it needs beside it)
#   scripts/device_check.sh             on the GPU machine, from the repository root, with build-gpu/dist/
#                                       carried there: provenance, the bitwise comparisons, the benchmark
#
# The run replaces results/gpu/ (and archives it under $OUT when $OUT is set): nvidia-smi, the code the
# binary carries, `demmat compare` of cuda against arrays under every law (dense bed settling and its
# compression stage, 1000 steps each), and `demmat bench` of cuda beside fast at every core and at 1
# under the paper's law, mindlin and mindlin + sds on dense beds of 10^6, 10^4 and 10^5 grains settled
# on the device under each law, and where BIG is set the paper's law on a loose lattice of BIG grains.
# It keeps to a time budget (BUDGET_S, default 450 s): a stage that no longer fits is skipped and says
# so in results/gpu/log.txt. runs.tsv names each result file's law, for analysis/summarise_gpu.py.
# Knobs: BUDGET_S, SETTLE_TIME (simulated seconds of settling, default 0.15: the 12-layer bed has
# collapsed by then), SIZES (default "1000000 10000 100000"), BIG (default 0: none; 10000000 was run
# before the laws),
# LAWS (compared, default "paper tsuji linear_history mindlin mindlin_sds"), BENCH_LAWS (benchmarked,
# default "paper mindlin mindlin_sds"), CMP_N and CMP_STEPS (the comparisons' bed and length, default
# 2000 and 1000), CHECK_EVERY (steps between the health checks of a settle, default 3000), THREADS (fast's
# threads beside 1, default every core), RESULTS (default results/gpu).
# VARIANT=cuda_host runs the whole flow on the CPU, to try the script without a GPU (with RESULTS set to
# a scratch folder, and small SIZES, BIG=0, CMP_N and CMP_STEPS).
# Usage: scripts/device_check.sh [--pack [--fast-arch ARCH]] [--build-dir DIR]
#   --pack            on the build machine: build DIR and pack DIR/dist for the GPU machine
#   --fast-arch ARCH  with --pack: compile fast for the GPU machine's CPU (GCC's -march=ARCH, e.g.
#                     x86-64-v4 for AVX-512) as its own build does with native; default: portable code
#   --build-dir DIR   the build folder (default build-gpu); its dist/ is what travels
source "$(dirname "$0")/lib.sh"
BUILD_DIR=${DEMMAT_BUILD_DIR:-build-gpu}
pack=false
fast_arch=""
while [[ $# -gt 0 ]]; do
  case "$1" in
    --pack) pack=true; shift ;;
    --fast-arch) need_value "$@"; fast_arch=$2; shift 2 ;;
    *) shared_option "$@"; shift "$SHIFT" ;;
  esac
done
set +e  # on the GPU machine a failed stage is logged and the next one runs

dist=$BUILD_DIR/dist

if $pack; then
  set -e
  # Portable code for an unknown host CPU (fast without -march), or fast for the CPU named by --fast-arch;
  # bit-identical either way.
  if [[ -n "$fast_arch" ]]; then fast=(-DDEMMAT_FAST_NATIVE=ON "-DDEMMAT_FAST_ARCH=$fast_arch"); else fast=(-DDEMMAT_FAST_NATIVE=OFF); fi
  cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release "${fast[@]}" -DDEMMAT_BUILD_BENCH=OFF \
        -DCMAKE_EXE_LINKER_FLAGS="-static-libstdc++ -static-libgcc" ${CCACHE_DIR:+-DCMAKE_CXX_COMPILER_LAUNCHER=ccache} >/dev/null
  cmake --build "$BUILD_DIR" -j"${JOBS:-2}" --target demmat
  rm -rf "$dist" && mkdir -p "$dist/bin" "$dist/lib" "$dist/glibc"
  cp "$BUILD_DIR/app/demmat" "$dist/bin/"
  # Every shared library it needs beside it; the C library apart, in glibc/, used (through its own
  # loader) only where the GPU machine's glibc is older than the one the binary was linked against.
  ldd "$BUILD_DIR/app/demmat" | awk '/=> \//{print $3} /ld-linux/{print $1}' | while read -r lib; do
    case "$(basename "$lib")" in
      libcuda.so*) ;;
      libc.so*|libm.so*|libdl.so*|libpthread.so*|librt.so*|ld-linux*) cp -L "$lib" "$dist/glibc/" ;;
      *) cp -L "$lib" "$dist/lib/" ;;
    esac
  done
  # What the GPU machine's C library must provide, and the device code's provenance from here.
  { echo "built on: $(uname -srm); $(ldd --version | head -1)"
    echo "highest glibc symbol version needed:"
    for f in "$dist"/bin/* "$dist"/lib/*; do objdump -T "$f" 2>/dev/null; done | grep -o 'GLIBC_[0-9.]*' | sort -Vu | tail -1
    grep -h 'set(CMAKE_CUDA_COMPILER_VERSION' $BUILD_DIR/CMakeFiles/*/CMakeCUDACompiler.cmake 2>/dev/null | head -1
    grep -h '^CUDA_FLAGS' $BUILD_DIR/variants/CMakeFiles/demmat_variant_cuda.dir/flags.make || echo "no cuda variant in this build"
    echo "fast compiled with: $(grep -h '^CXX_FLAGS' $BUILD_DIR/variants/CMakeFiles/demmat_variant_fast.dir/flags.make | cut -d= -f2-)"
  } > "$dist/build-info.txt"
  # The device code's arithmetic, checked here (cuobjdump is not on this machine): the PTX of cuda.cu
  # with the build's flags has no fused multiply-add, and every f64 add, mul, div and sqrt rounds to nearest.
  nvcc="$(sed -n 's/^set(CMAKE_CUDA_COMPILER "\(.*\)")$/\1/p' $BUILD_DIR/CMakeFiles/*/CMakeCUDACompiler.cmake | head -1)"
  if [[ -n "$nvcc" ]]; then
    flags="$(grep -h '^CUDA_FLAGS' $BUILD_DIR/variants/CMakeFiles/demmat_variant_cuda.dir/flags.make | cut -d= -f2- | sed 's/--generate-code=[^ ]*//g')"
    incs="$(grep -h '^CUDA_INCLUDES' $BUILD_DIR/variants/CMakeFiles/demmat_variant_cuda.dir/flags.make | cut -d= -f2-)"
    # shellcheck disable=SC2086
    root=$PWD; dist_abs=$(realpath -m "$dist")
    (cd "$BUILD_DIR/variants" && "$nvcc" $incs $flags -arch=compute_90 --ptx "$root/variants/cuda/cuda.cu" -o "$dist_abs/cuda.ptx")
    { echo "PTX of variants/cuda/cuda.cu (compute_90):"
      echo "  kernels (entry points): $(grep -c '\.entry' "$dist/cuda.ptx")"
      echo "  fma instructions: $(grep -cE '^\s*fma\.' "$dist/cuda.ptx")"
      echo "  f64 add/sub/mul: $(grep -cE '^\s*(add|sub|mul)\.rn\.f64' "$dist/cuda.ptx") with .rn, $(grep -cE '^\s*(add|sub|mul)\.f64' "$dist/cuda.ptx") without"
      echo "  f64 div: $(grep -cE '^\s*div\.rn\.f64' "$dist/cuda.ptx") (.rn), $(grep -cE '^\s*div\.(approx|full)' "$dist/cuda.ptx") (approximate)"
      echo "  f64 sqrt: $(grep -cE '^\s*sqrt\.rn\.f64' "$dist/cuda.ptx") (.rn), $(grep -cE '^\s*sqrt\.approx' "$dist/cuda.ptx") (approximate)"
    } > "$dist/ptx-check.txt"
    cat "$dist/ptx-check.txt"
  fi
  du -sh "$dist"
  echo "packed $dist: carry it to the GPU machine and run scripts/device_check.sh there"
  exit 0
fi

# ---- on the GPU machine --------------------------------------------------------------------------------
budget=${BUDGET_S:-450}
settle_time=${SETTLE_TIME:-0.15}
sizes=${SIZES:-"1000000 10000 100000"}  # the target's size first: a budget cut falls on the others
big=${BIG:-0}
laws=${LAWS:-"paper tsuji linear_history mindlin mindlin_sds"}
bench_laws=${BENCH_LAWS:-"paper mindlin mindlin_sds"}
threads=${THREADS:-$(nproc)}
for law in $laws $bench_laws; do contact_args "$law" > /dev/null || exit 2; done
start=$SECONDS
res=${RESULTS:-results/gpu}
gpu=${VARIANT:-cuda}
work=$res/work
rm -rf "$res" && mkdir -p "$res" "$work"  # this run's files only (the folder holds the committed run's)
log=$res/log.txt
runs=$res/runs.tsv
printf 'file\tlaw\n' > "$runs"
: > "$log"
say() { echo "$*" | tee -a "$log"; }
left() { echo $((budget - (SECONDS - start))); }
# run_capped CAP_S CMD...: runs CMD with at most min(CAP_S, time left) seconds; 124 when cut off.
run_capped() {
  local cap=$1; shift
  local l; l=$(left)
  ((l < cap)) && cap=$l
  if ((cap < 5)); then say "skipped (no time left): $*"; return 125; fi
  timeout "$cap" "$@"
  local rc=$?
  ((rc == 124)) && say "cut off after ${cap} s: $*"
  return $rc
}
finish() {
  say "== done in $((SECONDS - start)) s"
  # The lent machines return at most 8 files: the results as one archive (without the work files), the log beside it.
  if [[ -n "${OUT:-}" ]]; then
    tar -C "$(dirname "$res")" --exclude=work -czf "$OUT/gpu-results.tar.gz" "$(basename "$res")" && cp "$log" "$OUT/log.txt"
  fi
}
trap finish EXIT

bin="$PWD/$dist/bin/demmat"
[[ -x "$bin" ]] || { say "error: $bin missing: run scripts/device_check.sh --pack on the build machine and carry $dist"; exit 2; }
# demmat with its libraries; through the carried loader and C library where this machine's glibc is older.
demmat=(env LD_LIBRARY_PATH="$PWD/$dist/lib" "$bin")
if ! "${demmat[@]}" list > /dev/null 2> "$res/loader.txt"; then
  demmat=("$PWD/$dist/glibc/$(basename "$(ls "$dist"/glibc/ld-linux*)")" --library-path "$PWD/$dist/lib:$PWD/$dist/glibc" "$bin")
  say "the system's loader cannot start demmat ($(head -1 "$res/loader.txt")): using the carried glibc"
fi

say "== provenance"
{ date -u; uname -a; nproc; } > "$res/host.txt"
lscpu >> "$res/host.txt" 2>/dev/null
nvidia-smi > "$res/nvidia-smi.txt" 2>&1
nvidia-smi --query-gpu=name,driver_version,compute_cap,memory.total --format=csv 2>&1 | tee -a "$log"
nvidia-smi -q >> "$res/nvidia-smi.txt" 2>&1
cp "$dist/build-info.txt" "$dist/ptx-check.txt" "$res/" 2>/dev/null
if command -v cuobjdump >/dev/null; then
  cuobjdump --list-elf --list-ptx "$bin" > "$res/cuobjdump.txt" 2>&1
  cuobjdump -sass "$bin" 2>/dev/null | grep -cE '\bDFMA\b' | sed 's/^/DFMA instructions in the SASS: /' >> "$res/cuobjdump.txt"
else
  echo "cuobjdump not on this machine; the PTX check from the build machine is ptx-check.txt" > "$res/cuobjdump.txt"
fi
"${demmat[@]}" list | tee "$res/list.txt" | tee -a "$log"
if ! grep -E "^$gpu " "$res/list.txt" | grep -qv unavailable; then say "error: the $gpu variant cannot run here (see list.txt)"; exit 1; fi

# A settle on the device checks its health every CHECK_EVERY steps (default 3000), not the scene's 100:
# each check reads the whole state back and finds its contacts on one CPU core, which at 10^6 grains
# would take longer than the steps between the checks.
check_every=${CHECK_EVERY:-3000}
device_scene() {  # device_scene N FILE [ARGS]: the dense bed of N grains, checked every check_every steps
  local n=$1 f=$2; shift 2
  "${demmat[@]}" scene dense-bed --n "$n" "$@" -o "$f" && sed -i "s/^interval = .*/interval = $check_every/" "$f"
}

cmp_steps=${CMP_STEPS:-1000}
say "== bitwise: $gpu against arrays (and a second $gpu run), $cmp_steps steps, under each law: $laws"
n=${CMP_N:-2000}
cmp_failed=0  # a difference (or a failed compare) makes the whole check fail, after the benchmarks
for law in $laws; do
  # shellcheck disable=SC2046  # contact_args is a list of words on purpose
  set -- $(contact_args "$law")
  b=bed_${n}_$law
  device_scene "$n" "$work/$b.toml" "$@"
  # Settled on the device under the law: the compression stage starts from its state, stretches and all.
  run_capped 120 "${demmat[@]}" run "$work/$b.toml" --variant "$gpu" --time "$settle_time" --save "$work/${b}_settled.state" -q \
    --json "$res/settle_$b.json" >> "$log" 2>&1
  "${demmat[@]}" scene compression --from "$work/$b.toml" --state "$work/${b}_settled.state" "$@" -o "$work/${b}_compression.toml"
  for s in "$b" "${b}_compression"; do
    run_capped 90 "${demmat[@]}" compare "$work/$s.toml" --variants "$gpu,arrays,$gpu" --steps "$cmp_steps" 2>&1 | tee -a "$log" "$res/compare_$s.txt"
    [[ ${PIPESTATUS[0]} == 0 ]] || cmp_failed=1
    printf 'compare_%s.txt\t%s\n' "$s" "$law" >> "$runs"
  done
done

say "== benchmark: us per particle-step, $gpu beside fast at $threads threads and at 1, under: $bench_laws"
# bench LABEL LAW SCENE STEPS REPS CAP: each configuration alone (its own JSON), so that one cut off loses only itself.
bench() {
  for cfg in "$gpu:1" "fast:$threads" fast:1; do
    local v=${cfg%:*} t=${cfg#*:} f="bench_$1_$2_${cfg/:/_}" k=$4
    [[ $v == "$gpu" ]] && k=$((k * 10 > 200 ? 200 : k * 10))  # the device's steps are short: more of them
    run_capped "$6" "${demmat[@]}" bench "$3" --variants "$v" --threads "$t" --steps "$k" --repetitions "$5" --warmup 2 \
      --json "$res/$f.json" > "$res/$f.txt" 2>> "$log"
    tee -a "$log" < "$res/$f.txt"
    printf '%s.json\t%s\n' "$f" "$2" >> "$runs"
  done
}
for n in $sizes; do
  steps=$((2000000 / n)); ((steps < 3)) && steps=3; ((steps > 200)) && steps=200
  for law in $bench_laws; do
    # Settled on the device under the law itself (a state carries its law in its fingerprint).
    b=bed_${n}_$law
    # shellcheck disable=SC2046
    device_scene "$n" "$work/$b.toml" $(contact_args "$law")
    run_capped 200 "${demmat[@]}" run "$work/$b.toml" --variant "$gpu" --time "$settle_time" --save "$work/${b}_settled.state" -q \
      --json "$res/settle_$b.json" >> "$log" 2>&1 || continue
    "${demmat[@]}" scene settled --from "$work/$b.toml" --state "$work/${b}_settled.state" -o "$work/${b}_settled.toml"
    bench "settled_$n" "$law" "$work/${b}_settled.toml" "$steps" 3 150
  done
done
if ((big > 0)); then
  "${demmat[@]}" scene dense-bed --n "$big" -o "$work/loose_$big.toml"
  bench "loose_$big" paper "$work/loose_$big.toml" 2 1 200
fi
if ((cmp_failed)); then
  say "error: $gpu is not bit-identical to arrays on every comparison (results: compare_*.txt)"
  exit 1
fi

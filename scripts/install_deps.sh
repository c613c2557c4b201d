#!/usr/bin/env bash
# Installs the suite's dependencies from Debian's packages, only those that are missing.
# Usage: scripts/install_deps.sh [--optional] [--fuzz]
#   --optional  also the peers and the profiler: lammps, liggghts, valgrind
#   --fuzz      also clang and its libFuzzer runtime (scripts/fuzz.sh)
source "$(dirname "$0")/lib.sh"

required=(
  build-essential cmake git pkg-config
  libgtest-dev libgmock-dev libbenchmark-dev
  libtoml11-dev nlohmann-json3-dev libcli11-dev libfmt-dev
  libeigen3-dev
  gfortran fp-compiler
  python3 python3-pandas python3-matplotlib
  time
  libopenmpi-dev openmpi-bin
)
optional=(lammps liggghts valgrind)
fuzz=(clang-14 libclang-rt-14-dev)

want=("${required[@]}")
for a in "$@"; do
  case "$a" in
    --optional) want+=("${optional[@]}") ;;
    --fuzz) want+=("${fuzz[@]}") ;;
    -h|--help) usage 0 ;;
    *) unknown_option "$a" ;;
  esac
done

missing=()
for p in "${want[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[[ ${#missing[@]} -eq 0 ]] && exit 0

echo "install_deps: installing ${missing[*]}" >&2
if [[ $(id -u) -eq 0 ]]; then sudo=(); elif command -v sudo >/dev/null; then sudo=(sudo); else
  echo "install_deps: missing packages (${missing[*]}) and not root: install them with apt-get" >&2; exit 1
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo[@]}" apt-get update -qq
"${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null

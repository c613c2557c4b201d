# shellcheck shell=bash disable=SC2034  # (PYTHON, JOBS, BUILD_DIR: for the scripts that source this)
# The preamble that every script in scripts/ sources (not a program of its own):
#   source "$(dirname "$0")/lib.sh"
# Sourcing it sets strict mode (set -euo pipefail), moves to the repository root and sets
#   SCRIPT     the script's name, for messages
#   PYTHON     /usr/bin/python3: Debian's interpreter, whose pandas and matplotlib install_deps provides
#   JOBS       build jobs (every core)
#   BUILD_DIR  the build folder: $DEMMAT_BUILD_DIR, else build; every script sets it with --build-dir DIR
# and defines
#   shared_option "$@"            the options every script takes: --build-dir DIR (sets BUILD_DIR),
#                                 -h/--help; anything else: unknown_option. Then `shift "$SHIFT"`.
#   usage [STATUS]                print the script's "# Usage:" comment block (and exit STATUS if given)
#   unknown_option OPT            one-line error naming OPT, exit 2
#   need_value "$@"               error unless the option in $1 has a value in $2
#   positive_int OPT VALUE        error unless VALUE is a positive integer (checked before any long work)
#   install_deps [--optional] [--fuzz]  install the missing Debian packages (scripts/install_deps.sh)
#   cmake_build [-q] [-S SRC] DIR [TARGET...] [-- CMAKE_ARG...]
#                                 configure DIR (Release unless a CMAKE_BUILD_TYPE is given) and build
#                                 only TARGETs (everything without any); -q: no build log on stdout
#   demmat_in DIR                 the absolute path of DIR's demmat program (still right after a cd)
#   contact_args LAW              the `--contact KEY=VALUE` words of a named law (paper: none)
set -euo pipefail
SCRIPT=$(basename "$0")
script_file=$(cd "$(dirname "$0")" && pwd)/$SCRIPT   # for usage, after the cd below
cd "$(dirname "${BASH_SOURCE[0]}")/.."
PYTHON=/usr/bin/python3
JOBS=$(nproc 2>/dev/null || echo 2)
BUILD_DIR=${DEMMAT_BUILD_DIR:-build}

usage() {
  # The "# Usage:" line and the indented comment lines after it, from the script's own header.
  awk '/^# Usage:/ { on = 1 } on && !/^# Usage:/ && !/^#  / { exit } on { sub(/^# /, ""); print }' "$script_file"
  [[ $# -eq 0 ]] || exit "$1"
}

# shared_option "$@": the options that every script takes, --build-dir DIR and -h/--help; anything
# else is an unknown option. Sets SHIFT to the number of arguments used: `shift "$SHIFT"`.
shared_option() {
  case "$1" in
    --build-dir) need_value "$@"; BUILD_DIR=$2; SHIFT=2 ;;
    -h|--help) usage 0 ;;
    *) unknown_option "$1" ;;
  esac
}

unknown_option() {
  echo "$SCRIPT: unknown option '$1' (scripts/$SCRIPT --help lists the options)" >&2
  exit 2
}

need_value() {
  if [[ $# -lt 2 || $2 == --* ]]; then
    echo "$SCRIPT: option $1 needs a value (scripts/$SCRIPT --help lists the options)" >&2
    exit 2
  fi
}

positive_int() {
  if ! [[ $2 =~ ^[0-9]+$ ]] || (( 10#$2 == 0 )); then
    echo "$SCRIPT: $1 must be a positive integer, not '$2'" >&2
    exit 2
  fi
}

install_deps() {
  scripts/install_deps.sh "$@"
}

cmake_build() {
  local quiet=0 src=. dir targets=() args=()
  [[ ${1:-} == -q ]] && { quiet=1; shift; }
  [[ ${1:-} == -S ]] && { src=$2; shift 2; }
  dir=$1; shift
  while [[ $# -gt 0 && $1 != -- ]]; do targets+=("$1"); shift; done
  [[ ${1:-} == -- ]] && shift
  args=("$@")
  [[ " ${args[*]} " == *" -DCMAKE_BUILD_TYPE="* ]] || args+=(-DCMAKE_BUILD_TYPE=Release)
  # Configuring an existing build folder keeps its cache and takes a second; its log is not needed
  # (errors and warnings go to stderr).
  cmake -S "$src" -B "$dir" "${args[@]}" >/dev/null
  local cmd=(cmake --build "$dir" -j "$JOBS")
  [[ ${#targets[@]} -eq 0 ]] || cmd+=(--target "${targets[@]}")
  if [[ $quiet == 1 ]]; then "${cmd[@]}" >/dev/null; else "${cmd[@]}"; fi
}

demmat_in() {
  if [[ $1 == /* ]]; then echo "$1/app/demmat"; else echo "$PWD/$1/app/demmat"; fi
}

# contact_args LAW: the scene options of the laws the scripts run, with the parameters of
# tests/test_memory_equivalence.cpp (paper, tsuji, linear_history, mindlin, mindlin_sds).
contact_args() {
  case "$1" in
    paper) ;;
    tsuji) echo "--contact damping=tsuji --contact restitution=0.6" ;;
    linear_history) echo "--contact tangential=linear_history --contact kt=100 --contact tangential_damping_ratio=0.5" ;;
    mindlin) echo "--contact tangential=mindlin --contact tangential_damping_ratio=0.5" ;;
    mindlin_sds) echo "--contact tangential=mindlin --contact tangential_damping_ratio=0.5 --contact rolling=sds" \
                      "--contact kr=50 --contact rolling_damping=0.05 --contact rolling_friction=0.2" ;;
    *) echo "$SCRIPT: unknown law '$1' (paper, tsuji, linear_history, mindlin, mindlin_sds)" >&2; return 2 ;;
  esac
}

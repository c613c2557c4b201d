#!/usr/bin/env bash
# LAMMPS built the way its users build it for speed, the peer of the suite's benchmarks (docs/peers.md):
# Debian's own source package of the installed lammps version (apt-get source, from a deb-src entry for
# the archive and suite that installed it, in this cache's own apt lists; nothing fetched from anywhere else), configured with
# CMake (GRANULAR for the granular pair and walls, OPENMP for the thread comparison, no MPI: every
# peer run is one process) and compiled by GCC with -O3 -march=native, into DIR/lammps (the build
# folder). Prints the path of its lmp on stdout. Skipped when the cached build matches: the stamp
# beside lmp records the source version, the compiler, the flags and the packages.
# Usage: scripts/build_lammps.sh [--jobs J] [--nice] [--print-stamp] [--build-dir DIR]
#   --jobs J         compile jobs (default: every core)
#   --nice           compile at the lowest priority (a machine shared with other work)
#   --print-stamp    print the stamp that a matching build has (what the build would be), build nothing
#   --build-dir DIR  the build folder (default build, or $DEMMAT_BUILD_DIR); LAMMPS goes in DIR/lammps
source "$(dirname "$0")/lib.sh"
jobs=$JOBS; nice=(); print_stamp=0
while [[ $# -gt 0 ]]; do
  case "$1" in
    --jobs) need_value "$@"; jobs=$2; shift 2 ;;
    --nice) nice=(nice -n 19); shift ;;
    --print-stamp) print_stamp=1; shift ;;
    *) shared_option "$@"; shift "$SHIFT" ;;
  esac
done
positive_int --jobs "$jobs"

flags="-O3 -march=native"
packages="GRANULAR OPENMP"
version=$(dpkg-query -W -f='${source:Version}' lammps 2>/dev/null || true)
if [[ -z $version ]]; then
  echo "$SCRIPT: Debian's lammps is not installed (its version names the source); scripts/install_deps.sh --optional installs it" >&2
  exit 1
fi
if [[ $BUILD_DIR == /* ]]; then cache=$BUILD_DIR/lammps; else cache=$PWD/$BUILD_DIR/lammps; fi
build=$cache/native
lmp=$build/lmp
stamp="source lammps $version; compiler $(g++ -dumpfullversion) $(g++ -dumpmachine); flags $flags; packages $packages; no MPI"
if [[ $print_stamp == 1 ]]; then echo "$stamp"; exit 0; fi
if [[ -x $lmp && -f $build/demmat-stamp && $(cat "$build/demmat-stamp") == "$stamp" ]]; then
  echo "$lmp"
  exit 0
fi

# The source: Debian's package of the installed version, unpacked (Debian's patches applied) once.
upstream=${version#*:}; upstream=${upstream%-*}
src=$cache/source/lammps-$upstream
if [[ ! -f $src/cmake/CMakeLists.txt ]]; then
  # A deb-src entry for the archive and suite that the installed binary came from (apt's policy says
  # which), in a sources list and package lists of this cache's own: the machine's apt setup is left as it is.
  read -r uri suite < <(apt-cache policy lammps | awk -v v="${version#*:}" '
    /^ *(\*\*\*)? *[^ ]+ [0-9]+$/ { here = index($0, v) > 0 } here && /https?:\/\// { print $2, $3; exit }') || true
  if [[ -z ${uri:-} ]]; then
    echo "$SCRIPT: apt does not say which archive lammps $version came from (apt-cache policy lammps)" >&2
    exit 1
  fi
  mkdir -p "$cache/apt/lists/partial"
  printf 'Types: deb-src\nURIs: %s\nSuites: %s\nComponents: %s\n' "$uri" "${suite%%/*}" "${suite#*/}" > "$cache/apt/deb-src.sources"
  apt=(apt-get -qq -o Dir::Etc::sourcelist="$cache/apt/deb-src.sources" -o Dir::Etc::sourceparts=-
       -o Dir::State::Lists="$cache/apt/lists" -o Dir::Cache::pkgcache= -o Dir::Cache::srcpkgcache= -o APT::Sandbox::User=root)
  echo "$SCRIPT: apt-get source lammps=$version (deb-src $uri $suite)" >&2
  "${apt[@]}" update >&2
  rm -rf "$cache/source"; mkdir -p "$cache/source"
  (cd "$cache/source" && "${apt[@]}" source "lammps=$version" >&2)
  [[ -f $src/cmake/CMakeLists.txt ]] || { echo "$SCRIPT: apt-get source left no $src/cmake/CMakeLists.txt" >&2; exit 1; }
fi

# LAMMPS's own CMake build; ccache where installed (a rebuild after a change of flags is then quick).
launcher=(); command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
pkg_args=(); for p in $packages; do pkg_args+=("-DPKG_$p=on"); done
rm -f "$build/demmat-stamp"
echo "$SCRIPT: building LAMMPS $version ($flags; $packages) in $build" >&2
"${nice[@]}" cmake -S "$src/cmake" -B "$build" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_CXX_COMPILER=g++ \
  -DCMAKE_CXX_FLAGS_RELEASE="$flags -DNDEBUG" \
  -DBUILD_MPI=off -DBUILD_OMP=on -DBUILD_SHARED_LIBS=off \
  -DWITH_JPEG=off -DWITH_PNG=off -DWITH_FFMPEG=off -DWITH_GZIP=off \
  "${pkg_args[@]}" "${launcher[@]}" >/dev/null
"${nice[@]}" cmake --build "$build" -j "$jobs" --target lmp >/dev/null
[[ -x $lmp ]] || { echo "$SCRIPT: the build left no $lmp" >&2; exit 1; }
echo "$stamp" > "$build/demmat-stamp"
echo "$lmp"

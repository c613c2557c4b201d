#!/usr/bin/env bash
# scripts/build_lammps.sh without building LAMMPS: apt, dpkg-query and cmake are stand-ins that record
# their calls. A bad --jobs stops it (exit 2, one line) before any work; a cached build whose stamp
# matches is taken as it is (its lmp printed, nothing fetched or configured); a stale stamp or a missing
# lmp configures anew with the packages and flags the stamp names, and a failed build leaves no stamp.
# Usage: tests/check_build_lammps.sh REPOSITORY_ROOT
set -uo pipefail
script=$1/scripts/build_lammps.sh
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
failed=0
fail() { echo "FAIL: $*"; failed=1; }

mkdir -p "$tmp/bin"
for tool in apt-get apt-cache cmake; do
  printf '#!/bin/sh\necho "%s $*" >> "%s/calls"\nexit 1\n' "$tool" "$tmp" > "$tmp/bin/$tool"
done
printf '#!/bin/sh\necho 1.2.3-4\n' > "$tmp/bin/dpkg-query"
chmod +x "$tmp"/bin/*
build() { PATH="$tmp/bin:$PATH" timeout 20 bash "$script" --build-dir "$tmp/b" "$@"; }
native=$tmp/b/lammps/native

for bad in 0 two -1; do
  err=$(build --jobs "$bad" 2>&1 >/dev/null); rc=$?
  [[ $rc == 2 && $(wc -l <<<"$err") == 1 && $err == *"--jobs"* ]] || fail "--jobs $bad: exit $rc, '$err'"
done
[[ ! -e $tmp/calls && ! -e $tmp/b ]] || fail "a refused option still did some work"

stamp=$(build --print-stamp)
for part in "lammps 1.2.3-4" "-O3 -march=native" "GRANULAR OPENMP"; do
  [[ $stamp == *"$part"* ]] || fail "the stamp '$stamp' does not name '$part'"
done

# A cached build that matches: taken as it is.
mkdir -p "$native" "$tmp/b/lammps/source/lammps-1.2.3/cmake"
touch "$tmp/b/lammps/source/lammps-1.2.3/cmake/CMakeLists.txt"
printf '#!/bin/sh\n' > "$native/lmp"; chmod +x "$native/lmp"
echo "$stamp" > "$native/demmat-stamp"
out=$(build 2>/dev/null); rc=$?
[[ $rc == 0 && $out == "$native/lmp" ]] || fail "a matching build: exit $rc, printed '$out', expected $native/lmp"
[[ ! -e $tmp/calls ]] || fail "a matching build was configured or fetched again: $(cat "$tmp/calls")"

# A stale stamp (another version or flags) and a stamp without its lmp: configured anew, the stamp gone.
for case in stale no-lmp; do
  rm -f "$tmp/calls"
  if [[ $case == stale ]]; then echo "${stamp/-O3/-O2}" > "$native/demmat-stamp"; else echo "$stamp" > "$native/demmat-stamp"; rm -f "$native/lmp"; fi
  build >/dev/null 2>&1 && fail "$case: the stand-in cmake failed, yet the script succeeded"
  calls=$(cat "$tmp/calls" 2>/dev/null)
  for part in "-DPKG_GRANULAR=on" "-DPKG_OPENMP=on" "-O3 -march=native" "-DBUILD_OMP=on"; do
    [[ $calls == "cmake "*"$part"* ]] || fail "$case: cmake was not configured with $part: '$calls'"
  done
  [[ $calls != *apt-get* ]] || fail "$case: the unpacked source was fetched again"
  [[ ! -e $native/demmat-stamp ]] || fail "$case: a failed build kept a stamp"
done
[[ $failed == 0 ]] && echo "build_lammps.sh: bad options refused, a matching build kept, a stale one rebuilt"
exit $failed

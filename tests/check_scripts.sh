#!/usr/bin/env bash
# The scripts' shared command line (scripts/lib.sh), checked without running any of them: every script
# parses; --help prints its usage line (exit 0); an unknown option, the retired --build and a
# --build-dir without its folder each stop it with one line on stderr naming the problem (exit 2),
# before any work. run_tests.sh hands options it does not know to ctest, so it gets the last two only.
# Usage: tests/check_scripts.sh REPOSITORY_ROOT
set -uo pipefail
root=$1
failed=0
fail() { echo "FAIL: $*"; failed=1; }

# expect_error SCRIPT TEXT ARGS...: exit 2 and one line on stderr that contains TEXT
expect_error() {
  local f=$1 text=$2 err rc
  shift 2
  err=$(timeout 20 bash "$f" "$@" 2>&1 >/dev/null); rc=$?
  [[ $rc == 2 ]] || fail "$(basename "$f") $*: exit $rc, expected 2"
  [[ $(wc -l <<<"$err") == 1 && $err == *"$text"* ]] || fail "$(basename "$f") $*: error '$err' does not name '$text' in one line"
}

for f in "$root"/scripts/*.sh; do
  name=$(basename "$f")
  bash -n "$f" || { fail "$name does not parse"; continue; }
  [[ $name == lib.sh ]] && continue
  out=$(timeout 20 bash "$f" --help 2>&1); rc=$?
  [[ $rc == 0 ]] || fail "$name --help: exit $rc"
  [[ $out == "Usage: scripts/$name "* ]] || fail "$name --help does not start with its usage line: ${out%%$'\n'*}"
  if [[ $name != run_tests.sh ]]; then
    expect_error "$f" "--no-such-option" --no-such-option
    expect_error "$f" "--build" --build somewhere
  fi
  expect_error "$f" "--build-dir" --build-dir
done
[[ $failed == 0 ]] && echo "every script: usage, unknown options, --build-dir"
exit $failed

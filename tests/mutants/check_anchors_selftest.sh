#!/usr/bin/env bash
# The anchor check fails on a tree with a stale mutant (its anchor found
# nowhere, twice, or in another file than the one it names) and passes on
# one whose anchor is found once in its file.
#   tests/mutants/check_anchors_selftest.sh SCRATCH_DIR
set -uo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
T=${1:?scratch folder}
rm -rf "$T" && mkdir -p "$T/tests/mutants" "$T/cd/src" "$T/analysis/src"
printf 'int f() { return 1; }\nint g() { return 2; }\nint h() { return 2; }\n' > "$T/cd/src/a.cpp"
mut() { printf 'file: cd/src/a.cpp\nfind: %s\nreplace: x\ntests: test_x\nwhy: a test\n' "$2" > "$T/tests/mutants/$1.mut"; }
expect() {  # expect CODE WORDS...
  local want=$1; shift
  out=$("$HERE/check_anchors.sh" "$T" 2>&1); code=$?
  [ "$code" = "$want" ] || { echo "exit $code, expected $want: $out"; exit 1; }
  for w in "$@"; do case "$out" in *"$w"*) ;; *) echo "missing '$w' in: $out"; exit 1 ;; esac; done
}
mut 01-once 'return 1;'
expect 0 "1 mutant anchors, each found once"
mut 02-nowhere 'return 3;'
expect 1 "stale mutant: 02-nowhere.mut"
rm "$T/tests/mutants/02-nowhere.mut"
mut 03-twice 'return 2;'
expect 1 "stale mutant: 03-twice.mut"
rm "$T/tests/mutants/03-twice.mut"
# Found once, but in another file than the one the mutant names.
printf 'int k() { return 4; }\n' > "$T/cd/src/b.cpp"
printf 'file: cd/src/a.cpp\nfind: return 4;\nreplace: x\ntests: test_x\nwhy: a test\n' > "$T/tests/mutants/04-elsewhere.mut"
expect 1 "stale mutant: 04-elsewhere.mut: its anchor is found in cd/src/b.cpp"
echo "the anchor check catches a missing, a repeated and a misplaced anchor"

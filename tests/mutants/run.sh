#!/usr/bin/env bash
# make mutants: applies each deliberate physics bug of tests/mutants/*.mut,
# one at a time, to a scratch copy of the sources, builds the tests the
# mutant names, runs them, and reports which mutants the tests kill.
#
#   tests/mutants/run.sh [BUILD_DIR] [NAME ...]   (default: build/mutants, all)
#
# A .mut file holds one mutant (docs: tests/mutants/README.md):
#   file: the file it edits (a hint: if the anchor is not there once, the
#         whole of cd/src and analysis/src is searched for it)
#   find: the anchor, a text that must occur exactly once (in the file, or
#         else in the tree)
#   replace: what replaces it
#   tests: test executables to run, each optionally with a gtest filter
#          (test_shear:LeesEdwards.*)
#   why: what the bug is and why a physics test must see it
# An anchor found nowhere or more than once is reported "stale" (the code
# moved on: refresh the anchor), not counted as killed. Killed: some test
# fails (or times out); survived: every test passes; "no build": the mutant
# does not compile (not counted).
set -uo pipefail
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
OUT=${1:-build/mutants}
shift || true
case "$OUT" in /*) ;; *) OUT="$ROOT/$OUT" ;; esac
SRC="$OUT/src"
BLD="$OUT/build"
TIMEOUT=${MUTANT_TIMEOUT:-900}
mkdir -p "$OUT"

# A fresh scratch copy of the tracked sources (the working tree's versions).
rm -rf "$SRC"
mkdir -p "$SRC"
(cd "$ROOT" && git ls-files -z | tar --null -T - -cf -) | tar -xf - -C "$SRC"
launcher=()
command -v ccache > /dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
cmake -S "$SRC" -B "$BLD" -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" > "$OUT/cmake.log" 2>&1 ||
  { echo "mutants: cmake failed, see $OUT/cmake.log" >&2; exit 1; }

# field and locate (the anchor's file), shared with check_anchors.sh.
. "$ROOT/tests/mutants/anchors.sh"

# Replaces the one occurrence of $FIND by $REPL in the file (exact text).
apply() {
  FIND=$2 REPL=$3 awk '{ i = index($0, ENVIRON["FIND"]);
    if (i) $0 = substr($0, 1, i - 1) ENVIRON["REPL"] substr($0, i + length(ENVIRON["FIND"])); print }' \
    "$1" > "$1.mut" && mv "$1.mut" "$1"
}

# Builds and runs the tests of a spec list; returns 0 if all pass.
run_tests() {
  local log=$1; shift
  local t bin filt targets=()
  for t in "$@"; do targets+=("${t%%:*}"); done
  cmake --build "$BLD" -j "${JOBS:-2}" --target "${targets[@]}" >> "$log" 2>&1 || return 2
  for t in "$@"; do
    bin=${t%%:*}
    filt=
    [ "$t" != "$bin" ] && filt="--gtest_filter=${t#*:}"
    (cd "$BLD/tests" && OMP_WAIT_POLICY=passive timeout "$TIMEOUT" "./$bin" $filt) >> "$log" 2>&1 || return 1
  done
  return 0
}

mapfile -t specs < <(ls "$ROOT"/tests/mutants/*.mut)
if [ $# -gt 0 ]; then
  sel=()
  for n in "$@"; do sel+=("$ROOT/tests/mutants/$n.mut"); done
  specs=("${sel[@]}")
fi

# The baseline: every test the mutants name passes on the unmutated copy.
all=()
for f in "${specs[@]}"; do read -ra ts <<< "$(field tests "$f")"; all+=("${ts[@]}"); done
mapfile -t all < <(printf '%s\n' "${all[@]}" | sort -u)
echo "mutants: baseline (${#all[@]} test runs) ..."
if ! run_tests "$OUT/baseline.log" "${all[@]}"; then
  echo "mutants: the unmutated sources fail their tests (see $OUT/baseline.log): no score" >&2
  exit 1
fi

killed=0 survived=0 stale=0 nobuild=0
survivors=()
for f in "${specs[@]}"; do
  name=$(basename "$f" .mut)
  hint=$(field file "$f")
  find=$(field find "$f")
  repl=$(field replace "$f")
  read -ra ts <<< "$(field tests "$f")"
  file=$(locate "$hint" "$find")
  if [ -z "$file" ]; then
    printf '%-34s stale (anchor not found exactly once)\n' "$name"
    stale=$((stale + 1))
    continue
  fi
  cp "$SRC/$file" "$OUT/pristine"
  apply "$SRC/$file" "$find" "$repl"
  log="$OUT/$name.log"
  : > "$log"
  start=$(date +%s)
  run_tests "$log" "${ts[@]}"
  rc=$?
  cp "$OUT/pristine" "$SRC/$file"
  secs=$(( $(date +%s) - start ))
  case $rc in
    0) printf '%-34s SURVIVED (%s; %ss)\n' "$name" "${ts[*]}" "$secs"; survived=$((survived + 1)); survivors+=("$name") ;;
    1) printf '%-34s killed (%ss)\n' "$name" "$secs"; killed=$((killed + 1)) ;;
    2) printf '%-34s no build (see %s)\n' "$name" "$log"; nobuild=$((nobuild + 1)) ;;
  esac
done
# Leave the scratch copy's objects as the unmutated sources' (ccache keeps both).
total=$((killed + survived))
echo "mutants: $killed of $total killed; $survived survived${survivors:+ (${survivors[*]})}; $stale stale; $nobuild did not build"
[ "$survived" = 0 ] && [ "$stale" = 0 ] && [ "$nobuild" = 0 ]

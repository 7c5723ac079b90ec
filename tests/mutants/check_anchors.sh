#!/usr/bin/env bash
# Every mutant's anchor is found exactly once in the tree (make test, no
# build): a refactor that moves one fails the suite until the mutant is
# refreshed, instead of leaving its bug checked by nothing (make mutants
# would only report it "stale").
#
#   tests/mutants/check_anchors.sh [TREE]   (default: this checkout)
set -uo pipefail
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
SRC=${1:-$ROOT}
. "$ROOT/tests/mutants/anchors.sh"
stale=0 n=0
for m in "$SRC"/tests/mutants/*.mut; do
  n=$((n + 1))
  at=$(locate "$(field file "$m")" "$(field find "$m")")
  if [ -z "$at" ]; then
    echo "stale mutant: $(basename "$m"): its anchor (find:) is not found exactly once in $(field file "$m") or in cd/src and analysis/src; refresh it"
    stale=$((stale + 1))
  elif [ "$at" != "$(field file "$m")" ]; then
    # make mutants would edit another file than the one the mutant names
    # (a 3D mutant whose anchor only the 2D code still holds, say).
    echo "stale mutant: $(basename "$m"): its anchor is found in $at, not in its file: $(field file "$m"); refresh it"
    stale=$((stale + 1))
  fi
done
[ "$n" -gt 0 ] || { echo "no mutants in $SRC/tests/mutants"; exit 1; }
[ "$stale" = 0 ] || exit 1
echo "$n mutant anchors, each found once"

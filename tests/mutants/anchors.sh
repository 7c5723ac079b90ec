# The anchors of the mutants (tests/mutants/*.mut), sourced by run.sh (make
# mutants) and check_anchors.sh (make test): both find a mutant's anchor in
# the tree $SRC the same way.

# A field of a .mut file: field NAME FILE.
field() { sed -n "s/^$1: //p" "$2" | head -n 1; }

# The anchor's file: the hint if it holds the anchor once, else the one
# file of the tree that does; empty if none or several.
locate() {
  local hint=$1 find=$2 n
  if [ -f "$SRC/$hint" ]; then
    n=$(grep -cF -- "$find" "$SRC/$hint")
    if [ "$n" = 1 ] && [ "$(grep -oF -- "$find" "$SRC/$hint" | wc -l)" = 1 ]; then echo "$hint"; return; fi
  fi
  local hits
  hits=$(cd "$SRC" && grep -rlF -- "$find" cd/src analysis/src 2> /dev/null)
  if [ "$(printf '%s\n' "$hits" | grep -c .)" = 1 ] &&
     [ "$(grep -oF -- "$find" "$SRC/$hits" | wc -l)" = 1 ]; then
    echo "$hits"
  fi
}

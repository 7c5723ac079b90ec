#!/bin/bash
# A campaign folder's manifest (make's campaign targets; docs/shear.md,
# "What made a campaign"): the make variables its runs were made with.
#
#   manifest.sh FILE DRY KEY=VALUE... [-- KEY=VALUE...]
#
# The pairs before `--` are compared, those after are a record. Without FILE,
# writes it (DRY=1, make -n: says it would). With FILE, refuses (exit 2) when
# a compared key differs, naming each difference and the way out (another
# CAMPAIGNS folder, or removing this one): runs made with other parameters
# would be mixed into it. Otherwise the record's lists grow by the values
# asked now (more values of I are more runs of the same campaign), the build
# too (a note when it changed: runs already done are not redone).
set -u
file=$1 dry=$2
shift 2
compared=()
while [ $# -gt 0 ] && [ "$1" != -- ]; do compared+=("$1"); shift; done
[ $# -gt 0 ] && shift
recorded=("$@" "builds=$(git -C "$(dirname "$0")" describe --always --dirty --tags 2>/dev/null || echo unknown)")
folder=$(dirname "$file")

# KEY = "value" lines; values are TOML basic strings (\ and " escaped).
quote() { local v=${1//\\/\\\\}; printf '"%s"' "${v//\"/\\\"}"; }
value_of() {  # the value of key $1 in FILE, unescaped; exit 1 when absent
  awk -v k="$1" 'index($0, k " = \"") == 1 {
      v = substr($0, length(k) + 5); sub(/"$/, "", v); gsub(/\\"/, "\"", v); gsub(/\\\\/, "\\", v)
      print v; found = 1; exit }
    END { exit !found }' "$file"
}
# The words of list $2 not already in list $1, appended to it.
union() {
  local out=$1 w
  for w in $2; do [[ " $out " == *" $w "* ]] || out="${out:+$out }$w"; done
  printf '%s' "$out"
}
write() {  # the manifest's text, from the compared pairs and record values "$@"
  echo "# What made this campaign folder: the make variables of its runs (written by make;"
  echo "# docs/shear.md, \"What made a campaign\"). make refuses to add runs made with"
  echo "# other values of the keys of the first part; the second is a record."
  local kv
  for kv in "${compared[@]}"; do echo "${kv%%=*} = $(quote "${kv#*=}")"; done
  echo "# record: the values run into this folder so far, and the builds that ran them"
  for kv in "$@"; do echo "${kv%%=*} = $(quote "${kv#*=}")"; done
}

if [ ! -f "$file" ]; then
  if [ "$dry" = 1 ]; then echo "make: would write $file (what made this campaign)"; exit 0; fi
  mkdir -p "$folder" || exit 2
  tmp=$(mktemp "$file.XXXXXX") || exit 2
  write "${recorded[@]}" > "$tmp"
  # ln: atomic, and fails if another make wrote it meanwhile (then compared below).
  if ln "$tmp" "$file" 2>/dev/null; then rm -f "$tmp"; echo "make: wrote $file"; exit 0; fi
  rm -f "$tmp"
fi

# KEY=value as typed on make's command line (quoted when empty or spaced).
shown() { if [ -z "$2" ] || [[ $2 == *" "* ]]; then printf '%s="%s"' "$1" "$2"; else printf '%s=%s' "$1" "$2"; fi; }
made=() asked=()
for kv in "${compared[@]}"; do
  key=${kv%%=*} want=${kv#*=}
  if ! have=$(value_of "$key"); then made+=("no $key"); asked+=("$(shown "$key" "$want")")
  elif [ "$have" != "$want" ]; then made+=("$(shown "$key" "$have")"); asked+=("$(shown "$key" "$want")"); fi
done
if [ ${#made[@]} -gt 0 ]; then
  join() { local IFS=' '; echo "$*"; }
  case $folder in
    */prep) what="campaign folder ${folder%/prep} (its samples, $folder/)" remove=${folder%/prep} ;;
    *) what="campaign $folder" remove=$folder ;;
  esac
  echo "make: $what was made with $(join "${made[@]}"), you asked $(join "${asked[@]}"):" \
    "use CAMPAIGNS=<another folder> or remove $remove ($file has what made it)" >&2
  exit 2
fi

# The record grows by what is asked now.
new=() changed=0
for kv in "${recorded[@]}"; do
  key=${kv%%=*} want=${kv#*=}
  have=$(value_of "$key") || have=""
  grown=$(union "$have" "$want")
  [ "$grown" != "$have" ] && changed=1
  if [ "$key" = builds ] && [ -n "$have" ] && [ "$grown" != "$have" ]; then
    echo "make: note: $folder's runs so far were made by build $have; new runs are made by $want (done runs are kept)"
  fi
  new+=("$key=$grown")
done
if [ $changed = 1 ] && [ "$dry" != 1 ]; then
  tmp=$(mktemp "$file.XXXXXX") || exit 2
  write "${new[@]}" > "$tmp" && mv "$tmp" "$file"
fi
exit 0

#!/usr/bin/env bash
# The rows of a validation table (tests/data/validation/): one per finished
# run (summary.toml status "done") of a validation campaign folder, each
# value a steady mean over the same strain window for every shape, with its
# standard error, and the run's cost from its summary.toml.
#
#   cd/campaign/validation_table.sh CDANALYSIS periodic|walls CAMPAIGN WINDOW > TABLE.csv
#
# periodic (CAMPAIGN/angularity/ns_*): `cdanalysis fit angularity --window
#   WINDOW --snapshots 10` over the finished runs: mu (= mu* = q/p), nu, z,
#   the anisotropies, the sliding and side-side shares, the partial
#   strengths and the stress-fabric check (docs/analysis.md), every column
#   of its angularity.csv but its run index;
# walls (CAMPAIGN/walls/ns_*): alpha, then the bulk's (the central half of
#   the gap, docs/shear.md) q/p, packing fraction and z under the periodic
#   table's names mu, nu and z, its mu = -sigma_xy/sigma_yy (bulk_mu), and
#   the top wall's tau/sigma (wall_mu), each `cdanalysis steady --window
#   WINDOW`.
# Both then give protocol, ns, N, I, strain (the run's end), window and, at
# the end, cpu_s, sweeps_mean and build (cdlab_version) of each run.
# periodic3 (CAMPAIGN/angularity/shape_*, make campaign-angularity DIM=3):
#   `cdanalysis report` over the finished runs, each over its own steady
#   window (WINDOW -) or over WINDOW (report --window; a run whose detected
#   window holds too few independent samples): protocol, shape, N, I, strain,
#   window_begin, window_end, then mu (-sigma_xy/sigma_yy), nu, z, p and
#   the fabric (q/p of the snapshots, a_c, a_n, a_t, the contact kinds'
#   shares, the q/p of the face-face contacts, the sliding share,
#   check_rel, the branch anisotropies a_ln, a_lt and check_rel_branch),
#   each with its _err, then cpu_s, sweeps_mean, build.
set -euo pipefail
CDA=$1 PROTOCOL=$2 CAMPAIGN=$3 WINDOW=$4
case "$PROTOCOL" in
  periodic) DIR=$CAMPAIGN/angularity PATTERN=ns_* ;;
  walls) DIR=$CAMPAIGN/walls PATTERN=ns_* ;;
  periodic3) DIR=$CAMPAIGN/angularity PATTERN=shape_* ;;
  *) echo "validation_table.sh: protocol '$PROTOCOL': periodic, walls or periodic3" >&2; exit 2 ;;
esac
runs=()
for r in $(ls -d "$DIR"/$PATTERN 2> /dev/null | sort -t_ -k2 -n); do
  grep -qs '^status = "done"' "$r/summary.toml" && runs+=("$r")
done
[ ${#runs[@]} -gt 0 ] || { echo "validation_table.sh: no finished run in $DIR" >&2; exit 1; }

. "$(dirname "$0")/toml.sh"  # toml FILE SECTION KEY
# N: the scene's particles.n, or its sample's (a run started from prep/ns_<n>).
grains() {
  local n; n=$(toml "$1/scene.toml" particles n)
  [ "$n" != 0 ] && { echo "$n"; return; }
  toml "$CAMPAIGN/prep/$(basename "$1")/scene.toml" particles n
}
provenance() {  # protocol,ns,N,I,strain,window
  echo "$PROTOCOL,${1##*_},$(grains "$1"),$(toml "$1/scene.toml" shear inertial_number),$(toml "$1/scene.toml" shear strain),$WINDOW"
}
cost() {
  local s=$1/summary.toml
  echo "$(toml "$s" "" cpu_time),$(toml "$s" "" sweeps_mean),$(toml "$s" "" cdlab_version)"
}

if [ "$PROTOCOL" = periodic3 ]; then
  out=$(mktemp -d)
  trap 'rm -rf "$out"' EXIT
  mkdir "$out/runs"
  for r in "${runs[@]}"; do ln -s "$r" "$out/runs/$(basename "$r")"; done
  # Exit 5: written with reservations, a run without a steady window left
  # out (it is named on stderr, and gets no row).
  window=()
  [ "$WINDOW" = - ] || window=(--window "$WINDOW")
  s=0; "$CDA" report "$out/runs" "${window[@]}" --out "$out/report" > "$out/log" 2>&1 || s=$?
  [ $s -eq 0 ] || [ $s -eq 5 ] || { cat "$out/log" >&2; exit 1; }
  [ $s -eq 0 ] || grep '^problem: ' "$out/log" >&2
  steady="mu:shear_stress_ratio nu:packing_fraction z:z p:p"
  fabric="q_over_p a_c a_n a_t face_face_share edge_face_share vertex_face_share edge_edge_share q_over_p_face_face sliding check_rel a_ln a_lt check_rel_branch a_c_branch"
  head="protocol,shape,N,I,strain,window_begin,window_end"
  for c in $steady; do head="$head,${c%%:*},${c%%:*}_err"; done
  for c in $fabric; do head="$head,$c,${c}_err"; done
  echo "$head,cpu_s,sweeps_mean,build"
  # column NAME of row RUN (by its index) of a report table
  col() {
    awk -F, -v want="$2" -v run="$3" 'NR == 1 { for (i = 1; i <= NF; ++i) if ($i == want) c = i; next }
      $1 == run { print (c ? $c : "nan"); exit }' "$out/report/$1"
  }
  tail -n +2 "$out/report/runs.csv" | while IFS=, read -r i folder _; do
    r=$(readlink -f "$out/runs/$(basename "${folder//\"/}")")
    case $(col steady.csv window_begin "$i") in nan | "") continue ;; esac
    line="periodic3,${r##*/shape_},$(grains "$r"),$(toml "$r/scene.toml" shear inertial_number),$(toml "$r/scene.toml" shear strain)"
    line="$line,$(col steady.csv window_begin "$i"),$(col steady.csv window_end "$i")"
    for c in $steady; do line="$line,$(col steady.csv "${c#*:}" "$i"),$(col steady.csv "${c#*:}_err" "$i")"; done
    for c in $fabric; do line="$line,$(col fabric.csv "$c" "$i"),$(col fabric.csv "${c}_err" "$i")"; done
    echo "$line,$(cost "$r")"
  done
elif [ "$PROTOCOL" = periodic ]; then
  out=$(mktemp -d)
  trap 'rm -rf "$out"' EXIT
  # The table is written before the fit of mu*(alpha), which needs 3 shapes.
  "$CDA" fit angularity "${runs[@]}" --window "$WINDOW" --snapshots 10 --out "$out" > "$out/log" 2>&1 || true
  [ -s "$out/angularity.csv" ] || { cat "$out/log" >&2; exit 1; }
  head -n 1 "$out/angularity.csv" | sed 's/^run,nsides,/protocol,ns,N,I,strain,window,/; s/$/,cpu_s,sweeps_mean,build/'
  # Its rows are in the order of alpha: each joined to its run by nsides.
  tail -n +2 "$out/angularity.csv" | while IFS= read -r row; do
    ns=$(echo "$row" | cut -d, -f2)
    r=$DIR/ns_$ns
    echo "$(provenance "$r"),${row#*,*,},$(cost "$r")"
  done | sort -t, -k2,2n
else
  # Named as the periodic table's (mu, nu, z) where the quantity is the
  # same, measured in the bulk: the two tables compare column by column.
  cols="bulk_q_over_p bulk_packing_fraction bulk_z bulk_mu wall_mu"
  head="protocol,ns,N,I,strain,window,alpha"
  for c in mu nu z bulk_mu wall_mu; do head="$head,$c,${c}_err"; done
  echo "$head,cpu_s,sweeps_mean,build"
  for r in "${runs[@]}"; do
    ns=${r##*_}
    line="$(provenance "$r"),$(awk -v n="$ns" 'BEGIN { printf "%.17g", n == 0 ? 0 : 8 * atan2(1, 1) / n }')"
    for c in $cols; do
      m=$("$CDA" steady "$r" --column "$c" --window "$WINDOW" | awk '$1 == "mean" { print $2 "," $4 }')
      [ -n "$m" ] || { echo "validation_table.sh: no steady mean of $c in $r" >&2; exit 1; }
      line="$line,$m"
    done
    echo "$line,$(cost "$r")"
  done
fi

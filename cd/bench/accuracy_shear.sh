#!/usr/bin/env bash
# The table of `make accuracy-shear` (Makefile): for every
# run folder DIR/ns_<s>/I_<I>/<setting>/, the steady means and error bars of
# q/p (mu*), packing fraction and z (cdanalysis steady: detected window,
# batch-means error bar), what the run cost (summary.toml), and each setting's
# distance to the reference of its (shape, I) in combined error bars:
#   dev = (x - x_ref) / sqrt(err^2 + err_ref^2).
# Writes DIR/table.csv and DIR/table.md; prints the markdown.
#   usage: accuracy_shear.sh CDANALYSIS DIR
set -euo pipefail
cda=$1
dir=$2
csv=$dir/table.csv
tmp=$csv.tmp

# "mean err" of one column of one run over the strain window $3 ("a:b").
steady() {
  "$cda" steady "$1" --column "$2" --window "$3" | awk '$1 == "mean" { print $2, $4 }'
}
# The steady window of q/p (cdanalysis' detection) of the reference run,
# used for every column and every setting of its (shape, I), so that all
# average the same stretch of strain; when q/p has none, the second half.
window() {
  "$cda" steady "$1" --column q_over_p 2>/dev/null | awk '$1 == "window" { print $3 ":" $5 }' | grep . ||
    awk -F, 'NR == 1 { for (i = 1; i <= NF; ++i) if ($i == "strain") c = i } NR > 1 { x = $c }
             END { print x / 2 ":" x }' "$1/series.csv"
}
# One key of summary.toml.
key() { awk -v k="$2" '$1 == k { print $3; exit }' "$1/summary.toml"; }

echo "shape,I,setting,window,mu,mu_err,phi,phi_err,z,z_err,wall_s,cpu_s,steps,sweeps_mean,cap_share,residual_max,overlap_max" >"$tmp"
for run in "$dir"/ns_*/I_*/*/; do
  run=${run%/}
  [ -f "$run/.done" ] || continue
  setting=$(basename "$run")
  i=$(basename "$(dirname "$run")")
  s=$(basename "$(dirname "$(dirname "$run")")")
  # Every setting of a (shape, I) averages over the reference's window.
  ref=$(dirname "$run")/ref
  if [ -f "$ref/.done" ]; then w=$(window "$ref"); else w=$(window "$run"); fi
  read -r mu mue < <(steady "$run" q_over_p "$w")
  read -r phi phie < <(steady "$run" packing_fraction "$w")
  read -r z ze < <(steady "$run" z "$w")
  echo "${s#ns_},${i#I_},$setting,$w,$mu,$mue,$phi,$phie,$z,$ze,$(key "$run" wall_time),$(key "$run" cpu_time),$(key "$run" steps),$(key "$run" sweeps_mean),$(key "$run" cap_share),$(key "$run" residual_max),$(key "$run" overlap_max)" >>"$tmp"
done
mv "$tmp" "$csv"

awk -F, 'NR > 1 { row[NR] = $0; if ($3 == "ref") { ref[$1 "," $2] = NR } n = NR }
function dev(a, ae, b, be) { return (be == "" || ae + be == 0) ? 0 : (a - b) / sqrt(ae * ae + be * be) }
END {
  print "| shape | I | setting | window (γ) | μ* = q/p | dev | φ | dev | z | dev | CPU s | CPU / ref | sweeps/step | at cap | max residual | max overlap (d̄) |"
  print "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
  for (k = 2; k <= n; ++k) {
    split(row[k], a, ","); r = ref[a[1] "," a[2]]
    if (r) split(row[r], b, ","); else split("", b)
    printf "| %s | %s | %s | %s | %.4f ± %.4f | %+.1f | %.4f ± %.4f | %+.1f | %.3f ± %.3f | %+.1f | %.1f | %.2f | %.0f | %.1f %% | %.1e | %.1e |\n",
      a[1] == 0 ? "disks" : a[1] "-gons", a[2], a[3], a[4], a[5], a[6], dev(a[5], a[6], b[5], b[6]),
      a[7], a[8], dev(a[7], a[8], b[7], b[8]), a[9], a[10], dev(a[9], a[10], b[9], b[10]),
      a[12], (r && b[12] > 0) ? a[12] / b[12] : 0, a[14], 100 * a[15], a[16], a[17]
  }
}' "$csv" | tee "$dir/table.md"

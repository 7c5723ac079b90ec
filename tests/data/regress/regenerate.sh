#!/usr/bin/env bash
# Regenerates the reference campaign of `make regress` and of
# test_analysis_regress (RealCampaign*): the same runs as `make regress`
# (100 disks, strain 3, p = 100 N/m, I = 0.01 ... 0.4), their series cut to the
# columns the mu(I) fit reads, and the stored fit. Run on purpose only, when
# a change of the physics or numerics is meant to move the curve, from the
# repository root:
#   tests/data/regress/regenerate.sh
# then review `git diff tests/data/regress` (the fit and its uncertainties)
# before committing.
set -euo pipefail
DIR=tests/data/regress
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
make --no-print-directory regress-campaign REGRESS_DIR="$TMP"
rm -rf "$DIR/inertial"
for run in "$TMP"/inertial/I_*; do
  out="$DIR/inertial/$(basename "$run")"
  mkdir -p "$out"
  cp "$run/scene.toml" "$out/"
  # step, time, strain, shear_rate, syy, kyy, q_over_p, inertial_number, packing_fraction
  awk -F, -v OFS=, 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i }
    { print $c["step"], $c["time"], $c["strain"], $c["shear_rate"], $c["syy"], $c["kyy"],
            $c["q_over_p"], $c["inertial_number"], $c["packing_fraction"] }' "$run/series.csv" > "$out/series.csv"
done
build/analysis/cdanalysis fit mu-i "$DIR/inertial" --window 1:3 --toml "$DIR/mu_i.toml"

#!/usr/bin/env bash
# Regenerates a reference campaign of `make regress` and of
# test_analysis_regress (SimulatorCampaign*): the same runs as `make regress`
# (2D: 100 disks, p = 100 N/m, I = 0.01 ... 0.4, into tests/data/regress;
# 3D: 200 spheres, p = 1e5 N/m^2, I = 0.02 ... 1, into tests/data/regress3d;
# strain 3 both), their series cut to the columns the mu(I) fit reads, and the
# stored fit. Run on purpose only, when a change of the physics or numerics is
# meant to move the curve, from the repository root:
#   tests/data/regress/regenerate.sh      # 2D
#   tests/data/regress/regenerate.sh 3    # 3D
# then review `git diff tests/data/regress*` (the fit and its uncertainties)
# before committing.
set -euo pipefail
DIM=${1:-2}
case "$DIM" in
  2) DIR=tests/data/regress; TARGET=regress-campaign; VAR=REGRESS_DIR; MU=q_over_p ;;
  3) DIR=tests/data/regress3d; TARGET=regress3-campaign; VAR=REGRESS3_DIR; MU=shear_stress_ratio ;;
  *) echo "regenerate.sh: the dimension is 2 or 3, not '$DIM'" >&2; exit 2 ;;
esac
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
make --no-print-directory "$TARGET" "$VAR=$TMP"
rm -rf "$DIR/inertial"
for run in "$TMP"/inertial/I_*; do
  out="$DIR/inertial/$(basename "$run")"
  mkdir -p "$out"
  cp "$run/scene.toml" "$out/"
  # step, time, strain, shear_rate, syy, kyy, mu (2D q_over_p, 3D shear_stress_ratio),
  # inertial_number, packing_fraction
  awk -F, -v OFS=, -v mu="$MU" 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i }
    { print $c["step"], $c["time"], $c["strain"], $c["shear_rate"], $c["syy"], $c["kyy"],
            $c[mu], $c["inertial_number"], $c["packing_fraction"] }' "$run/series.csv" > "$out/series.csv"
done
build/analysis/cdanalysis fit mu-i "$DIR/inertial" --window 1:3 --toml "$DIR/mu_i.toml"

#!/usr/bin/env bash
# Regenerates the synthetic mu(I) campaign and its stored fit (the reference
# of test_analysis_regress). Run on purpose only, from the repository root:
#   tests/data/analysis/regenerate.sh build
# then review `git diff tests/data/analysis` before committing.
set -euo pipefail
BUILD=${1:?usage: regenerate.sh BUILD_DIR}
DIR=tests/data/analysis/mu_i
cmake --build "$BUILD" --target gen_analysis_campaign cdanalysis
rm -rf "$DIR"
"$BUILD/tests/gen_analysis_campaign" "$DIR"
"$BUILD/analysis/cdanalysis" fit mu-i "$DIR" --toml "$DIR/fits.toml"

#!/bin/bash
# The make analyze-* targets: analysis/analyze.sh REPORT_CMD FIT_CMD...
# Runs the report and then every fit whatever the others gave (an analysis
# never dead-ends on its first refusal), and says which fits were written.
# Exit codes of cdanalysis (docs/errors.md): 0 done, 5 written with
# reservations (runs left out, parameters undetermined: named above them),
# 1 refused, 2 bad input. This script exits 0 when at least one fit was
# written (0 or 5), else 2 when a command met bad input, else 1.
report=$1
shift
echo "$report"
bash -c "$report"
report_rc=$?
worst=$report_rc
fitted=()
refused=()
for cmd in "$@"; do
  echo "$cmd"
  bash -c "$cmd"
  rc=$?
  name=$(awk '{ for (i = 1; i < NF; ++i) if ($i == "fit") { print "fit " $(i + 1); exit } }' <<< "$cmd")
  case $rc in
    0) fitted+=("$name") ;;
    5) fitted+=("$name (with reservations)") ;;
    *) refused+=("$name (exit $rc)"); [ "$rc" = 2 ] && worst=2 ;;
  esac
done
join() { local IFS=';'; echo "$*" | sed 's/;/; /g'; }
echo "analysis: report exit $report_rc;" \
  "fits written: $( [ ${#fitted[@]} -gt 0 ] && join "${fitted[@]}" || echo none );" \
  "refused: $( [ ${#refused[@]} -gt 0 ] && join "${refused[@]}" || echo none )"
[ ${#fitted[@]} -gt 0 ] && exit 0
[ "$worst" = 2 ] && exit 2
exit 1

#!/bin/bash
# make campaign-status: the state of each run of the campaigns asked, its
# cost so far and an ETA (docs/shear.md, "What made a campaign").
#
#   status.sh CAMPAIGNS NAME=RUN_FOLDERS...
#
# RUN_FOLDERS are the runs make would make now (its variables); the run
# folders already in CAMPAIGNS/NAME are shown too. A run is
#   done         its .done is there (make marks a run done when cdsim succeeded)
#   running      a cdsim holds its folder's lock (DIR/.cdsim.lock, /proc/locks)
#   not started  no folder
#   failed       diverged (summary.toml), or nothing written (see make's output)
#   stopped      by a signal, --max-steps or a kill: make resumes it from its checkpoint
# Progress is the series' last row: time over the run's duration (a shear
# run: strain over shear.strain). Cost: CPU seconds and steps of summary.toml
# (written when a session ends); for a running run, the steps of the series
# and the CPU of its current cdsim. ETA: the wall time per simulated second
# over the last 20 rows of timings.csv, times what is left.
set -u
campaigns=$1
shift

# toml FILE SECTION KEY (cd/campaign/toml.sh).
. "$(dirname "$0")/toml.sh"
# The last row's column $2 of a CSV file $1.
last_col() {
  awk -F, -v c="$2" 'NR == 1 { for (i = 1; i <= NF; ++i) if ($i == c) j = i; next } j { v = $j } END { if (j && v != "") print v }' "$1" 2>/dev/null
}
# The pid holding the fcntl lock of file $1, if any.
lock_holder() {
  [ -f "$1" ] || return 1
  local ino
  ino=$(stat -c %i "$1") || return 1
  awk -v ino="$ino" '$2 == "POSIX" { n = split($6, f, ":"); if (f[n] == ino) { print $5; found = 1; exit } }
    END { exit !found }' /proc/locks
}
fmt_time() {  # seconds -> "42 s", "12 min", "3.4 h"
  awk -v s="$1" 'BEGIN { if (s < 10) printf "%.1f s", s; else if (s < 120) printf "%.0f s", s; else if (s < 7200) printf "%.0f min", s / 60;
    else printf "%.1f h", s / 3600 }'
}

# Progress of run $1 (0..1) from its series and scene, and the simulated
# time at which it ends; empty when it cannot be told.
progress() {
  local run=$1 t strain target dur
  t=$(last_col "$run/series.csv" time)
  [ -n "$t" ] || return
  target=$(toml "$run/scene.toml" shear strain)
  strain=$(last_col "$run/series.csv" strain)
  dur=$(toml "$run/scene.toml" time duration)
  awk -v t="$t" -v g="$strain" -v G="$target" -v d="$dur" 'BEGIN {
    if (G + 0 > 0 && g + 0 > 0) end = t * G / g; else end = d + 0
    if (end > 0) printf "%.6g %.6g\n", (t / end > 1 ? 1 : t / end), end }'
}
# Wall seconds per simulated second over the last 20 rows of timings.csv.
wall_rate() {
  awk -F, 'NR > 1 { n = NR - 1; t[n] = $2; w = 0; for (i = 3; i <= NF; ++i) w += $i; wall[n] = w }
    END { if (n < 2) exit; k = n > 20 ? 20 : n - 1; s = 0
          for (i = n - k + 1; i <= n; ++i) s += wall[i]
          if (t[n] > t[n - k]) printf "%.6g\n", s / (t[n] - t[n - k]) }' "$1/timings.csv" 2>/dev/null
}

declare -A count
cpu_done=0
for arg in "$@"; do
  name=${arg%%=*}
  runs=(${arg#*=})
  folder=$campaigns/$name
  for d in "$folder"/*/; do  # the runs already there, made with other values too
    [ -d "$d" ] && [[ " ${runs[*]} " != *" ${d%/} "* ]] && runs+=("${d%/}")
  done
  [ ${#runs[@]} -gt 0 ] || continue
  echo "$name ($folder/)$( [ -f "$folder/manifest.toml" ] || echo ": no manifest.toml yet" )"
  printf '  %-20s %-8s %-36s %-8s %s\n' run progress cost ETA state
  for run in "${runs[@]}"; do
    read -r f end <<< "$(progress "$run")"
    pct=$( [ -n "${f:-}" ] && awk -v f="$f" 'BEGIN { printf "%.0f %%", 100 * f }' || echo -)
    steps=$(toml "$run/summary.toml" "" steps)
    cpu=$(toml "$run/summary.toml" "" cpu_time)
    cost=$( [ -n "$cpu" ] && printf 'CPU %s, %s steps' "$(fmt_time "$cpu")" "$steps" || echo -)
    eta=-
    if [ -f "$run/.done" ]; then
      state=done; pct="100 %"
      [ -n "$cpu" ] && cpu_done=$(awk -v a="$cpu_done" -v b="$cpu" 'BEGIN { print a + b }')
    elif pid=$(lock_holder "$run/.cdsim.lock"); then
      state=running
      steps=$(last_col "$run/series.csv" step)
      cpu=$(ps -o times= -p "$pid" 2>/dev/null | tr -d ' ')
      cost="${steps:-0} steps$( [ -n "$cpu" ] && printf ', CPU %s this session' "$(fmt_time "$cpu")")"
      rate=$(wall_rate "$run")
      t=$(last_col "$run/series.csv" time)
      if [ -n "$rate" ] && [ -n "${end:-}" ]; then
        eta=$(fmt_time "$(awk -v r="$rate" -v e="$end" -v t="$t" 'BEGIN { print r * (e - t) }')")
      fi
    elif [ ! -d "$run" ]; then
      state="not started"
    else
      case $(toml "$run/summary.toml" "" status) in
        diverged) state="failed (diverged: summary.toml)" ;;
        done) state="finished (make marks it done)" ;;
        "") if [ -f "$run/series.csv" ]; then state="stopped (killed; make resumes it)"
            else state="failed (nothing written; see make's output)"; fi ;;
        max-steps) state="stopped (--max-steps; make resumes it)" ;;
        *) state="stopped (a signal; make resumes it)" ;;
      esac
    fi
    kind=${state%% (*}
    count[$kind]=$(( ${count[$kind]:-0} + 1 ))
    printf '  %-20s %-8s %-36s %-8s %s\n' "${run#$folder/}" "$pct" "$cost" "$eta" "$state"
  done
done
summary=""
for s in done running stopped failed finished "not started"; do
  [ -n "${count[$s]:-}" ] && summary="$summary${summary:+, }${count[$s]} $s"
done
echo "${summary:-no runs}; CPU of the done runs $(fmt_time "$cpu_done")"

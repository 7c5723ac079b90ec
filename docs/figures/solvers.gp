# The solver comparison of docs/accuracy.md: law residual against
# time for each method on the four frozen dense-shear steps of
# tests/data/frozen-shear, from the history.csv that cd/bench/solvers writes:
#   for f in tests/data/frozen-shear/*.cdp.gz; do gunzip -c $f > /tmp/fz/$(basename $f .gz); done
#   build/cd/bench/solvers /tmp/fz/*.cdp --methods nlgs,cold,sor:1.3,sor-adapt,apgd,ssn:100 \
#     --threads 1 --time-limit 6 --csv outputs/solvers
#   gnuplot -e "hist='outputs/solvers/history.csv'" docs/figures/solvers.gp
if (!exists("hist")) hist = 'outputs/solvers/history.csv'
if (!exists("out")) out = 'docs/figures/solvers.png'
set terminal pngcairo size 1400,1000 font ",11"
set output out
set datafile separator ","
set logscale xy
set format y "10^{%L}"
set xlabel "time (ms, one thread)"
set ylabel "largest law residual / mean |p|"
set grid
set key bottom left
problems = "ns0_I1e-2_step1000 ns0_I1e-3_step400 ns6_I1e-2_step1000 ns6_I1e-3_step400"
titles = "'disks, I = 1e-2 (2250 rows)' 'disks, I = 1e-3 (2277 rows)' 'hexagons, I = 1e-2 (3833 rows)' 'hexagons, I = 1e-3 (3978 rows)'"
methods = "nlgs cold sor:1.3 sor-adapt apgd ssn:100"
set multiplot layout 2,2 title "Frozen dense-shear steps (N = 1000): residual against time, from the step's warm start (cold: from zero)"
do for [k = 1:4] {
  p = word(problems, k)
  set title word(titles, k)
  plot for [m in methods] hist using ((strcol(1) eq "fz/".p && strcol(2) eq m) ? 1e3 * $4 : 1/0):6 \
       with lines lw 2 title m, \
       1e-4 with lines dt 2 lc rgb "black" title "1e-4"
}
unset multiplot

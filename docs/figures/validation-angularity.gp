# The angularity figure of docs/validation.md: mu* = q/p, the packing
# fraction phi and the fabric and force anisotropies against the angularity
# alpha = 2 pi / n_s (disks: 0) of regular polygons, the observables of
# Azema, Estrada & Radjai, Phys. Rev. E 86, 041301 (2012). From the
# repository root:
#   gnuplot docs/figures/validation-angularity.gp
# Two sets, both committed:
#   docs/figures/angularity.csv (`cdanalysis fit angularity`, docs/analysis.md):
#     N = 300, d_max/d_min = 2, I = 0.01, solver.tol 1e-4, with the fit
#     mu*(alpha) = mu0 + (mu1 - mu0)(1 - exp(-alpha/alpha_c)) given there;
#   tests/data/validation/angularity-periodic.csv (`make validate-angularity`,
#     its columns those of `cdanalysis fit angularity`):
#     N = 1000, d_max/d_min = 4, I = 1e-3, window 1-3; one row per finished
#     shape, so the figure grows as the campaign's rows are added; with the
#     fit stored beside it (angularity-periodic-fits.toml, read here) and
#     the same grains between rough walls (angularity-walls.csv: the bulk's
#     q/p and packing fraction under the names mu and nu).
if (!exists("study")) study = 'docs/figures/angularity.csv'
if (!exists("val")) val = 'tests/data/validation/angularity-periodic.csv'
if (!exists("walls")) walls = 'tests/data/validation/angularity-walls.csv'
if (!exists("fits")) fits = 'tests/data/validation/angularity-periodic-fits.toml'
# a parameter's value from the fits' TOML: the "value" line of [mu_alpha.params.<name>]
param(name) = real(system(sprintf("awk '/^\\[mu_alpha.params.%s\\]/{f=1} f && /^value/{print $3; exit}' %s", name, fits)))
v0 = param("mu0"); v1 = param("mu1"); vc = param("alpha_c")
if (!exists("out")) out = 'docs/figures/validation-angularity.png'
set datafile separator ","
set datafile columnheaders
alpha(ns) = (ns == 0 ? 0 : 2*pi/ns)
set terminal pngcairo size 1500,500 font ",12" enhanced
set output out
set grid
set xrange [-0.1:2.3]
set xlabel "angularity α = 2π/n_s"
set x2range [-0.1:2.3]
set x2tics ("disks" 0, "20" 2*pi/20, "6" 2*pi/6, "5" 2*pi/5, "4" 2*pi/4, "3" 2*pi/3)
set x2tics font ",10"
set multiplot layout 1,3
set ylabel "μ* = q/p"
set yrange [0.25:0.55]
set key bottom right font ",10"
mu0 = 0.296; mu1 = 0.480; ac = 1.16
plot mu0 + (mu1 - mu0)*(1 - exp(-x/ac)) with lines lw 2 lc rgb '#1f3b73' title 'fit, N = 300, I = 0.01', \
     v0 + (v1 - v0)*(1 - exp(-x/vc)) with lines lw 2 dt 2 lc rgb '#b03a2e' title 'fit, N = 1000, periodic', \
     study using (column("alpha")):(column("mu")):(column("mu_err")) with yerrorbars pt 7 ps 1.2 lc rgb 'black' title 'N = 300, r = 2, I = 0.01', \
     val using (column("alpha")):(column("mu")):(column("mu_err")) with yerrorbars pt 5 ps 1.4 lc rgb '#b03a2e' title 'N = 1000, r = 4, I = 10^{-3}, periodic', \
     walls using (column("alpha")+0.02):(column("mu")):(column("mu_err")) with yerrorbars pt 4 ps 1.4 lc rgb '#2e7d32' title 'the same, walls (bulk)'
set ylabel "packing fraction φ"
set yrange [0.77:0.835]
set key bottom left font ",10"
plot study using (column("alpha")):(column("nu")):(column("nu_err")) with yerrorbars pt 7 ps 1.2 lc rgb 'black' title 'N = 300, r = 2, I = 0.01', \
     val using (column("alpha")):(column("nu")):(column("nu_err")) with yerrorbars pt 5 ps 1.4 lc rgb '#b03a2e' title 'N = 1000, r = 4, I = 10^{-3}, periodic', \
     walls using (column("alpha")+0.02):(column("nu")):(column("nu_err")) with yerrorbars pt 4 ps 1.4 lc rgb '#2e7d32' title 'the same, walls (bulk)'
set ylabel "anisotropy (black, blue, red: N = 300; open: N = 1000)"
set yrange [0:0.6]
set key top left
plot study using (column("alpha")):(column("a_c")):(column("a_c_err")) with yerrorbars pt 7 ps 1.2 lc rgb 'black' title 'a_c', \
     study using (column("alpha")):(column("a_c")) with lines lc rgb 'black' notitle, \
     study using (column("alpha")):(column("a_fn")):(column("a_fn_err")) with yerrorbars pt 9 ps 1.2 lc rgb '#1f3b73' title 'a_{fn}', \
     study using (column("alpha")):(column("a_fn")) with lines lc rgb '#1f3b73' notitle, \
     study using (column("alpha")):(column("a_ft")):(column("a_ft_err")) with yerrorbars pt 5 ps 1.2 lc rgb '#b03a2e' title 'a_{ft}', \
     study using (column("alpha")):(column("a_ft")) with lines lc rgb '#b03a2e' notitle, \
     val using (column("alpha")):(column("a_c")):(column("a_c_err")) with yerrorbars pt 6 ps 1.4 lc rgb 'black' title 'a_c, N = 1000', \
     val using (column("alpha")):(column("a_fn")):(column("a_fn_err")) with yerrorbars pt 8 ps 1.4 lc rgb '#1f3b73' title 'a_{fn}, N = 1000', \
     val using (column("alpha")):(column("a_ft")):(column("a_ft_err")) with yerrorbars pt 4 ps 1.4 lc rgb '#b03a2e' title 'a_{ft}, N = 1000'
unset multiplot

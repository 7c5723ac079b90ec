# The 3D critical states of the README: mu(I) and phi(I) of the
# 1000-sphere inertial ladder with the fits and their 1-sigma bands, beside
# the law of Jop, Forterre & Pouliquen, Nature 441, 727 (2006) for glass
# beads (mu1 = tan 20.9 deg, mu2 = tan 32.76 deg, I0 = 0.279). From the
# files `make analyze-inertial-ladder DIM=3` writes:
#   gnuplot -e "dir='outputs/analysis3d/inertial-ladder'" docs/figures/critical3d.gp
# (docs/3d.md, "Critical-state campaigns in 3D", gives the fit commands).
if (!exists("dir")) dir = 'outputs/analysis3d/inertial-ladder'
if (!exists("out")) out = 'docs/figures/critical3d.png'
set terminal pngcairo size 1300,520 font ",12" enhanced
set output out
set datafile separator ","
set logscale x
set format x "10^{%L}"
set xrange [5e-4:0.6]
set grid
set multiplot layout 1,2
set xlabel "I = γ̇ d (ρ/σ_{yy})^{1/2}"
set ylabel "μ = −σ_{xy}/σ_{yy}"
set key top left
mu1 = tan(20.9*pi/180); mu2 = tan(32.76*pi/180); I0 = 0.279
jop(x) = mu1 + (mu2 - mu1)/(1 + I0/x)
plot dir.'/mu_I/mu_I_fit.csv' every ::1 using 1:3:4 with filledcurves fc rgb '#cce5ff' title '1σ band', \
     dir.'/mu_I/mu_I_fit.csv' every ::1 using 1:2 with lines lw 2 lc rgb '#1f3b73' title 'μ(I) fit', \
     jop(x) with lines dt 2 lw 2 lc rgb '#b03a2e' title 'Jop et al. 2006 (glass beads)', \
     dir.'/mu_I/mu_I_data.csv' every ::1 using 1:2:3 with yerrorbars pt 7 ps 1.2 lc rgb 'black' title 'cdsim, 1000 spheres, μ_p = 0.4'
set ylabel "packing fraction φ"
set key bottom left
plot dir.'/nu_i/nu_I_fit.csv' every ::1 using 1:2 with lines lw 2 lc rgb '#1f3b73' title 'φ_{max} − a I (χ²/dof 61)', \
     dir.'/nu_i/nu_I_data.csv' every ::1 using 1:3:2:4 with xyerrorbars pt 7 ps 1.2 lc rgb 'black' title 'cdsim'
unset multiplot

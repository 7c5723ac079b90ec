# The 2D figure of docs/validation.md: mu(I) and phi(I) of frictional disks
# (mu_p = 0.4, e = 0, d_max/d_min = 2) sheared in the bi-periodic
# Lees-Edwards cell at imposed p, with the linear laws of da Cruz et al.,
# Phys. Rev. E 72, 021309 (2005), mu = mu_min + b I and phi = phi_max - a I,
# fitted here to the committed points. From the repository root:
#   gnuplot docs/figures/validation-mu-i-2d.gp
# It prints the fitted parameters and reads docs/figures/validation-mu-i-2d.csv,
# whose rows are
#   regress:   the 100-disk reference campaign of `make regress`
#              (tests/data/regress/inertial, strain 3, window 1-3), as
#                cdanalysis fit mu-i tests/data/regress/inertial --window 1:3 --out DIR
#                cdanalysis fit nu-i tests/data/regress/inertial --window 1:3 --out DIR
#              write them (mu_I_data.csv: I, mu = q/p; nu_I_data.csv: I,
#              I_err, phi), I the measured inertial number;
#   fresh1000: the 1000-disk fresh runs of docs/shear.md ("Ladder", N = 1000,
#              STRAIN = 4, SHEAR_TOL = 1e-3, window 1-4), q/p and phi as its
#              table gives them, I the imposed one.
# The linear laws are fitted to the regress points with I <= 0.3 (the
# imposed 0.4 was still in its transient) and to the four fresh1000 points,
# by weighted least squares, errors scaled by max(1, chi^2/dof) as cdanalysis
# scales its own. The saturating curves are cdanalysis' mu(I) fits of the
# same sets: tests/data/regress/mu_i.toml and docs/shear.md.
if (!exists("csv")) csv = 'docs/figures/validation-mu-i-2d.csv'
if (!exists("out")) out = 'docs/figures/validation-mu-i-2d.png'
set datafile separator ","
set fit quiet
set fit logfile '/dev/null'
set fit errorvariables
reg(x) = (strcol(1) eq "regress" && column(3) <= 0.3) ? x : NaN
big(x) = (strcol(1) eq "fresh1000") ? x : NaN
lin(x, c0, c1) = c0 + c1*x
# Parameter errors scaled by max(1, chi^2/dof): gnuplot scales by chi^2/dof.
scale(e) = e / FIT_STDFIT * sqrt(FIT_WSSR/FIT_NDF > 1 ? FIT_WSSR/FIT_NDF : 1)
report(what, n0, v0, e0, n1, v1, e1) = sprintf("%s: %s = %.4f +- %.4f, %s = %.3f +- %.3f, chi2/dof %.2f (dof %d)", \
  what, n0, v0, e0, n1, v1, e1, FIT_WSSR/FIT_NDF, FIT_NDF)
mr = 0.28; br = 1.0
fit lin(x, mr, br) csv every ::1 using (reg($3)):5:6 yerror via mr, br
print report("100 disks, I <= 0.3, mu = q/p", "mu_min", mr, scale(mr_err), "b", br, scale(br_err))
pr = 0.81; ar = -0.3
fit lin(x, pr, ar) csv every ::1 using (reg($3)):7:8 yerror via pr, ar
print report("100 disks, I <= 0.3, phi", "phi_max", pr, scale(pr_err), "-a", ar, scale(ar_err))
mb = 0.28; bb = 1.0
fit lin(x, mb, bb) csv every ::1 using (big($3)):5:6 yerror via mb, bb
print report("1000 disks, I = 0.003-0.1, mu = q/p", "mu_min", mb, scale(mb_err), "b", bb, scale(bb_err))
pb = 0.81; ab = -0.3
fit lin(x, pb, ab) csv every ::1 using (big($3)):7:8 yerror via pb, ab
print report("1000 disks, I = 0.003-0.1, phi", "phi_max", pb, scale(pb_err), "-a", ab, scale(ab_err))
sat(x, m1, m2, i0) = m1 + (m2 - m1)/(1 + i0/x)
set terminal pngcairo size 1300,540 font ",12" enhanced
set output out
set logscale x
set format x "10^{%L}"
set xrange [2e-3:0.7]
set grid
set multiplot layout 1,2
set xlabel "I = γ̇ d (ρ/σ_{yy})^{1/2}"
set ylabel "μ* = q/p"
set key top left
plot sat(x, 0.281, 0.887, 0.341) with lines lw 2 lc rgb 'black' title 'μ(I) fit, 100 disks', \
     sat(x, 0.277, 0.67, 0.20) with lines lw 2 lc rgb '#2e7d32' title 'μ(I) fit, 1000 disks', \
     (x <= 0.3 ? lin(x, mr, br) : NaN) with lines dt 2 lw 2 lc rgb 'black' title sprintf('μ_{min} + b I = %.3f + %.2f I', mr, br), \
     (x <= 0.1 ? lin(x, mb, bb) : NaN) with lines dt 2 lw 2 lc rgb '#2e7d32' title sprintf('μ_{min} + b I = %.3f + %.2f I', mb, bb), \
     csv every ::1 using (strcol(1) eq "regress" ? $3 : NaN):5:4:6 with xyerrorbars pt 7 ps 1.1 lc rgb 'black' title '100 disks (make regress), γ = 1–3', \
     csv every ::1 using (strcol(1) eq "fresh1000" ? $3 : NaN):5:6 with yerrorbars pt 5 ps 1.1 lc rgb '#2e7d32' title '1000 disks, γ = 1–4'
set ylabel "packing fraction φ"
set key bottom left
plot (x <= 0.3 ? lin(x, pr, ar) : NaN) with lines dt 2 lw 2 lc rgb 'black' title sprintf('φ_{max} − a I = %.4f − %.3f I', pr, -ar), \
     (x <= 0.1 ? lin(x, pb, ab) : NaN) with lines dt 2 lw 2 lc rgb '#2e7d32' title sprintf('φ_{max} − a I = %.4f − %.3f I', pb, -ab), \
     csv every ::1 using (strcol(1) eq "regress" ? $3 : NaN):7:4:8 with xyerrorbars pt 7 ps 1.1 lc rgb 'black' title '100 disks (make regress), γ = 1–3', \
     csv every ::1 using (strcol(1) eq "fresh1000" ? $3 : NaN):7:8 with yerrorbars pt 5 ps 1.1 lc rgb '#2e7d32' title '1000 disks, γ = 1–4'
unset multiplot

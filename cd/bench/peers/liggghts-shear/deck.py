#!/usr/bin/python3
"""A LIGGGHTS 3.8 input (Debian's `liggghts`) for the soft-sphere twin of a
cdsim 3D mu(I) point: plane shear of frictional spheres at imposed normal
stress, driven by two rough walls, periodic along x (flow) and z
(vorticity), no gravity.

Why walls: Debian's LIGGGHTS 3.8 gives a triclinic (Lees-Edwards) box no
ghost atoms, so the `fix deform ... remap v` route loses atoms; rough walls
are the usual substitute, at the price of layering near them (the bulk
shear rate is 1.06-1.25 times the nominal one).

usage: deck.py OUTDIR [key=value ...]    keys and defaults: DEFAULTS below

The scene
  grains   N spheres, diameters in [a, ratio a] of number mean d, drawn
           as cdsim draws a scene's (particles.size_dist, cd/src/scene/
           derived.cpp): uniform_area, pdf ~ 1/d^2 (cdsim's default and its
           3D shear samples', ratio 2), or uniform; density rho; Hertz-Mindlin with history
           ("hertz tangential history"), E = Ep p, Poisson nu, restitution
           en, friction mu, the same for grain-wall contacts.
  walls    Lxz x Lxz glued spheres of diameter d on a square grid of pitch
           d, jittered +-0.1 d in x and z, +-0.25 d in y; the bottom fixed,
           the top a rigid body of mass M (its spheres' density wallrho
           rho) free along y under the grains' force and the imposed -p A
           (`fix aveforce`: each of its spheres gets the mean force; `fix
           setforce` holds v_x and v_z), so that <F_y> = p A exactly
           whenever its momentum is steady, at any contact stiffness.
  prepare  random sequential addition of the grains at packing fraction
           phi0 between the walls; (A) the top wall comes down at rate
           rmax H/t_p (`fix move`) until the grains' layer holds phi =
           0.55; (B) the wall under -p A for tB t_p (records of F_y/(p A)
           in prep_ave.txt).
  shear    V = gdot H0 (gdot = I sqrt(p/rho)/d, H0 the wall gap at the
           start of shear), the grains given the linear profile, the wall
           under -p A moving along x at V. gamma = V t / H0.
  Why not a servo on the wall's velocity from its force error (the deck's
  first form, v_y = H g (F_y/(pA) - 1)/t_p with g ~ p/K): at a stiffness
  E/p = 1e6 its gain is so small that the dilatancy of shear kept p at
  0.84 of the target after gamma = 2.
  step     dtfac times the Hertz duration of a collision of two of the
           smallest grains at sqrt(p/rho).
  records  every dgamma of strain (averaged over every 10th step): the wall
           forces, the gap H, the mean contact number; a dump of every
           atom and one of every contact (the pair, its normal force:
           shear.contacts) every 5 dgamma (phi, z, profiles).
Writes OUTDIR/in.shear, OUTDIR/shear.data and OUTDIR/params.txt (what
post.py reads).
"""
import math
import os
import random
import sys

DEFAULTS = dict(N=1000, I=0.01, strain=2.0, Ep=1e5, en=0.1, mu=0.4, nu=0.3, ratio=2.0, dist="uniform_area",
                seed=12345, dtfac=0.1, p=100.0, d=1e-3, rho=2600.0, phi0=0.35, wallrho=1.0,
                tB=40.0, skin=0.15, dgamma=0.02, Lxz=8, rmax=0.02)
INTS = {"N", "seed", "Lxz"}


def options(argv):
    o = dict(DEFAULTS)
    for a in argv:
        k, sep, v = a.partition("=")
        if not sep or k not in o:
            sys.exit("deck.py: unknown option '%s' (keys: %s)" % (a, " ".join(DEFAULTS)))
        if k == "dist":
            if v not in ("uniform", "uniform_area"):
                sys.exit("deck.py: dist '%s': uniform or uniform_area" % v)
            o[k] = v
        else:
            o[k] = int(v) if k in INTS else float(v)
    return o


def diameter_range(o):
    """[a, b], b = ratio a, whose number mean is d under the law dist (cdsim's diameter_range)."""
    r, d = o["ratio"], o["d"]
    if r == 1.0:
        return d, d
    a = 2.0 * d / (1.0 + r) if o["dist"] == "uniform" else d * (r - 1.0) / (r * math.log(r))
    return a, a * r


def hertz_duration(o, E_eff):
    """Duration of a head-on Hertz collision of two of the smallest grains at sqrt(p/rho)."""
    dmin = diameter_range(o)[0]
    m_eff = 0.5 * o["rho"] * math.pi * dmin ** 3 / 6
    r_eff = dmin / 4
    v = math.sqrt(o["p"] / o["rho"])
    return 2.87 * (m_eff ** 2 / (r_eff * E_eff ** 2 * v)) ** 0.2


def place_grains(o, rng, diam, L, y0, height):
    """Random sequential addition, largest first, in [0, L) x [y0, y0 + height] x [0, L)."""
    placed = {}
    for i in sorted(range(len(diam)), key=lambda k: -diam[k]):
        r = diam[i] / 2
        for _ in range(200000):
            c = (L * rng.random(), y0 + r + (height - 2 * r) * rng.random(), L * rng.random())
            if all(far_enough(c, placed[j], (diam[i] + diam[j]) / 2 * 1.001, L) for j in placed):
                placed[i] = c
                break
        else:
            sys.exit("deck.py: could not place grain %d at phi0 = %g" % (i, o["phi0"]))
    return [placed[i] for i in range(len(diam))]


def far_enough(a, b, dist, L):
    dx = a[0] - b[0]
    dx -= L * round(dx / L)
    dz = a[2] - b[2]
    dz -= L * round(dz / L)
    dy = a[1] - b[1]
    return dx * dx + dy * dy + dz * dz >= dist * dist


def rough_wall(rng, o, y):
    d, n = o["d"], o["Lxz"]
    return [((ix + 0.5) * d + 0.1 * d * (2 * rng.random() - 1), y + 0.25 * d * (2 * rng.random() - 1),
             (iz + 0.5) * d + 0.1 * d * (2 * rng.random() - 1)) for ix in range(n) for iz in range(n)]


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    out, o = sys.argv[1], options(sys.argv[2:])
    N, d, p, rho = o["N"], o["d"], o["p"], o["rho"]
    E = o["Ep"] * p
    E_eff = E / (2 * (1 - o["nu"] ** 2))
    tp = d * math.sqrt(rho / p)
    gd = o["I"] / tp
    tH = hertz_duration(o, E_eff)
    dt = o["dtfac"] * tH

    rng = random.Random(o["seed"])
    L = o["Lxz"] * d
    area = L * L
    a, b = diameter_range(o)
    diam = [a + (b - a) * rng.random() if o["dist"] == "uniform" else 1.0 / (1.0 / a - rng.random() * (1.0 / a - 1.0 / b))
            for _ in range(N)]
    vol = sum(math.pi * x ** 3 / 6 for x in diam)
    gas = vol / o["phi0"] / area  # the layer the grains fill at phi0
    centres = place_grains(o, rng, diam, L, d, gas)
    y_top = d + gas + d
    atoms = list(zip(diam, centres))
    atoms += [(d, c) for c in rough_wall(rng, o, 0.0)]
    atoms += [(d, c) for c in rough_wall(rng, o, y_top)]
    nwall = o["Lxz"] ** 2

    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "shear.data"), "w") as f:
        f.write("cdlab side-by-side: LIGGGHTS wall shear, N=%d\n\n%d atoms\n1 atom types\n\n" % (N, len(atoms)))
        f.write("0 %.9g xlo xhi\n%.9g %.9g ylo yhi\n0 %.9g zlo zhi\n\nAtoms\n\n" % (L, -2 * d, y_top + 3 * d, L))
        for k, (dd, c) in enumerate(atoms):
            f.write("%d 1 %.9g %.6g %.9g %.9g %.9g\n" % (k + 1, dd, rho * (o["wallrho"] if k >= N else 1.0),
                                                         c[0], c[1], c[2]))

    rmax = o["rmax"]
    H_A = vol / (0.55 * area) + d  # wall gap (centre to centre) when the layer holds phi = 0.55
    steps_A = int(math.ceil(math.log(y_top / H_A) / rmax * tp / dt / 10)) * 10
    steps_B = int(math.ceil(o["tB"] * tp / dt / 10)) * 10
    every = max(10, int(round(o["dgamma"] / (gd * dt) / 10.0)) * 10)  # steps between records
    steps_S = int(math.ceil(o["strain"] / (gd * dt) / every)) * every
    bot = (N + 1, N + nwall)
    top = (N + nwall + 1, N + 2 * nwall)
    # The record interval of (B): every 0.1 t_p, each the mean of every 10th step.
    everyB = max(10, int(round(0.1 * tp / dt / 10.0)) * 10)
    fwall = -p * area / nwall  # added to each top sphere's share of the mean force
    vars_ = dict(o, E=E, tp=tp, gd=gd, dt=dt, tH=tH, fwall=fwall, everyB=everyB, everyB10=everyB // 10,
                 area=area, steps_A=steps_A,
                 steps_B=steps_B, steps_S=steps_S, every=every, every10=every // 10, dump=5 * every,
                 thermo_A=max(10, steps_A // 100 * 10), thermo_B=max(10, steps_B // 200 * 10),
                 thermo_S=5 * every, b0=bot[0], b1=bot[1], t0=top[0], t1=top[1], neigh=o["skin"] * d)
    with open(os.path.join(out, "in.shear"), "w") as f:
        f.write(DECK.format(**vars_))
    with open(os.path.join(out, "params.txt"), "w") as f:
        keys = dict(o, nwall=nwall, E=E, tp=tp, gd=gd, dt=dt, tH=tH, L=L, A=area, steps_A=steps_A,
                    steps_B=steps_B, steps_S=steps_S, every=every)
        f.write(" ".join("%s=%s" % (k, v) for k, v in keys.items()) + "\n")
    print("deck: N=%d + 2 walls of %d, E/p=%g, dt=%.4e s (%.4f t_p, %.3f t_H), gdot=%.5g /s, I=%g, "
          "steps: %d + %d preparation, %d shear" % (N, nwall, o["Ep"], dt, dt / tp, dt / tH, gd, o["I"],
                                                     steps_A, steps_B, steps_S))


DECK = """# cdlab side-by-side: 3D plane shear between rough walls at imposed normal stress (deck.py)
# N={N} I={I} strain={strain} E/p={Ep:g} en={en} mu={mu} nu={nu} ratio={ratio} {dist} seed={seed} walls {Lxz}x{Lxz}
# p={p} Pa d={d} m rho={rho} t_p={tp:.6e} s gdot={gd:.6e} /s dt={dt:.6e} s, top wall density {wallrho} rho
atom_style granular
atom_modify map array
boundary p f p
newton off
communicate single vel yes
units si
soft_particles yes
hard_particles yes
read_data shear.data
group flow id <> 1 {N}
group bot id <> {b0} {b1}
group top id <> {t0} {t1}
neighbor {neigh:.6g} bin
neigh_modify delay 0
fix m1 all property/global youngsModulus peratomtype {E:.9g}
fix m2 all property/global poissonsRatio peratomtype {nu}
fix m3 all property/global coefficientRestitution peratomtypepair 1 {en}
fix m4 all property/global coefficientFriction peratomtypepair 1 {mu}
pair_style gran model hertz tangential history
pair_coeff * *
timestep {dt:.9e}
fix integr flow nve/sphere
fix ts flow check/timestep/gran 10 0.3 0.1
compute rke flow erotate/sphere
compute cpa all contact/atom
compute ncon flow reduce sum c_cpa
compute pgl all pair/gran/local id force_normal force_tangential
variable P equal {p}
variable A equal {area:.9e}
variable tp equal {tp:.9e}
variable rmax equal {rmax}
variable H equal xcm(top,y)-xcm(bot,y)
variable Fyt equal fcm(top,y)
variable Fxt equal fcm(top,x)
variable Fyb equal fcm(bot,y)
variable Fxb equal fcm(bot,x)
variable zf equal c_ncon/{N}
variable V equal 0.0
variable vyt equal -v_rmax*v_H/v_tp
fix mv top move variable NULL NULL NULL v_V v_vyt NULL
thermo_style custom step time ke c_rke v_H v_Fxt v_Fyt v_Fxb v_Fyb v_zf f_ts[1] f_ts[2]
thermo_modify lost error norm no flush yes
thermo {thermo_A}
# (A) the top wall comes down to a layer at phi = 0.55
run {steps_A}
# (B) the top wall a rigid body under -p A: aveforce gives each of its
# spheres the mean force plus its share of -p A (its global vector: the
# grains' force on the wall before that change), setforce then holds v_x
# and v_z; nve moves it.
unfix mv
velocity top set 0.0 0.0 0.0 units box
fix fw top aveforce 0.0 {fwall:.9e} 0.0
fix sw top setforce 0.0 NULL 0.0
fix integt top nve
variable Fyt equal f_fw[2]
variable Fxt equal f_fw[1]
variable pyt equal v_Fyt/(v_P*v_A)
variable pyb equal -v_Fyb/(v_P*v_A)
fix aveB all ave/time 10 {everyB10} {everyB} v_pyt v_pyb v_H file prep_ave.txt
thermo {thermo_B}
run {steps_B}
unfix aveB
print "PREP_DONE H=$(v_H) Fyt/pA=$(v_Fyt/(v_P*v_A)) Fyb/pA=$(v_Fyb/(v_P*v_A)) z=$(v_zf) ke=$(ke)"
# shear
variable tmp equal v_H
variable H0 equal ${{tmp}}
variable tmp equal xcm(bot,y)
variable yb equal ${{tmp}}
variable tmp equal xcm(top,y)
variable yt equal ${{tmp}}
variable tmp equal {gd:.9e}*v_H0
variable Vs equal ${{tmp}}
velocity flow ramp vx 0.0 ${{Vs}} y ${{yb}} ${{yt}} sum yes units box
velocity top set ${{Vs}} NULL 0.0 units box
variable tmp equal step
variable s0 equal ${{tmp}}
variable strain equal (step-v_s0)*dt*v_Vs/v_H0
fix ave all ave/time 10 {every10} {every} v_strain v_Fxt v_Fyt v_Fxb v_Fyb v_H v_zf c_rke file shear_ave.txt
thermo_style custom step time v_strain ke c_rke v_H v_Fxt v_Fyt v_Fxb v_Fyb v_zf f_ts[1] f_ts[2]
thermo {thermo_S}
dump dsh all custom {dump} shear.dump id radius x y z vx vy vz c_cpa
dump_modify dsh sort id
dump dlc all local {dump} shear.contacts c_pgl[1] c_pgl[2] c_pgl[3] c_pgl[4] c_pgl[5] c_pgl[6] c_pgl[7] c_pgl[8] c_pgl[9]
run {steps_S}
print "SHEAR_DONE strain=$(v_strain) H=$(v_H)"
"""

if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""Steady averages of a LIGGGHTS wall-shear run of deck.py.

usage: post.py RUNDIR [g0=S/2] [g1=S] [blocks=5]     (S: the run's strain)
Prints one line of key=value pairs.

mu = sigma_xy / sigma_yy from the wall forces, the two walls averaged
(compression positive; the top wall moves along +x, the grains drag it
back): sigma_yy = (F_y,top - F_y,bot) / 2A, sigma_xy = (F_x,bot - F_x,top)
/ 2A. This is the whole stress (contact and kinetic): at a wall all the
momentum passes through contacts. mu is <sigma_xy> / <sigma_yy> over the
records with strain in [g0, g1]; its error the standard error of the
values of `blocks` equal strain blocks. phi and z: in the bulk, the slab
more than 2.5 d from the wall spheres' mean planes (each grain's volume
inside the slab exactly, as sphere caps), from the dumps in [g0, g1]; z is
LIGGGHTS' contact count per grain there (rattlers included).
"""
import math
import sys

import numpy as np


def cap(r, h):
    """Volume of a sphere of radius r below a plane at height h above its lowest point."""
    h = np.clip(h, 0.0, 2 * r)
    return math.pi * h * h * (3 * r - h) / 3


def frames(path):
    """(step, array of rows id radius x y z vx vy vz contacts) for each dump frame."""
    with open(path) as f:
        blocks = f.read().split("ITEM: TIMESTEP")[1:]
    for b in blocks:
        lines = b.strip().splitlines()
        start = next(k for k, l in enumerate(lines) if l.startswith("ITEM: ATOMS")) + 1
        a = np.array([[float(x) for x in l.split()] for l in lines[start:]])
        yield int(lines[0]), a[np.argsort(a[:, 0])]


def main():
    run = sys.argv[1]
    par = dict(kv.split("=") for kv in open(run + "/params.txt").read().split())
    N, nwall = int(par["N"]), int(par["nwall"])
    A, d, rho, dt = (float(par[k]) for k in ("A", "d", "rho", "dt"))
    S = float(par["strain"])
    opt = {"g0": S / 2, "g1": S, "blocks": 5}
    for a in sys.argv[2:]:
        k, v = a.split("=")
        opt[k] = float(v)
    g0, g1, nb = opt["g0"], opt["g1"], int(opt["blocks"])

    rec = np.loadtxt(run + "/shear_ave.txt", comments="#", ndmin=2)
    step, gam, Fxt, Fyt, Fxb, Fyb = (rec[:, k] for k in range(6))
    syy = (Fyt - Fyb) / (2 * A)
    sxy = (Fxb - Fxt) / (2 * A)
    sel = (gam >= g0) & (gam <= g1)
    if sel.sum() < nb:
        sys.exit("post.py: %d records in the window [%g, %g]: too few" % (sel.sum(), g0, g1))
    mu = sxy[sel].mean() / syy[sel].mean()
    edges = np.linspace(g0, g1, nb + 1)
    mub = []
    for k in range(nb):
        s = (gam >= edges[k]) & ((gam < edges[k + 1]) if k < nb - 1 else (gam <= edges[k + 1]))
        mub.append(sxy[s].mean() / syy[s].mean())
    mu_se = np.std(mub, ddof=1) / math.sqrt(nb)
    p_mean = syy[sel].mean()
    rate = np.polyfit(step, gam, 1)[0] / dt  # the nominal shear rate

    out = open(run + "/out.txt").read()
    shear_steps = int(out.split("SHEAR_DONE")[0].rsplit("Loop time of", 1)[1].split("for")[1].split()[0])

    phis, zs, rates = [], [], []
    s0 = None
    for st, a in frames(run + "/shear.dump"):
        s0 = st if s0 is None else s0
        g = (st - s0) * dt * rate
        if g < g0 - 1e-9 or g > g1 + 1e-9:
            continue
        grains, bot, top = a[:N], a[N:N + nwall], a[N + nwall:N + 2 * nwall]
        lo, hi = bot[:, 3].mean() + 2.5 * d, top[:, 3].mean() - 2.5 * d
        r, y = grains[:, 1], grains[:, 3]
        phis.append((cap(r, hi - (y - r)) - cap(r, lo - (y - r))).sum() / (A * (hi - lo)))
        inside = (y > lo) & (y < hi)
        zs.append(grains[inside, 8].mean())
        rates.append(np.polyfit(y[inside], grains[inside, 5], 1)[0] / rate)
    if not phis:
        sys.exit("post.py: no dump frame in the window [%g, %g]" % (g0, g1))
    # The strain of the whole run (the last record is a mean over its interval).
    strain = shear_steps * dt * rate
    print("code=liggghts I_set=%s Ep=%s strain=%.3f window=%.3g:%.3g steps=%d mu=%.4f mu_se=%.4f phi=%.4f z=%.3f "
          "p=%.4g p_over_set=%.3f bulk_rate=%.3f frames=%d I_nom=%.4g" %
          (par["I"], par["Ep"], strain, g0, g1, shear_steps, mu, mu_se, np.mean(phis), np.mean(zs), p_mean, p_mean / float(par["p"]), np.mean(rates),
           len(phis), rate * d * math.sqrt(rho / p_mean)))


if __name__ == "__main__":
    main()

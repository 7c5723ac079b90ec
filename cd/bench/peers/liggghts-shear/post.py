#!/usr/bin/python3
"""Steady averages of a LIGGGHTS wall-shear run of deck.py.

usage: post.py RUNDIR [g0=S/2] [g1=S] [blocks=5] [cda=CDANALYSIS]    (S: the run's strain)
Prints one line of key=value pairs.

mu = sigma_xy / sigma_yy from the wall forces, the two walls averaged
(compression positive; the top wall moves along +x, the grains drag it
back): sigma_yy = (F_y,top - F_y,bot) / 2A, sigma_xy = (F_x,bot - F_x,top)
/ 2A. This is the whole stress (contact and kinetic): at a wall all the
momentum passes through contacts. mu is <sigma_xy> / <sigma_yy> over the
records with strain in [g0, g1]; its error the standard error of the
values of `blocks` equal strain blocks. phi and z: in the bulk, the slab
more than 2.5 d from the wall spheres' mean planes (each grain's volume
inside the slab exactly, as sphere caps), from the dumps in [g0, g1]; z_raw is
LIGGGHTS' contact count per grain there (rattlers included). With cda (a
cdanalysis binary): z, the coordination of the force-bearing network with
rattlers out, by cdanalysis itself (`fabric`, the estimator of cdsim's own
z column: a contact bears force above 1e-9 of the mean |f_n|, a rattler has
fewer than 2) on the bulk of each frame (snapshots.py), its error the
standard error over the frames. p_prep: the grains' force on the top wall
over the last 10 t_p of the preparation, in units of p A (p_prep_bot: the
bottom wall's). I_bulk: the inertial number of the bulk, from its shear
rate (the slope of v_x against y in the slab) and the mean wall stress.
"""
import os
import re
import subprocess
import math
import sys

import numpy as np

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
from snapshots import frames  # noqa: E402  (LIGGGHTS' dump frames, one reader for both scripts)


def cap(r, h):
    """Volume of a sphere of radius r below a plane at height h above its lowest point."""
    h = np.clip(h, 0.0, 2 * r)
    return math.pi * h * h * (3 * r - h) / 3


def main():
    run = sys.argv[1]
    par = dict(kv.split("=") for kv in open(run + "/params.txt").read().split())
    N, nwall = int(par["N"]), int(par["nwall"])
    A, d, rho, dt = (float(par[k]) for k in ("A", "d", "rho", "dt"))
    S = float(par["strain"])
    opt = {"g0": S / 2, "g1": S, "blocks": 5, "cda": None}
    for a in sys.argv[2:]:
        k, v = a.split("=", 1)
        if k not in opt:
            sys.exit("post.py: unknown option '%s' (g0, g1, blocks, cda)" % a)
        opt[k] = v if k == "cda" else float(v)
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
    if "SHEAR_DONE" not in out:
        sys.exit("post.py: %s/out.txt has no SHEAR_DONE line: the run did not finish" % run)
    shear_steps = int(out.split("SHEAR_DONE")[0].rsplit("Loop time of", 1)[1].split("for")[1].split()[0])

    prep = np.loadtxt(run + "/prep_ave.txt", comments="#", ndmin=2)
    tp = float(par["tp"])
    last = prep[:, 0] > prep[-1, 0] - 10 * tp / dt
    p_prep, p_prep_bot = prep[last, 1].mean(), prep[last, 2].mean()

    phis, zs, rates, window_frames = [], [], [], []
    s0 = None
    for k, (st, rows) in enumerate(frames(run + "/shear.dump", "ATOMS")):
        a = np.array(sorted(rows))  # by id
        s0 = st if s0 is None else s0
        g = (st - s0) * dt * rate
        if g < g0 - 1e-9 or g > g1 + 1e-9:
            continue
        window_frames.append(k)
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
    z_fb = z_fb_se = float("nan")
    if opt["cda"]:
        snap = os.path.join(run, "snapshots")
        subprocess.run([sys.executable, os.path.join(os.path.dirname(os.path.abspath(__file__)), "snapshots.py"),
                        run, snap], check=True)
        zf = []
        for k in window_frames:
            txt = subprocess.run([opt["cda"], "fabric", snap, "--snapshot", str(k)], check=True, text=True,
                                 stdout=subprocess.PIPE).stdout
            zf.append(float(re.search(r"^connect\.\s+z (\S+)", txt, re.M).group(1)))
        z_fb, z_fb_se = np.mean(zf), np.std(zf, ddof=1) / math.sqrt(len(zf)) if len(zf) > 1 else float("nan")
    p_set = float(par["p"])
    I_bulk = np.mean(rates) * rate * d * math.sqrt(rho / p_mean)
    print("code=liggghts I_set=%s Ep=%s seed=%s strain=%.3f window=%.3g:%.3g steps=%d mu=%.4f mu_se=%.4f phi=%.4f "
          "phi_se=%.4f z=%.4f z_se=%.4f z_raw=%.3f p=%.4g p_over_set=%.4f p_prep=%.4f p_prep_bot=%.4f bulk_rate=%.3f "
          "frames=%d I_nom=%.4g I_bulk=%.4g" %
          (par["I"], par["Ep"], par["seed"], strain, g0, g1, shear_steps, mu, mu_se, np.mean(phis),
           np.std(phis, ddof=1) / math.sqrt(len(phis)) if len(phis) > 1 else float("nan"), z_fb, z_fb_se,
           np.mean(zs), p_mean, p_mean / p_set, p_prep, p_prep_bot, np.mean(rates), len(phis),
           rate * d * math.sqrt(rho / p_mean), I_bulk))


if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""The side-by-side table of `make compare-liggghts-shear`: LIGGGHTS' wall
shear (liggghts-shear/run.py) against cdsim's 3D point of the same I
(make campaign-inertial DIM=3 N=1000), from their output folders.

usage: shear_table.py DIR      (DIR/liggghts/result.txt, DIR/cdsim/{prep,inertial/I_*}/)
Prints a Markdown table and writes DIR/table.md.

Both codes are averaged over the second half of their strain, mu as the
ratio of the mean stresses, its error the standard error of 5 equal strain
blocks. cdsim: mu = -(s_xy + s_yx)/2 / s_yy of the contact stress, phi of
the whole cell, z without rattlers (series.csv); LIGGGHTS: the wall
forces, phi in the bulk, z by cdanalysis on the bulk's force-bearing
network without rattlers (the estimator of cdsim's z), and its raw contact
count per grain, rattlers in (post.py). CPU: user +
system seconds of each process (cdsim: summary.toml's cpu_time).
"""
import csv
import glob
import math
import os
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from run_files import scene_value, summary  # noqa: E402


def toml_scene_pressure(path):
    """shear.pressure of a resolved scene.toml."""
    p = scene_value(path, "shear", "pressure")
    if p is None:
        sys.exit("shear_table.py: no shear.pressure in " + path)
    return float(p)


def window_stats(series, P, blocks=5):
    rows = list(csv.DictReader(open(series)))
    g = [float(r["strain"]) for r in rows]
    S = g[-1]
    sel = [r for r, x in zip(rows, g) if x >= S / 2]

    def mu_of(rs):
        sxy = sum(0.5 * (float(r["sxy"]) + float(r["syx"])) for r in rs) / len(rs)
        syy = sum(float(r["syy"]) for r in rs) / len(rs)
        return -sxy / syy

    n = len(sel)
    if n < blocks:
        sys.exit("shear_table.py: %d series rows in the second half of %s: too few" % (n, series))
    parts = [sel[k * n // blocks:(k + 1) * n // blocks] for k in range(blocks)]
    mub = [mu_of(p) for p in parts]
    mean_b = sum(mub) / blocks
    se = math.sqrt(sum((x - mean_b) ** 2 for x in mub) / (blocks - 1) / blocks)
    mean = lambda key: sum(float(r[key]) for r in sel) / n
    return dict(strain=S, mu=mu_of(sel), mu_se=se, phi=mean("packing_fraction"), z=mean("z"),
                syy=mean("syy") / P)


def main():
    top = sys.argv[1]
    lig = dict(kv.split("=", 1) for kv in open(os.path.join(top, "liggghts", "result.txt")).read().split())
    runs = sorted(glob.glob(os.path.join(top, "cdsim", "inertial", "I_*")))
    if len(runs) != 1:
        sys.exit("shear_table.py: expected one cdsim run in %s/cdsim/inertial, found %d" % (top, len(runs)))
    shear = summary(os.path.join(runs[0], "summary.toml"))
    prep = summary(os.path.join(top, "cdsim", "prep", "ns_0", "summary.toml"))
    P = toml_scene_pressure(os.path.join(runs[0], "scene.toml"))
    st = window_stats(os.path.join(runs[0], "series.csv"), P)

    S_l, S_c = float(lig["strain"]), st["strain"]
    cpu_l, cpu_c = float(lig["cpu_shear"]), shear["cpu_time"]
    per_l, per_c = cpu_l / S_l, cpu_c / S_c
    hdr = ("| run | CPU s | CPU s per unit strain | ratio | steps | sweeps a step | mu | phi | z | s_yy/p | "
           "largest overlap |\n|---|---|---|---|---|---|---|---|---|---|---|\n")
    rows = [
        "| LIGGGHTS shear, E/p = %.3g, to gamma = %.2f | %.1f | %.2f | 1 | %s | - | %.3f +- %.3f | %.4f | %.2f "
        "(raw %.2f) | %.3f | - |" % (float(lig["Ep"]), S_l, cpu_l, per_l, lig["steps"], float(lig["mu"]),
                                     float(lig["mu_se"]), float(lig["phi"]), float(lig["z"]), float(lig["z_raw"]),
                                     float(lig["p_over_set"])),
        "| cdsim 3D shear, to gamma = %.2f | %.1f | %.2f | **%.1f** | %d | %.0f (%.1f %% at the cap) | "
        "%.3f +- %.3f | %.4f | %.2f | %.3f | %.2g d |" % (S_c, cpu_c, per_c, per_c / per_l, shear["steps"],
                                                         shear["sweeps_mean"], 100 * shear["cap_share"], st["mu"],
                                                         st["mu_se"], st["phi"], st["z"], st["syy"],
                                                         shear["overlap_max"]),
        "| LIGGGHTS preparation | %.1f | | 1 | | | | | | | |" % float(lig["cpu_prep"]),
        "| cdsim preparation | %.1f | | **%.1f** | %d | %.0f (%.1f %% at the cap) | | | | | %.2g d |" %
        (prep["cpu_time"], prep["cpu_time"] / float(lig["cpu_prep"]), prep["steps"], prep["sweeps_mean"],
         100 * prep["cap_share"], prep["overlap_max"]),
    ]
    load = open("/proc/loadavg").read().split()[:3]
    note = ("\nI = %s, 1000 grains, one thread each, CPU seconds (user + system), mu, phi, z over the second "
            "half of each run; load average at the end %s (1, 5, 15 min); cdsim %s\n" %
            (lig["I_set"] if "I_set" in lig else "?", " ".join(load), shear.get("cdlab_version", "?")))
    table = hdr + "\n".join(rows) + "\n" + note
    with open(os.path.join(top, "table.md"), "w") as f:
        f.write(table)
    print(table)


if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""The table of `make accuracy-shear3`: solver settings of the 3D shear at
imposed p and I, each continued from the same sheared state of several
independent samples, against the first setting (the reference).

usage: accuracy_shear3.py DIR W0 SETTING...
       (DIR/s<seed>/<setting>/{series.csv,summary.toml}, seeds found by glob)
Prints a Markdown table and writes DIR/table.md.

Per run: the means of mu (-(s_xy + s_yx)/2 / s_yy of the contact stress),
phi and z (rattlers removed) over the series rows at continuation strain
>= W0. Per setting: their mean over the samples +- the standard error of
that mean (sample-to-sample scatter / sqrt(n)); the difference to the
reference in units of the combined error sqrt(se_ref^2 + se^2) (the
samples are paired, so this is conservative); CPU seconds (summary.toml's
cpu_time: user + system) per unit strain, sweeps a step, the share of
steps at the cap, the largest overlap (mean diameters) and the largest law
residual of any step.
"""
import csv
import glob
import math
import os
import statistics
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
from run_files import summary


def run(folder, w0):
    rows = list(csv.DictReader(open(os.path.join(folder, "series.csv"))))
    window = [r for r in rows if float(r["strain"]) >= w0]
    if not window:
        sys.exit("accuracy_shear3.py: %s has no series row at strain >= %g" % (folder, w0))
    s = summary(os.path.join(folder, "summary.toml"))
    mean = lambda k: statistics.fmean(float(r[k]) for r in window)
    return {
        "mu": statistics.fmean(-(float(r["sxy"]) + float(r["syx"])) / 2 / float(r["syy"]) for r in window),
        "phi": mean("packing_fraction"),
        "z": mean("z"),
        "cpu": s["cpu_time"] / float(rows[-1]["strain"]),
        "sweeps": s["sweeps_mean"],
        "cap": s["cap_share"],
        "overlap": s["overlap_max"],
        "residual": s["residual_max"],
    }


def mean_se(values):
    m = statistics.fmean(values)
    return m, (statistics.stdev(values) / math.sqrt(len(values)) if len(values) > 1 else float("nan"))


def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    top, w0, settings = sys.argv[1], float(sys.argv[2]), sys.argv[3:]
    seeds = sorted(os.path.basename(p) for p in glob.glob(os.path.join(top, "s*")))
    stats = {}
    for k in settings:
        runs = [run(os.path.join(top, s, k), w0) for s in seeds if os.path.exists(os.path.join(top, s, k, ".done"))]
        if runs:
            stats[k] = runs
    if not stats:
        sys.exit("accuracy_shear3.py: no finished run in " + top)
    ref = settings[0]
    lines = [
        "%d samples (%s); means over continuation strain >= %g; +- the standard error over samples; "
        "(d sigma): the difference to %s in combined errors" % (len(seeds), " ".join(seeds), w0, ref),
        "",
        "| setting | samples | CPU s per unit strain | sweeps a step | at the cap | mu | phi | z | largest overlap (d) | largest law residual |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for k, runs in stats.items():
        cells = []
        for q, fmt in (("mu", "%.4f"), ("phi", "%.4f"), ("z", "%.3f")):
            m, se = mean_se([r[q] for r in runs])
            cell = (fmt + " ± " + fmt) % (m, se)
            if k != ref and ref in stats:
                mr, ser = mean_se([r[q] for r in stats[ref]])
                comb = math.hypot(se, ser)
                if comb > 0:
                    cell += " (%+.1fσ)" % ((m - mr) / comb)
            cells.append(cell)
        lines.append("| %s | %d | %.1f | %.0f | %.1f %% | %s | %.1e | %.2g |" % (
            k, len(runs), statistics.fmean(r["cpu"] for r in runs), statistics.fmean(r["sweeps"] for r in runs),
            100 * statistics.fmean(r["cap"] for r in runs), " | ".join(cells),
            max(r["overlap"] for r in runs), max(r["residual"] for r in runs)))
    text = "\n".join(lines) + "\n"
    sys.stdout.write(text)
    with open(os.path.join(top, "table.md"), "w") as f:
        f.write(text)


if __name__ == "__main__":
    main()

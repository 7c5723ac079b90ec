#!/usr/bin/python3
"""The table and figure of `make compare-liggghts-ladder`: LIGGGHTS at each
contact stiffness beside cdsim's settings, each against cdsim's rigid
reference (make accuracy-shear3).

usage: ladder_table.py DIR REFERENCE.csv [CDSIM_RUN ...]
  DIR/liggghts/I_<I>/Ep_<E/p>/s_<seed>/result.txt   (liggghts-shear/run.py)
  CDSIM_RUN: a make accuracy-shear3 continuation (series.csv, summary.toml)
Prints a Markdown table; writes DIR/table.md, DIR/ladder.csv and
DIR/ladder.svg (CPU per unit strain, and z beside the reference's,
against the contacts' stiffness number, at I = 0.01).

One estimator for both codes: mu the shear over the normal stress (LIGGGHTS:
the walls' forces; cdsim: the contact stress), phi the packing fraction
(LIGGGHTS: the bulk slab 2.5 d from the walls; cdsim: the cell), z the
force-bearing network's coordination with rattlers out, by the code of
cdsim's z column (LIGGGHTS: cdanalysis on the bulk, post.py). A LIGGGHTS
row of several seeds: their mean +- the larger of the standard error over
seeds and the runs' own window errors combined as a mean's (strain blocks
for mu, frames for phi and z); of one: its window's own error. A cdsim
run: its window (continuation strain >= W0 = 0.1 at I = 0.01, 0.05 at
1e-3) in 5 blocks. (d sigma): the difference to the
reference in combined errors, sqrt(se_ref^2 + se^2); the reference's se is
over its five samples. kappa: the stiffness number k / (p d) of a linear
contact, (E/p)^(2/3) for LIGGGHTS' Hertz contacts (the order of the
stiffness of a Hertz contact at the mean force), cdsim's
contact.stiffness_number for compliant contacts, none for rigid ones.
"""
import csv
import glob
import math
import os
import statistics
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from run_files import scene_value, summary  # noqa: E402


def kv_file(path):
    return dict(x.split("=", 1) for x in open(path).read().split())


def blocks_se(values, nb=5):
    n = len(values)
    if n < nb:
        return float("nan")
    means = [statistics.fmean(values[k * n // nb:(k + 1) * n // nb]) for k in range(nb)]
    return statistics.stdev(means) / math.sqrt(nb)


def liggghts_rows(top):
    groups = {}
    for res in glob.glob(os.path.join(top, "liggghts", "I_*", "Ep_*", "s_*", "result.txt")):
        r = kv_file(res)
        groups.setdefault((float(r["I_set"]), float(r["Ep"])), []).append(r)
    rows = []
    for (I, Ep), rs in sorted(groups.items(), key=lambda x: (-x[0][0], x[0][1])):
        row = {"code": "LIGGGHTS", "setting": "E/p = %.0e" % Ep, "I": I, "kappa": Ep ** (2.0 / 3.0),
               "samples": len(rs)}
        for k in ("mu", "phi", "z"):
            vals = [float(r[k]) for r in rs]
            row[k] = statistics.fmean(vals)
            # The runs' own window errors, combined as those of a mean of
            # independent runs; with several seeds, the larger of that and
            # the scatter over seeds (two or three seeds estimate it poorly).
            own = math.sqrt(sum(float(r[k + "_se"]) ** 2 for r in rs)) / len(rs)
            row[k + "_se"] = max(own, statistics.stdev(vals) / math.sqrt(len(vals))) if len(vals) > 1 else own
        for k in ("z_raw", "p_over_set", "p_prep", "I_bulk"):
            row[k] = statistics.fmean(float(r[k]) for r in rs)
        row["cpu"] = statistics.fmean(float(r["cpu_shear"]) / float(r["strain"]) for r in rs)
        row["cpu_prep"] = statistics.fmean(float(r["cpu_prep"]) for r in rs)
        rows.append(row)
    return rows


def cdsim_row(folder):
    rows = list(csv.DictReader(open(os.path.join(folder, "series.csv"))))
    I = float(scene_value(os.path.join(folder, "scene.toml"), "shear", "inertial_number"))
    P = float(scene_value(os.path.join(folder, "scene.toml"), "shear", "pressure"))
    kappa = scene_value(os.path.join(folder, "scene.toml"), "contact", "stiffness_number")
    w0 = 0.1 if I >= 0.01 else 0.05
    win = [r for r in rows if float(r["strain"]) >= w0]
    if len(win) < 5:
        sys.exit("ladder_table.py: %s has %d series rows at strain >= %g" % (folder, len(win), w0))
    s = summary(os.path.join(folder, "summary.toml"))
    sxy = [-(float(r["sxy"]) + float(r["syx"])) / 2 for r in win]
    syy = [float(r["syy"]) for r in win]
    mu_b = [statistics.fmean(sxy[k * len(win) // 5:(k + 1) * len(win) // 5]) /
            statistics.fmean(syy[k * len(win) // 5:(k + 1) * len(win) // 5]) for k in range(5)]
    col = lambda k: [float(r[k]) for r in win]
    kap = float(kappa) if kappa not in (None, "0", "0.0") else float("inf")
    return {"code": "cdsim", "setting": os.path.basename(folder.rstrip("/")), "I": I, "kappa": kap, "samples": 1,
            "mu": statistics.fmean(sxy) / statistics.fmean(syy), "mu_se": statistics.stdev(mu_b) / math.sqrt(5),
            "phi": statistics.fmean(col("packing_fraction")), "phi_se": blocks_se(col("packing_fraction")),
            "z": statistics.fmean(col("z")), "z_se": blocks_se(col("z")), "z_raw": float("nan"),
            "p_over_set": statistics.fmean(syy) / P, "p_prep": float("nan"), "I_bulk": statistics.fmean(
                col("inertial_number")), "cpu": s["cpu_time"] / float(rows[-1]["strain"]),
            "cpu_prep": float("nan"), "sweeps": s["sweeps_mean"], "overlap": s["overlap_max"]}


def sigmas(row, ref):
    out = {}
    for k in ("mu", "phi", "z"):
        e = math.hypot(ref[k + "_se"], row[k + "_se"] if math.isfinite(row[k + "_se"]) else 0.0)
        out[k] = (row[k] - ref[k]) / e
    return out


def svg(rows, ref, path):
    """Two panels against kappa (log), at I = 0.01: CPU per unit strain (log), and z beside the reference's."""
    W, H, m = 640, 520, 60
    pts = [r for r in rows if abs(r["I"] - 0.01) < 1e-12]
    if not pts:
        return
    finite = [r["kappa"] for r in pts if math.isfinite(r["kappa"])]
    x_rigid = max(finite + [1e4]) * 10  # where the rigid settings stand
    xs = [r["kappa"] if math.isfinite(r["kappa"]) else x_rigid for r in pts]
    x0, x1 = math.log10(min(xs)) - 0.3, math.log10(x_rigid) + 0.3
    cpu = [r["cpu"] for r in pts]
    y0, y1 = math.log10(min(cpu)) - 0.2, math.log10(max(cpu)) + 0.2
    ds = [r["z"] for r in pts] + [ref["z"]]
    d0, d1 = min(ds) - 0.05, max(ds) + 0.05
    ph = (H - 3 * m) / 2
    X = lambda x: m + (math.log10(x) - x0) / (x1 - x0) * (W - 2 * m)
    Y1 = lambda y: m + ph - (math.log10(y) - y0) / (y1 - y0) * ph
    Y2 = lambda y: 2 * m + 2 * ph - (y - d0) / (d1 - d0) * ph
    o = ['<svg xmlns="http://www.w3.org/2000/svg" width="%d" height="%d" font-family="sans-serif" font-size="11">'
         % (W, H), '<rect width="100%" height="100%" fill="white"/>']
    for top, label in ((m, "CPU s per unit strain (log)"), (2 * m + ph, "z, force-bearing network without rattlers")):
        o.append('<rect x="%d" y="%d" width="%d" height="%d" fill="none" stroke="black"/>' % (m, top, W - 2 * m, ph))
        o.append('<text x="%d" y="%d">%s</text>' % (m, top - 6, label))
    for e in range(math.ceil(x0), math.floor(x1) + 1):
        if 10 ** e < x_rigid / 3:
            o.append('<text x="%.1f" y="%d" text-anchor="middle">1e%d</text>' % (X(10 ** e), H - m + 16, e))
    o.append('<text x="%.1f" y="%d" text-anchor="middle">rigid</text>' % (X(x_rigid), H - m + 16))
    o.append('<text x="%d" y="%d" text-anchor="middle">stiffness number kappa = k/(p d) (LIGGGHTS: (E/p)^(2/3))'
             '</text>' % (W / 2, H - m + 34))
    for e in range(math.ceil(y0), math.floor(y1) + 1):
        o.append('<text x="%d" y="%.1f" text-anchor="end">%g</text>' % (m - 4, Y1(10 ** e) + 4, 10 ** e))
    for k in range(math.ceil(d0 * 10), math.floor(d1 * 10) + 1):
        if k % 2 == 0:
            o.append('<text x="%d" y="%.1f" text-anchor="end">%.1f</text>' % (m - 4, Y2(k / 10) + 4, k / 10))
    o.append('<line x1="%d" x2="%d" y1="%.1f" y2="%.1f" stroke="black" stroke-dasharray="4,3"/>' %
             (m, W - m, Y2(ref["z"]), Y2(ref["z"])))
    o.append('<text x="%d" y="%.1f">the rigid reference, z = %.3f +- %.3f</text>' %
             (m + 8, Y2(ref["z"]) - 5, ref["z"], ref["z_se"]))
    colour = {"LIGGGHTS": "#c03020", "cdsim": "#2050b0"}
    for code in colour:
        sel = sorted([(x, r) for x, r in zip(xs, pts) if r["code"] == code], key=lambda t: t[0])
        if code == "LIGGGHTS" and len(sel) > 1:
            o.append('<polyline fill="none" stroke="%s" points="%s"/>' %
                     (colour[code], " ".join("%.1f,%.1f" % (X(x), Y1(r["cpu"])) for x, r in sel)))
            o.append('<polyline fill="none" stroke="%s" points="%s"/>' %
                     (colour[code], " ".join("%.1f,%.1f" % (X(x), Y2(r["z"])) for x, r in sel)))
        for x, r in sel:
            for yy in (Y1(r["cpu"]), Y2(r["z"])):
                o.append('<circle cx="%.1f" cy="%.1f" r="4" fill="%s"/>' % (X(x), yy, colour[code]))
            o.append('<text x="%.1f" y="%.1f" fill="%s">%s</text>' % (X(x) + 6, Y1(r["cpu"]) - 6, colour[code],
                                                                      r["setting"]))
    o.append('<text x="%d" y="%d" fill="#c03020">LIGGGHTS (Hertz, walls)</text>' % (m + 8, m + 14))
    o.append('<text x="%d" y="%d" fill="#2050b0">cdsim (Lees-Edwards cell)</text>' % (m + 8, m + 28))
    o.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(o) + "\n")


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    top, ref_csv, cd_runs = sys.argv[1], sys.argv[2], sys.argv[3:]
    refs = {float(r["I"]): {k: float(v) for k, v in r.items() if k not in ("source",)}
            for r in csv.DictReader(open(ref_csv))}
    rows = liggghts_rows(top) + [cdsim_row(d) for d in cd_runs if os.path.exists(os.path.join(d, ".done"))]
    if not rows:
        sys.exit("ladder_table.py: no finished run under " + top)
    fmt_s = lambda r, k, d: "%.4f ± %.4f (%+.1fσ)" % (r[k], r[k + "_se"], d[k]) if k != "mu" else \
        "%.3f ± %.3f (%+.1fσ)" % (r[k], r[k + "_se"], d[k])
    pol = {r["I"]: r["cpu"] for r in rows if r["code"] == "cdsim" and r["setting"] == "policy"}
    out = ["| code | setting | I | κ | samples | μ | φ | z | z raw | σ_yy/p (prep; window) | I bulk | "
           "CPU s per unit strain | ÷ cdsim policy |", "|" + "---|" * 13]
    for r in rows:
        ref = refs.get(r["I"])
        if ref is None:
            continue
        d = sigmas(r, ref)
        r["dz"] = d["z"]
        out.append("| %s | %s | %g | %s | %d | %s | %s | %s | %s | %s | %.4f | %.1f | %s |" % (
            r["code"], r["setting"], r["I"], "%.0f" % r["kappa"] if math.isfinite(r["kappa"]) else "rigid",
            r["samples"], fmt_s(r, "mu", d), fmt_s(r, "phi", d), fmt_s(r, "z", d),
            "%.2f" % r["z_raw"] if math.isfinite(r["z_raw"]) else "—",
            ("%.4f; %.4f" % (r["p_prep"], r["p_over_set"])) if math.isfinite(r["p_prep"]) else "—; %.4f" %
            r["p_over_set"], r["I_bulk"], r["cpu"],
            "%.2f" % (r["cpu"] / pol[r["I"]]) if r["I"] in pol else "—"))
    for I, ref in sorted(refs.items(), reverse=True):
        out.append("| cdsim | the rigid reference | %g | rigid | %d | %.4f ± %.4f | %.4f ± %.4f | %.4f ± %.4f | — | — | "
                   "— | %.1f | %s |" % (I, ref["samples"], ref["mu"], ref["mu_se"], ref["phi"], ref["phi_se"],
                                        ref["z"], ref["z_se"], ref["cpu_per_strain"],
                                        "%.2f" % (ref["cpu_per_strain"] / pol[I]) if I in pol else "—"))
    load = open("/proc/loadavg").read().split()[:3]
    note = ("\n1000 grains, one thread each; σ: combined standard errors against cdsim's rigid reference "
            "(make accuracy-shear3, five samples; its CPU from that measurement, not from these runs); "
            "load average at the end %s\n" % " ".join(load))
    table = "\n".join(out) + "\n" + note
    with open(os.path.join(top, "table.md"), "w") as f:
        f.write(table)
    keys = ["code", "setting", "I", "kappa", "samples", "mu", "mu_se", "phi", "phi_se", "z", "z_se", "z_raw",
            "p_prep", "p_over_set", "I_bulk", "cpu", "cpu_prep"]
    with open(os.path.join(top, "ladder.csv"), "w") as f:
        f.write(",".join(keys) + "\n")
        for r in rows:
            f.write(",".join(str(r.get(k, "")) for k in keys) + "\n")
    if 0.01 in refs:
        svg([r for r in rows if "dz" in r], refs[0.01], os.path.join(top, "ladder.svg"))
    print(table)


if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""LIGGGHTS' frames of a deck.py run as cdsim 3D snapshots of its bulk, so
that `cdanalysis fabric` measures both codes with one estimator (the z,
rattlers and force-bearing threshold of cd/src/core/observables.hpp, the
code behind cdsim's own z column).

usage: snapshots.py RUNDIR OUTDIR
Reads RUNDIR/{params.txt, shear.dump, shear.contacts}; writes
OUTDIR/scene.toml (dimension = 3, what cdanalysis reads of a folder),
OUTDIR/spheres_NNNNN.vtp and OUTDIR/contacts_NNNNN.vtp, one pair per
frame (NNNNN from 0), and OUTDIR/frames.txt (frame index, LIGGGHTS step).

The bulk: the grains whose centre lies more than 2.5 d from both walls'
mean planes (post.py's slab). They are the snapshot's particles; every
contact with at least one of them is a row, the other body (a grain
outside the slab or a wall sphere) standing as a boundary body: it is
never a rattler and a contact with it counts for the bulk grain, as a
wall's does in cdsim (analysis/src/coordination.hpp).

A row: n from body 1 to body 2 (the centres' minimum image in x and z,
the periodic directions), the branch vector l along it, fn = f.n and ft
the rest of f, the force on body 2 (repulsive fn > 0), from LIGGGHTS'
force_normal + force_tangential of the pair (the force on one of the two:
on body 1 when its normal part points against n, and then negated).
Status 0: LIGGGHTS does not tell stick from slip.
"""
import os
import sys

import numpy as np


def frames(path, what):
    """(step, rows) for each frame of a LIGGGHTS text dump (atoms or local entries)."""
    with open(path) as f:
        blocks = f.read().split("ITEM: TIMESTEP")[1:]
    for b in blocks:
        lines = b.strip().splitlines()
        start = next(k for k, l in enumerate(lines) if l.startswith("ITEM: " + what)) + 1
        rows = [[float(x) for x in l.split()] for l in lines[start:]]
        yield int(lines[0]), np.array(rows, ndmin=2) if rows else np.zeros((0, 9))


def ascii_array(name, values, comps=1, kind="Float64"):
    fmt = "%d" if kind.startswith("Int") else "%.17g"
    body = " ".join(fmt % v for v in np.asarray(values).ravel())
    return ('<DataArray type="%s" Name="%s" NumberOfComponents="%d" format="ascii">%s</DataArray>\n' %
            (kind, name, comps, body))


def polydata(points, point_data="", cell_data="", lines=None):
    n_lines = 0 if lines is None else len(lines) // 2  # lines: the two points of each
    out = ['<?xml version="1.0"?>\n<VTKFile type="PolyData" version="0.1" byte_order="LittleEndian">\n<PolyData>\n',
           '<Piece NumberOfPoints="%d" NumberOfVerts="0" NumberOfLines="%d" NumberOfStrips="0" NumberOfPolys="0">\n' %
           (len(points), n_lines),
           "<Points>\n", ascii_array("Points", points, 3), "</Points>\n",
           "<PointData>\n", point_data, "</PointData>\n", "<CellData>\n", cell_data, "</CellData>\n"]
    if lines is not None:
        out += ["<Lines>\n", ascii_array("connectivity", lines, 1, "Int64"),
                ascii_array("offsets", 2 * np.arange(1, n_lines + 1), 1, "Int64"), "</Lines>\n"]
    out.append("</Piece>\n</PolyData>\n</VTKFile>\n")
    return "".join(out)


def write(path, text):
    with open(path + ".tmp", "w") as f:
        f.write(text)
    os.replace(path + ".tmp", path)


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    run, out = sys.argv[1:]
    par = dict(kv.split("=") for kv in open(os.path.join(run, "params.txt")).read().split())
    N, nwall = int(par["N"]), int(par["nwall"])
    d, L = float(par["d"]), float(par["L"])
    os.makedirs(out, exist_ok=True)
    write(os.path.join(out, "scene.toml"), "# LIGGGHTS frames of %s (snapshots.py)\ndimension = 3\n" %
          os.path.abspath(run))
    atoms = frames(os.path.join(run, "shear.dump"), "ATOMS")
    pairs = frames(os.path.join(run, "shear.contacts"), "ENTRIES")
    index = []
    for k, ((st, a), (sc, c)) in enumerate(zip(atoms, pairs)):
        if st != sc:
            sys.exit("snapshots.py: frame %d: the atoms' step %d is not the contacts' %d" % (k, st, sc))
        a = a[np.argsort(a[:, 0])]
        ids = a[:, 0].astype(int)
        if len(ids) != N + 2 * nwall or (ids != np.arange(1, N + 2 * nwall + 1)).any():
            sys.exit("snapshots.py: frame %d (step %d) does not hold atoms 1..%d" % (k, st, N + 2 * nwall))
        x = a[:, 2:5]
        bot, top = x[N:N + nwall, 1].mean(), x[N + nwall:, 1].mean()
        lo, hi = bot + 2.5 * d, top - 2.5 * d
        bulk = np.zeros(N + 2 * nwall + 1, bool)
        bulk[1:N + 1] = (x[:N, 1] > lo) & (x[:N, 1] < hi)
        keep = [i for i in range(N) if bulk[i + 1]]
        pd = ascii_array("id", ids[keep], 1, "Int32") + ascii_array("radius", a[keep, 1]) + \
            ascii_array("velocity", a[keep, 5:8], 3)
        write(os.path.join(out, "spheres_%05d.vtp" % k), polydata(x[keep], point_data=pd))
        i1, i2 = c[:, 0].astype(int), c[:, 1].astype(int)
        rows = bulk[i1] | bulk[i2]
        i1, i2, f = i1[rows], i2[rows], c[rows, 3:6] + c[rows, 6:9]
        l = x[i2 - 1] - x[i1 - 1]
        for ax in (0, 2):
            l[:, ax] -= L * np.round(l[:, ax] / L)
        n = l / np.linalg.norm(l, axis=1)[:, None]
        fnv = c[rows, 3:6]
        on1 = np.einsum("ij,ij->i", fnv, n) < 0
        f[on1] *= -1.0
        fn = np.einsum("ij,ij->i", f, n)
        ft = f - fn[:, None] * n
        p1 = x[i1 - 1]
        pts = np.empty((2 * len(i1), 3))
        pts[0::2], pts[1::2] = p1, p1 + l
        cd = ascii_array("fn", fn) + ascii_array("ft", ft, 3) + ascii_array("normal", n, 3) + \
            ascii_array("branch", l, 3) + ascii_array("status", np.zeros(len(i1)), 1, "Int32") + \
            ascii_array("b1", i1, 1, "Int32") + ascii_array("b2", i2, 1, "Int32")
        write(os.path.join(out, "contacts_%05d.vtp" % k), polydata(pts, cell_data=cd, lines=np.arange(len(pts))))
        index.append("%d %d\n" % (k, st))
    write(os.path.join(out, "frames.txt"), "".join(index))


if __name__ == "__main__":
    main()

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
import math
import os
import sys


def frames(path, what):
    """(step, rows) for each frame of a LIGGGHTS text dump (atoms or local entries)."""
    with open(path) as f:
        blocks = f.read().split("ITEM: TIMESTEP")[1:]
    for b in blocks:
        lines = b.strip().splitlines()
        start = next(k for k, l in enumerate(lines) if l.startswith("ITEM: " + what)) + 1
        yield int(lines[0]), [[float(x) for x in l.split()] for l in lines[start:]]


def ascii_array(name, values, comps=1, kind="Float64"):
    """values: a flat list (comps values a tuple)."""
    fmt = "%d" if kind.startswith("Int") else "%.17g"
    body = " ".join(fmt % v for v in values)
    return ('<DataArray type="%s" Name="%s" NumberOfComponents="%d" format="ascii">%s</DataArray>\n' %
            (kind, name, comps, body))


def polydata(points, point_data="", cell_data="", n_lines=None):
    """points: a flat list of x y z; n_lines: lines of two consecutive points each (None: no cells)."""
    out = ['<?xml version="1.0"?>\n<VTKFile type="PolyData" version="0.1" byte_order="LittleEndian">\n<PolyData>\n',
           '<Piece NumberOfPoints="%d" NumberOfVerts="0" NumberOfLines="%d" NumberOfStrips="0" NumberOfPolys="0">\n' %
           (len(points) // 3, n_lines or 0),
           "<Points>\n", ascii_array("Points", points, 3), "</Points>\n",
           "<PointData>\n", point_data, "</PointData>\n", "<CellData>\n", cell_data, "</CellData>\n"]
    if n_lines is not None:
        out += ["<Lines>\n", ascii_array("connectivity", range(2 * n_lines), 1, "Int64"),
                ascii_array("offsets", range(2, 2 * n_lines + 1, 2), 1, "Int64"), "</Lines>\n"]
    out.append("</Piece>\n</PolyData>\n</VTKFile>\n")
    return "".join(out)


def write(path, text):
    with open(path + ".tmp", "w") as f:
        f.write(text)
    os.replace(path + ".tmp", path)


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


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
        a.sort(key=lambda row: row[0])
        if [int(row[0]) for row in a] != list(range(1, N + 2 * nwall + 1)):
            sys.exit("snapshots.py: frame %d (step %d) does not hold atoms 1..%d" % (k, st, N + 2 * nwall))
        x = [row[2:5] for row in a]  # x[id - 1]
        bot = sum(p[1] for p in x[N:N + nwall]) / nwall
        top = sum(p[1] for p in x[N + nwall:]) / nwall
        lo, hi = bot + 2.5 * d, top - 2.5 * d
        bulk = [False] + [i < N and lo < x[i][1] < hi for i in range(N + 2 * nwall)]  # bulk[id]
        keep = [i for i in range(N) if bulk[i + 1]]
        pd = ascii_array("id", [i + 1 for i in keep], 1, "Int32") + ascii_array("radius", [a[i][1] for i in keep]) + \
            ascii_array("velocity", [v for i in keep for v in a[i][5:8]], 3)
        write(os.path.join(out, "spheres_%05d.vtp" % k), polydata([v for i in keep for v in x[i]], point_data=pd))
        pts, fn, ft, nn, ll, b1, b2 = [], [], [], [], [], [], []
        for row in c:
            i1, i2 = int(row[0]), int(row[1])
            if not (bulk[i1] or bulk[i2]):
                continue
            l = [x[i2 - 1][ax] - x[i1 - 1][ax] for ax in range(3)]
            for ax in (0, 2):
                l[ax] -= L * round(l[ax] / L)
            r = math.sqrt(dot(l, l))
            n = [v / r for v in l]
            f = [row[3 + ax] + row[6 + ax] for ax in range(3)]
            if dot(row[3:6], n) < 0:  # LIGGGHTS gave body 1's force
                f = [-v for v in f]
            g = dot(f, n)
            fn.append(g)
            ft += [f[ax] - g * n[ax] for ax in range(3)]
            nn += n
            ll += l
            b1.append(i1)
            b2.append(i2)
            pts += x[i1 - 1] + [x[i1 - 1][ax] + l[ax] for ax in range(3)]
        cd = ascii_array("fn", fn) + ascii_array("ft", ft, 3) + ascii_array("normal", nn, 3) + \
            ascii_array("branch", ll, 3) + ascii_array("status", [0] * len(fn), 1, "Int32") + \
            ascii_array("b1", b1, 1, "Int32") + ascii_array("b2", b2, 1, "Int32")
        write(os.path.join(out, "contacts_%05d.vtp" % k), polydata(pts, cell_data=cd, n_lines=len(fn)))
        index.append("%d %d\n" % (k, st))
    write(os.path.join(out, "frames.txt"), "".join(index))


if __name__ == "__main__":
    main()

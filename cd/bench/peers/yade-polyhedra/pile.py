# YADE's polyhedra (CGAL) on the scene of configs/pile-polyhedra.toml, for
# make compare-yade-pile (docs/3d.md, "Against YADE"): N cubes of circumscribed diameter
# uniform in [5, 10] mm (side d / sqrt 3), 2600 kg/m^3, at random
# orientations on the lattice n x n x ceil(N / n^2) (n = ceil(N^(1/3)),
# pitch 2.2 r_max, bottom layer at 1.1 r_max, centres jittered by
# +-0.05 r_max) in the square box n pitch wide, g = 9.81, mu = 0.4 on every
# contact, no damping; T seconds of the deposition. The same construction as
# cdsim's, not the same random draws. Environment: N, T, E (the material's
# 'young', see below), DTF, SEED. Prints one line of key=value.
import os, math, time, random
from yade import polyhedra_utils, utils
from yade.wrapper import *
from yade import O, log
# YADE 2023.02a's polyhedra warn "Unhandled switch case:0, function
# do_intersect" about a thousand times a step here (about 300 MB over the
# first 0.12 s of 1000 cubes); errors only.
log.setLevel("Default", log.ERROR)
N = int(os.environ.get('N', '1000')); T = float(os.environ.get('T', '0.12'))
E = float(os.environ.get('E', '1e8')); DTF = float(os.environ.get('DTF', '0.1'))
SEED = int(os.environ.get('SEED', '1'))
rng = random.Random(SEED)
dmin, dmax = 5e-3, 10e-3
rmax = 0.5 * dmax; pitch = 2.2 * rmax
n = int(math.ceil(N ** (1.0 / 3.0) - 1e-9)); L = n * pitch
mat = PolyhedraMat(density=2600.0, young=E, poisson=0.25, frictionAngle=math.atan(0.4))
O.materials.append(mat)
for ax, pos, sense in ((2, 0.0, 1), (0, 0.0, 1), (0, L, -1), (1, 0.0, 1), (1, L, -1)):
    O.bodies.append(utils.wall(pos, axis=ax, sense=sense, material=mat))
def rot(q):  # uniform random rotation matrix from a unit quaternion
    w, x, y, z = q
    return ((1-2*(y*y+z*z), 2*(x*y-w*z), 2*(x*z+w*y)),
            (2*(x*y+w*z), 1-2*(x*x+z*z), 2*(y*z-w*x)),
            (2*(x*z-w*y), 2*(y*z+w*x), 1-2*(x*x+y*y)))
for m in range(N):
    i, j, k = m % n, (m // n) % n, m // (n * n)
    c = ((i + 0.5) * pitch + rng.uniform(-0.05, 0.05) * rmax, (j + 0.5) * pitch + rng.uniform(-0.05, 0.05) * rmax,
         1.1 * rmax + k * pitch + rng.uniform(-0.05, 0.05) * rmax)
    a = rng.uniform(dmin, dmax) / math.sqrt(3.0)
    q = [rng.gauss(0, 1) for _ in range(4)]; s = math.sqrt(sum(v * v for v in q)); q = [v / s for v in q]
    R = rot(q)
    vs = []
    for sx in (-0.5, 0.5):
        for sy in (-0.5, 0.5):
            for sz in (-0.5, 0.5):
                p = (sx * a, sy * a, sz * a)
                vs.append(tuple(c[r] + sum(R[r][t] * p[t] for t in range(3)) for r in range(3)))
    O.bodies.append(polyhedra_utils.polyhedra(mat, v=vs))
depth_max = [0.0]
def sample_depth():  # the deepest overlap now, kept over the run
    for I in O.interactions:
        if I.isReal:
            depth_max[0] = max(depth_max[0], I.geom.equivalentPenetrationDepth)
O.engines = [
    ForceResetter(),
    InsertionSortCollider([Bo1_Polyhedra_Aabb(), Bo1_Wall_Aabb()], verletDist=0.05 * dmin),
    InteractionLoop([Ig2_Wall_Polyhedra_PolyhedraGeom(), Ig2_Polyhedra_Polyhedra_PolyhedraGeom()],
                    [Ip2_PolyhedraMat_PolyhedraMat_PolyhedraPhys()],
                    [Law2_PolyhedraGeom_PolyhedraPhys_Volumetric()]),
    NewtonIntegrator(damping=0.0, gravity=(0, 0, -9.81)),
    PyRunner(command='sample_depth()', iterPeriod=10),
]
# The volumetric law's normal force is kn V (V the overlap's volume, kn = E/2
# between two bodies of 'young' E, in N/m^3): a face contact of area a^2 is a
# spring kn a^2, so the smallest cube (side a_min, mass rho a_min^3) on
# another oscillates at omega^2 = E / (2 rho a_min); the step is DTF times
# the critical 2 / omega.
a_min = dmin / math.sqrt(3.0)
O.dt = DTF * 2.0 * math.sqrt(2.0 * 2600.0 * a_min / E)
steps = int(round(T / O.dt))
t0 = time.process_time()
O.run(steps, True)
cpu = time.process_time() - t0
sample_depth()
nc = sum(1 for I in O.interactions if I.isReal)
d_mean = 0.5 * (dmin + dmax)
print("yade_pile,N=%d,T=%g,E=%g,dt=%.4g,steps=%d,cpu_s=%.2f,contacts=%d,overlap_max=%.3g"
      % (N, T, E, O.dt, steps, cpu, nc, depth_max[0] / d_mean))

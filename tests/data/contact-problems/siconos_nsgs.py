"""Siconos' own NSGS on the frozen 2D problems of this folder: the reference
numbers of tests/test_frozen.cpp (siconos-nsgs.txt beside this script).

    /usr/bin/python3 tests/data/contact-problems/siconos_nsgs.py > tests/data/contact-problems/siconos-nsgs.txt

Needs Debian's python3-siconos (apt-get install --no-install-recommends
python3-siconos). Each problem is read by Siconos' reader
(frictionContact_new_from_filename), its W made dense by NM_to_dense (fc2d
NSGS takes dense storage), and solved by fc2d NSGS from r = 0 at
tol 1e-6 and 1e-8 (at most 100000 sweeps); printed: Siconos' iteration
count and its own error measure (SICONOS_DPARAM_RESIDU) at the end.
"""
import os
import sys

import numpy as np
import siconos.numerics as sn

here = os.path.dirname(os.path.abspath(__file__))
files = sys.argv[1:] or sorted(f for f in os.listdir(here) if f.endswith(".dat"))
print("# file contacts tol info iterations siconos_error")
for f in files:
    read = sn.frictionContact_new_from_filename(os.path.join(here, f))
    n = read.dimension * read.numberOfContacts
    # fc2d's NSGS takes dense storage: Siconos' matrix converted by Siconos.
    W = sn.NumericsMatrix(np.zeros((n, n)))
    sn.NM_to_dense(read.M, W)
    p = sn.FrictionContactProblem(read.dimension, read.numberOfContacts, W, np.array(read.q),
                                  np.array(read.mu))
    for tol in (1e-6, 1e-8):
        opts = sn.SolverOptions(sn.SICONOS_FRICTION_2D_NSGS)
        opts.iparam[sn.SICONOS_IPARAM_MAX_ITER] = 100000
        opts.dparam[sn.SICONOS_DPARAM_TOL] = tol
        r = np.zeros(n)
        v = np.zeros(n)
        info = sn.fc2d_driver(p, r, v, opts)
        print(f"{f} {p.numberOfContacts} {tol:g} {info} {opts.iparam[sn.SICONOS_IPARAM_ITER_DONE]} "
              f"{opts.dparam[sn.SICONOS_DPARAM_RESIDU]:.3e}", flush=True)

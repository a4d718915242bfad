#!/usr/bin/env python3
# bench/bench_elastica.py — the clamped elastica (tests/c1/data/elastica.scene) at a given
# accuracy: calcvar solve --tol T against scipy's solve_bvp on the Euler-Lagrange
# equation, in the same run. Each run's true max error is measured against the shooting
# reference of tests/c1/elastica_ref.py; for each T, solve_bvp's fastest run that is at
# least as accurate as calcvar's is compared with calcvar's time (ratio = bvp / calcvar).
# Times: calcvar's solve time (JSON time_s, best of 5, without parsing and process
# start), solve_bvp's call (best of 3). Not a test: run it by hand with a Python that
# has scipy (Debian python3-scipy: /usr/bin/python3 bench/bench_elastica.py build/src/cli/calcvar).
#
# solve_bvp gets what it needs and calcvar does not: the Euler-Lagrange equation derived
# by hand and reduced to first order — the first integral F_y' - d/dx F_y'' = C, so
# (y, y', y'') with y''' = (5 p q^2 / w - C w^(5/2)) / 2 and the unknown parameter C —
# and a start (the cubic x^3 - x^2/2 through the end conditions, C = -12).
# SPDX-License-Identifier: MIT
import json
import os
import subprocess
import sys
import time

import numpy as np
from scipy.integrate import solve_bvp

root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(root, "tests", "c1"))
import elastica_ref  # noqa: E402

calcvar = os.path.abspath(sys.argv[1]) if len(sys.argv) > 1 else "calcvar"
scene = os.path.join(root, "tests", "c1", "data", "elastica.scene")
xs = [k / 400 for k in range(401)]
ref, ref_err = elastica_ref.reference(xs, 3000)
ref = np.array(ref)
print("reference: shooting, own error %.1e" % ref_err)


def calcvar_run(T):
    best = None
    for _ in range(5):
        r = subprocess.run([calcvar, "solve", scene, "--tol", "%g" % T, "--json", "-", "--quiet"],
                           capture_output=True, text=True, check=True)
        j = json.loads(r.stdout)
        best = j if best is None or j["time_s"] < best["time_s"] else best
    r = subprocess.run([calcvar, "solve", scene, "--tol", "%g" % T, "--csv", "-", "--quiet"],
                       capture_output=True, text=True, check=True)
    rows = [tuple(map(float, line.split(",")[:2])) for line in r.stdout.split()[1:]]
    x, y = np.array(rows).T
    true = np.max(np.abs(y - np.array(elastica_ref.reference(list(x), 3000)[0])))
    return best["time_s"], true, best["elements"], best["degree"]


def bvp_run(tol):
    def f(x, Y, p):
        w = 1 + Y[1] ** 2
        return np.vstack((Y[1], Y[2], 0.5 * (5 * Y[1] * Y[2] ** 2 / w - p[0] * w ** 2.5)))

    def bc(ya, yb, p):
        return np.array([ya[0], ya[1], yb[0] - 0.5, yb[1] - 2.0])

    x0 = np.linspace(0, 1, 11)
    Y0 = np.vstack((x0 ** 3 - x0 ** 2 / 2, 3 * x0 ** 2 - x0, 6 * x0 - 1))
    best, sol = None, None
    for _ in range(3):
        t0 = time.perf_counter()
        s = solve_bvp(f, bc, x0, Y0, p=[-12.0], tol=tol, max_nodes=1000000)
        t = time.perf_counter() - t0
        if best is None or t < best:
            best, sol = t, s
    if not sol.success:
        return best, np.inf
    return best, np.max(np.abs(sol.sol(np.array(xs))[0] - ref))


bvp = []
for e in np.arange(3, 11.5, 0.5):  # below 1e-11 it fails after 13-25 s each
    t, err = bvp_run(10.0 ** -e)
    bvp.append((t, err))
    print("solve_bvp tol 1e-%.1f: %.3e s, true error %.2e" % (e, t, err))
print("\n%8s %10s %10s %8s %10s %10s %8s" % ("tol", "calcvar_s", "true_err", "mesh", "bvp_s",
                                             "bvp_err", "ratio"))
for T in (1e-4, 1e-6, 1e-8, 1e-10):
    tc, ec, E, p = calcvar_run(T)
    ok = [(t, err) for t, err in bvp if err <= ec]
    tb, eb = min(ok) if ok else (np.inf, np.inf)
    print("%8.0e %10.3e %10.2e %8s %10.3e %10.2e %8.1f" % (T, tc, ec, "%dx%d" % (E, p), tb, eb,
                                                          tb / tc))

#!/usr/bin/env python3
# tests/deflation/test_all_systematic.py — `--all` searches systematically and says how far
# it got (issue 29, item 6; theory DF-6): perturbations of several amplitudes (1/16 to 3/2
# of a path's size) along its soft modes and along harmonics of each unknown, and a stop
# sentence that counts the starts tried against those planned, never "every start was
# tried".
# SPDX-License-Identifier: MIT
#
# usage: test_all_systematic.py CALCVAR DATA
#
# - catenoids at 0.99, 0.995 and 0.999 of the fold, default flags: both paths (before: one,
#   from h = 0.66 on), each against its root c of c cosh(h/c) = 1 (bisection here): the
#   value at x = 0 is c to 10 x its estimate (+1e-6), Morse indices 0 and 1;
# - the double pendulum over [0, 3] (ends (0.5, 0.2) and (0.3, -0.4)) on 40 elements of
#   degree 4 with --work 100: at least 10 paths, each verified independently as a
#   trajectory: over windows of 8 elements the Euler-Lagrange flow (RK4, written here) from
#   the path's state at the window's start follows the path within 2e-2 (a control bent by
#   0.05 sin(pi t/3) must fail); the paths' initial velocities are pairwise distinct;
# - no stop sentence says "every start was tried".
import csv
import json
import math
import os
import subprocess
import sys
import tempfile

calcvar, data = [os.path.abspath(a) for a in sys.argv[1:3]]
failures = 0
checks = 0
FOLD = 0.6627434193491815


def check(what, ok, detail=""):
    global failures, checks
    checks += 1
    if not ok:
        failures += 1
        print("FAIL %s %s" % (what, detail))


def run_all(scene, *flags):
    with tempfile.TemporaryDirectory() as tmp:
        c = os.path.join(tmp, "all.csv")
        r = subprocess.run([calcvar, "solve", os.path.join(data, scene), "--all", "--json", "-",
                            "--csv", c] + list(flags), capture_output=True, text=True,
                           timeout=300)
        check("%s %s sanitizers" % (scene, flags), "Sanitizer" not in r.stderr and
              "runtime error:" not in r.stderr, r.stderr[:2000])
        check("%s %s exit 0" % (scene, flags), r.returncode == 0, r.stderr[:300])
        if r.returncode != 0:
            return None, []
        rows = list(csv.reader(open(c)))
        return json.loads(r.stdout), rows


def bisect(f, a, b, n=200):
    fa = f(a)
    for _ in range(n):
        m = 0.5 * (a + b)
        fm = f(m)
        if (fa < 0) == (fm < 0):
            a, fa = m, fm
        else:
            b = m
    return 0.5 * (a + b)


# ---- catenoids near the fold
for frac in (0.99, 0.995, 0.999):
    h = FOLD * frac
    f = lambda c: c * math.cosh(h / c) - 1.0
    cstar = bisect(lambda c: math.cosh(h / c) - (h / c) * math.sinh(h / c), 0.3, 0.99)
    roots = sorted([bisect(f, 0.05, cstar), bisect(f, cstar, 1.0)])
    out, rows = run_all("catenoid_fold.scene", "--set", "h=%.17g" % h)
    what = "catenoid at %g of the fold" % frac
    if not out:
        continue
    sols = out["solutions"]
    check(what + ": two paths", len(sols) == 2, "%d: %s" % (len(sols), out.get("search")))
    check(what + ": not 'every start was tried'",
          "every start" not in out["search"].get("stopped", ""), out["search"])
    mids = []
    for k, sol in enumerate(sols):
        mine = [(float(w[1]), float(w[2])) for w in rows[1:] if w[0] == str(k + 1)]
        x0 = min(mine, key=lambda p: abs(p[0]))
        mids.append((x0[1], sol.get("error_estimate", 1e-3), sol.get("morse_index")))
    mids.sort()
    for (y0, est, morse), c, m in zip(mids, roots, (1, 0)):  # the smaller c is the saddle
        check(what + ": y(0) = c = %.6f" % c, abs(y0 - c) <= 10 * est + 1e-6,
              "y(0) %.8f, estimate %.2g" % (y0, est))
        check(what + ": Morse index %d for c = %.4f" % (m, c), morse == m, morse)


# ---- the double pendulum: >= 10 paths, each verified by shooting
G = 9.81


def rhs(u):
    a, b, va, vb = u
    c, s = math.cos(a - b), math.sin(a - b)
    r1 = -s * vb * vb - 2.0 * G * math.sin(a)
    r2 = s * va * va - G * math.sin(b)
    det = 2.0 - c * c
    return (va, vb, (r1 - c * r2) / det, (2.0 * r2 - c * r1) / det)


def flow(a, b, va, vb, dt, n=100):
    """RK4 for time dt from the state (a, b, a', b'); the final (a, b)."""
    h, u = dt / n, (a, b, va, vb)
    for _ in range(n):
        k1 = rhs(u)
        k2 = rhs(tuple(u[i] + 0.5 * h * k1[i] for i in range(4)))
        k3 = rhs(tuple(u[i] + 0.5 * h * k2[i] for i in range(4)))
        k4 = rhs(tuple(u[i] + h * k3[i] for i in range(4)))
        u = tuple(u[i] + h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]) for i in range(4))
    return u[0], u[1]


def slope_at_start(ts, vs):
    """The derivative at ts[0] of the polynomial through (ts, vs) (one element's nodes)."""
    d = 0.0
    for i in range(len(ts)):
        for m in range(len(ts)):
            if m == i:
                continue
            prod = 1.0 / (ts[i] - ts[m])
            for l in range(len(ts)):
                if l != i and l != m:
                    prod *= (ts[0] - ts[l]) / (ts[i] - ts[l])
            d += vs[i] * prod
    return d


# A path is verified as a trajectory window by window (multiple shooting: a global shot over
# [0, 3] is too ill-conditioned for the fast-rotating paths): from the state at the start of
# each window of W elements (the path's values and its first element's polynomial slope),
# the Euler-Lagrange flow (RK4) must follow the path to TOL at every element boundary of
# the window. The slope at an element's end node is the least accurate part of the
# discrete path (measured: defects 1e-4 .. 6.5e-3 over one element); a control perturbs
# path 1 by 0.05 sin(pi t / 3) in both angles, which is no trajectory, and must fail.
P, W, TOL = 4, 8, 2e-2


def window_defect(mine):
    defect = 0.0
    for e in range(0, len(mine) - 1, P * W):
        el = mine[e:e + P + 1]
        ts = [m[0] for m in el]
        a, b = el[0][1], el[0][2]
        va = slope_at_start(ts, [m[1] for m in el])
        vb = slope_at_start(ts, [m[2] for m in el])
        u = (a, b, va, vb)
        for k in range(e, min(e + P * W, len(mine) - 1), P):
            dt = mine[k + P][0] - mine[k][0]
            u = flow_state(u, dt)
            defect = max(defect, abs(u[0] - mine[k + P][1]), abs(u[1] - mine[k + P][2]))
    return defect, (va, vb)


def flow_state(u, dt, n=100):
    h = dt / n
    for _ in range(n):
        k1 = rhs(u)
        k2 = rhs(tuple(u[i] + 0.5 * h * k1[i] for i in range(4)))
        k3 = rhs(tuple(u[i] + 0.5 * h * k2[i] for i in range(4)))
        k4 = rhs(tuple(u[i] + h * k3[i] for i in range(4)))
        u = tuple(u[i] + h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]) for i in range(4))
    return u


out, rows = run_all("double_pendulum_T.scene", "--set", "T=3", "--elements", "40", "--degree",
                    "4", "--work", "100", "--max", "40")
if out:
    sols = out["solutions"]
    check("double pendulum: at least 10 paths", len(sols) >= 10, "%d: %s" %
          (len(sols), out.get("search")))
    check("double pendulum: not 'every start was tried'",
          "every start" not in out["search"].get("stopped", ""), out["search"])
    starts = []
    verified = 0
    for k, sol in enumerate(sols):
        mine = [(float(w[1]), float(w[2]), float(w[3])) for w in rows[1:] if w[0] == str(k + 1)]
        what = "double pendulum path %d (Morse index %s)" % (k + 1, sol.get("morse_index"))
        ts = [m[0] for m in mine[:P + 1]]
        starts.append((slope_at_start(ts, [m[1] for m in mine[:P + 1]]),
                       slope_at_start(ts, [m[2] for m in mine[:P + 1]])))
        defect, _ = window_defect(mine)
        check(what + ": a trajectory (window defect <= %g)" % TOL, defect <= TOL, defect)
        verified += defect <= TOL
        if k == 0:
            bent = [(m[0], m[1] + 0.05 * math.sin(math.pi * m[0] / 3.0),
                     m[2] + 0.05 * math.sin(math.pi * m[0] / 3.0)) for m in mine]
            d2, _ = window_defect(bent)
            check("control: path 1 bent by 0.05 sin(pi t/3) is no trajectory", d2 > TOL, d2)
    for i in range(len(starts)):
        for j in range(i):
            check("double pendulum paths %d and %d: distinct initial velocities" % (j + 1, i + 1),
                  max(abs(starts[i][0] - starts[j][0]), abs(starts[i][1] - starts[j][1])) > 1e-3,
                  (starts[i], starts[j]))
    print("double pendulum: %d paths, %d verified as trajectories" % (len(sols), verified))

print("%d checks, %d failures" % (checks, failures))
sys.exit(1 if failures else 0)

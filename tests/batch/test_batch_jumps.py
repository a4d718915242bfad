#!/usr/bin/env python3
# tests/batch/test_batch_jumps.py — a batch row of a scene whose integrand jumps in y is
# solved as `calcvar solve` solves it (theory HC-4): the jumps smoothed over a width the mesh
# resolves, the answer said to be the smoothed problem's, and --tol refusing to claim an
# estimate it cannot make. Before, batch compiled the integrand without the smoothing: the
# plain row failed (no_progress) where solve converged, and the --tol row said "converged"
# with an estimate of 3.4e-9 on an action 0.29 above the true one.
# The scene: a ray from (0, 0) to (2, 1) through n = 1 below y = 1/2 and n = n2 above; the
# exact optical path is min over a of sqrt(a^2 + 1/4) + n2 sqrt((2 - a)^2 + 1/4) (Snell at
# the interface), found here by bisection on its derivative.
# Usage: test_batch_jumps.py CALCVAR
# SPDX-License-Identifier: MIT
import csv
import io
import json
import math
import os
import subprocess
import sys
import tempfile

calcvar = sys.argv[1]
fails = 0


def check(what, ok, detail=""):
    global fails
    if not ok:
        fails += 1
        print("FAIL", what, detail)


def exact(n2):
    f = lambda a: a / math.hypot(a, 0.5) - n2 * (2 - a) / math.hypot(2 - a, 0.5)
    lo, hi = 0.0, 2.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if f(mid) < 0 else (lo, mid)
    a = 0.5 * (lo + hi)
    return math.hypot(a, 0.5) + n2 * math.hypot(2 - a, 0.5)


SCENE = """[scene]
interval  = 0, 2
unknowns  = y
integrand = n * sqrt(1 + y'^2)
[parameters]
n2 = 1.5
[definitions]
n = if(y < 0.5, 1, n2)
[boundary]
y = 0, 1
"""
with tempfile.TemporaryDirectory() as tmp:
    sc, tb = os.path.join(tmp, "jump.scene"), os.path.join(tmp, "t.csv")
    open(sc, "w").write(SCENE)
    open(tb, "w").write("n2\n1.5\n1.25\n")
    for opts in ([], ["--tol", "1e-8"]):
        p = subprocess.run([calcvar, "batch", sc, tb, *opts], capture_output=True, text=True)
        rows = list(csv.DictReader(io.StringIO(p.stdout)))
        check("batch %s rows" % opts, len(rows) == 2, p.stdout + p.stderr)
        for row in rows:
            q = subprocess.run([calcvar, "solve", sc, "--set", "n2=" + row["n2"], *opts, "--json",
                                "-"], capture_output=True, text=True)
            r = json.loads(q.stdout)
            check("row n2=%s %s status as solve's" % (row["n2"], opts),
                  row["status"] == r["status"], (row["status"], r["status"], row["message"]))
            if r["status"] == "converged":
                A = float(row["action"])
                check("row n2=%s action as solve's" % row["n2"], abs(A - r["action"]) <= 1e-12,
                      (A, r["action"]))
                # the smoothed problem's action: within its stated first-order offset (< 2e-3)
                check("row n2=%s action near the sharp one" % row["n2"],
                      0 <= A - exact(float(row["n2"])) <= 2e-3, (A, exact(float(row["n2"]))))
                check("row n2=%s says it smoothed" % row["n2"], "smoothed" in row["message"],
                      row["message"])
            else:  # --tol: no estimate claimed for a smoothed answer
                check("row n2=%s %s no estimate" % (row["n2"], opts),
                      row["error_estimate"] == "" and "smoothed" in row["message"], row)
print("%d failures" % fails)
sys.exit(1 if fails else 0)

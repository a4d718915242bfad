#!/usr/bin/env python3
# bench/bench_obstacles.py — the active-set iteration of docs/obstacles.md against mesh size:
# Newton iterations and time per iteration on the bump (y >= 1 - x^2) and the unit disk
# (x^2 + y^2 >= 1) from (-2, 0) to (2, 0), degree 1, 10^2 .. 10^5 elements, beside the same
# scene without the constraint (its answer the straight line, from the same guess), in the
# same run. Times: the solve's own time (JSON time_s), best of 3; per iteration = time /
# iterations (setup included, so the unconstrained run's few iterations carry its whole
# setup). Not a test: /usr/bin/python3 bench/bench_obstacles.py build/src/cli/calcvar [Emax]
# SPDX-License-Identifier: MIT
import json
import os
import subprocess
import sys
import tempfile

calcvar = os.path.abspath(sys.argv[1]) if len(sys.argv) > 1 else "calcvar"
emax = int(sys.argv[2]) if len(sys.argv) > 2 else 100000

SCENE = """[scene]
interval  = -2, 2
unknowns  = y
integrand = sqrt(1 + y'^2)
[boundary]
y = 0, 0
%s
[guess]
y = 1.5*(1 - x^2/4)
"""
CASES = (("free", ""), ("bump", "[constraints]\nover = y - (1 - x^2) >= 0"),
         ("disk", "[constraints]\naround = x^2 + y^2 - 1 >= 0"))


def solve(text, E):
    with tempfile.NamedTemporaryFile("w", suffix=".scene", delete=False) as f:
        f.write(text)
    try:
        best = None
        for _ in range(3):
            p = subprocess.run([calcvar, "solve", f.name, "--elements", str(E), "--degree", "1",
                                "--json", "-"], capture_output=True, text=True)
            r = json.loads(p.stdout)
            if r["status"] != "converged":
                return r["status"], r["iterations"], float("nan")
            if best is None or r["time_s"] < best:
                best = r["time_s"]
        return "converged", r["iterations"], best
    finally:
        os.unlink(f.name)


print("%8s  %-5s %6s %10s %12s %8s" % ("elements", "case", "its", "time_ms", "ms_per_it",
                                        "vs_free"))
E = 100
while E <= emax:
    free = None
    for name, cons in CASES:
        st, its, t = solve(SCENE % cons, E)
        per = 1e3 * t / its if its else float("nan")
        if name == "free":
            free = per
        print("%8d  %-5s %6d %10.2f %12.4f %8.2f%s" % (E, name, its, 1e3 * t, per, per / free,
                                                        "" if st == "converged" else "  " + st))
    E *= 10

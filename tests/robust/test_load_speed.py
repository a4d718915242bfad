#!/usr/bin/env python3
# tests/robust/test_load_speed.py — large scenes load in linear time (issue 27, item 5).
# SPDX-License-Identifier: MIT
#
# Before: 10^5 parameters (1.5 MB) took 60 s to load, 10^5 definitions that name one
# definition did not finish in 120 s, a chain of 8000 definitions took 4-8 s (every name
# compared with every earlier one, a "did you mean" distance computed for names that
# resolved, a walk over the whole DAG per parsed value). The aim is under 1 s for any
# scene under the 4 MiB cap; here each run gets a generous wall-clock cap of 20 s, which a
# quadratic loader misses by far (it took 50-120 s on these scenes) while a shared, slow
# or sanitised build keeps well inside it. Speed itself is measured in bench/, not here.
# Each scene's answer is checked against its exact action too.
#
# usage: test_load_speed.py CALCVAR
import json
import os
import subprocess
import sys
import tempfile
import time

calcvar = os.path.abspath(sys.argv[1])
N = 100000
CAP = 20.0
failures = 0

HEAD = """[scene]
title = big
interval = 0, 1
unknowns = y
integrand = y'^2 + %s*y
[boundary]
y = 0, 1
[mesh]
elements = 2
degree = 4
"""
# y'^2 + c y with y(0) = 0, y(1) = 1: y = c x^2/4 + (1 - c/4) x, and the action is
# the integral of (c x/2 + 1 - c/4)^2 + c (c x^2/4 + (1 - c/4) x), 1 + c/2 - c^2/48.


def action(c):
    return 1 + c / 2 - c * c / 48


def scenes():
    """(name, text, c, table header, table row): each with about 10^5 names."""
    params = "\n".join("p%d = 1e-5" % i for i in range(N))
    yield ("1e5 parameters and 1e5 references",
           HEAD % "e" + "[parameters]\n" + params + "\n[definitions]\ne = " +
           " + ".join("p%d" % i for i in range(N)) + "\n", 1.0, "p7", "1e-5")
    yield ("1e5 definitions naming one definition",
           HEAD % "q99999" + "[parameters]\na = 0.5\n[definitions]\nd = a\n" +
           "\n".join("q%d = d" % i for i in range(N)) + "\n", 0.5, "a", "0.5")
    yield ("a chain of 1e5 definitions",
           HEAD % "d99999" + "[parameters]\na = 1\n[definitions]\nd0 = a - 99999\n" +
           "\n".join("d%d = d%d + 1" % (i, i - 1) for i in range(1, N)) + "\n", 1.0, "a", "1")
    yield ("1e5 parameters in a chain",
           HEAD % "p99999" + "[parameters]\np0 = 2 - 99999\n" +
           "\n".join("p%d = p%d + 1" % (i, i - 1) for i in range(1, N)) + "\n", 2.0, "p0",
           str(2 - 99999))


def timed(args):
    t0 = time.monotonic()
    try:
        r = subprocess.run([calcvar] + args, capture_output=True, timeout=3 * CAP)
    except subprocess.TimeoutExpired:
        return None, 3 * CAP
    return r, time.monotonic() - t0


def main():
    global failures
    with tempfile.TemporaryDirectory() as tmp:
        for name, text, c, col, val in scenes():
            path = os.path.join(tmp, "big.scene")
            with open(path, "w") as f:
                f.write(text)
            assert len(text) < 4 << 20, name
            table = os.path.join(tmp, "t.csv")
            with open(table, "w") as f:
                f.write("%s\n%s\n" % (col, val))
            for what, args in (("solve", ["solve", path, "--json", "-", "--quiet"]),
                               ("batch", ["batch", path, table])):
                r, dt = timed(args)
                label = "%s (%d bytes), %s" % (name, len(text), what)
                if r is None or dt > CAP:
                    failures += 1
                    print("FAIL %s: %.1f s (cap %.0f s)" % (label, dt, CAP))
                    continue
                if r.returncode != 0:
                    failures += 1
                    print("FAIL %s: exit %d: %s" % (label, r.returncode, r.stderr.decode()[:300]))
                    continue
                if what == "solve":
                    got = json.loads(r.stdout)["action"]
                else:
                    lines = r.stdout.decode().splitlines()
                    head = lines[0].split(",")
                    got = float(lines[1].split(",")[head.index("action")])
                err = abs(got - action(c))
                ok = err < 1e-9
                failures += not ok
                print("%s %s: %.2f s, action %.15g, exact %.15g (error %.1e, tolerance 1e-9)" %
                      ("ok  " if ok else "FAIL", label, dt, got, action(c), err))
    print("%d failure(s)" % failures)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())

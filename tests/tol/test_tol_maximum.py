#!/usr/bin/env python3
# tests/tol/test_tol_maximum.py — a maximum of the action gets an error estimate and `--tol`
# works on it (issue 29, item 2): the enriched solve of a maximum has more free directions,
# so its Morse index is larger, and that is no other path (theory HP-3: the co-index).
# SPDX-License-Identifier: MIT
#
# usage: test_tol_maximum.py CALCVAR TOL_DATA
#
# - the minimal case, verbatim on standard input: exit 0, converged, a maximum,
#   the estimate <= T; against the exact y = sinh(x)/sinh(1), action -coth(1): true nodal
#   error <= 10 T and the estimate >= 0.1 x the true error;
# - a plain solve of it reports an error estimate, honest against the exact answer;
# - Dido's problem (largest area for a given length, an integral constraint): the same.
import json
import math
import os
import subprocess
import sys

calcvar, tdata = [os.path.abspath(a) for a in sys.argv[1:3]]
failures = 0
checks = 0
MINIMAL = "[scene]\ninterval = 0, 1\nunknowns = y\nintegrand = -(y'^2 + y^2)\n[boundary]\ny = 0, 1\n"


def check(what, ok, detail=""):
    global failures, checks
    checks += 1
    if not ok:
        failures += 1
        print("FAIL %s %s" % (what, detail))


def solve(path, *flags, stdin=None):
    r = subprocess.run([calcvar, "solve", path, "--json", "-"] + list(flags), input=stdin,
                       capture_output=True, text=True, timeout=120)
    check("%s %s sanitizers" % (path, flags), "Sanitizer" not in r.stderr and
          "runtime error:" not in r.stderr, r.stderr[:2000])
    try:
        return r, json.loads(r.stdout)
    except ValueError:
        check("%s %s JSON parses" % (path, flags), False, r.stdout[:200] + r.stderr[:400])
        return r, {}


def node_error(d, exact):
    return max(abs(y - exact(x)) for x, y in zip(d["x"], d["y"]["y"]))


def check_maximum(what, r, d, T, exact, action):
    check(what + " exit 0", r.returncode == 0, r.stderr[:300])
    if not d:
        return
    check(what + " converged", d.get("status") == "converged", d.get("message", ""))
    check(what + " a maximum", d.get("stationary_kind") == "maximum", d.get("message", ""))
    est = d.get("error_estimate")
    check(what + " has an error estimate", est is not None, d.get("message", ""))
    if est is None or "x" not in d:
        return
    err = node_error(d, exact)
    if T is not None:
        check(what + " estimate <= T", est <= T, "%g" % est)
        check(what + " true error <= 10 T", err <= 10 * T, "%g" % err)
    check(what + " estimate >= 0.1 x true error", est >= 0.1 * err, "%g vs %g" % (est, err))
    check(what + " action", abs(d["action"] - action) <= 1e-9 * abs(action) + (T or 1e-6),
          "%.15g vs %.15g" % (d["action"], action))


sinh1 = math.sinh(1.0)
minimal_y = lambda x: math.sinh(x) / sinh1
for T in (1e-6, 1e-8, 1e-10):
    r, d = solve("-", "--tol", "%g" % T, stdin=MINIMAL)
    check_maximum("minimal maximum --tol %g" % T, r, d, T, minimal_y, -1.0 / math.tanh(1.0))
r, d = solve("-", stdin=MINIMAL)
check_maximum("minimal maximum, plain solve", r, d, None, minimal_y, -1.0 / math.tanh(1.0))
# the sign flipped: a minimum, as before
r, d = solve("-", "--tol", "1e-8", stdin=MINIMAL.replace("-(y'^2 + y^2)", "y'^2 + y^2"))
check("minimal minimum --tol 1e-8 converged", r.returncode == 0 and
      d.get("stationary_kind") == "minimum", r.stderr[:300])

dido = os.path.join(tdata, "dido_maximum.scene")
dido_y = lambda x: math.sqrt(4.0 - x * x) - math.sqrt(3.0)
dido_area = 2.0 * (math.pi / 3.0 - math.sin(math.pi / 3.0))
for T in (1e-6, 1e-8, 1e-10):
    r, d = solve(dido, "--tol", "%g" % T)
    check_maximum("Dido --tol %g" % T, r, d, T, dido_y, dido_area)

print("%d checks, %d failures" % (checks, failures))
sys.exit(1 if failures else 0)

#!/usr/bin/env python3
# tests/robust/test_cli_robust.py — issue 7 through the command: adaptivity, singular ends,
# continuation, no solution, hostile input; every run bounded in time (no hang).
# Usage: test_cli_robust.py CALCVAR SHARED_DATA_DIR ROBUST_DATA_DIR
# SPDX-License-Identifier: MIT
import json
import math
import os
import subprocess
import sys

calcvar, data, rdata = sys.argv[1], sys.argv[2], sys.argv[3]
failures = 0
checks = 0


def check(what, ok, expected, actual):
    global failures, checks
    checks += 1
    if not ok:
        failures += 1
        print("FAIL %s\n  expected: %s\n  actual:   %s" % (what, expected, actual))


def run(scene, *flags, timeout=60):
    r = subprocess.run([calcvar, "solve", scene, "--json", "-"] + list(flags),
                       capture_output=True, text=True, timeout=timeout)
    check(scene + " sanitizers", "Sanitizer" not in r.stderr and "runtime error:" not in
          r.stderr, "no finding", r.stderr[:500])
    check(scene + " no NaN in JSON", "NaN" not in r.stdout and "Infinity" not in r.stdout,
          "finite", r.stdout[:200])
    try:
        j = json.loads(r.stdout) if r.stdout else {}
    except ValueError:
        j = {}
    return r.returncode, j, r.stderr


def exact_layer(x, eps):
    return 1 - (math.exp((x - 1) / eps) + math.exp(-x / eps)) / (1 + math.exp(-1 / eps))


# Boundary layers to eps = 1e-8 with --adapt: converged, true error below 1e-6.
for eps in ["1e-2", "1e-4", "1e-6", "1e-8"]:
    rc, j, err = run(os.path.join(data, "boundary_layer.scene"), "--set", "eps=" + eps,
                     "--adapt", "1e-7", "--degree", "4")
    check("layer %s exit" % eps, rc == 0, 0, (rc, err.strip()))
    check("layer %s converged" % eps, j.get("status") == "converged", "converged",
          j.get("status"))
    e = j.get("error", {}).get("max_nodal")
    check("layer %s error < 1e-6" % eps, e is not None and e < 1e-6, "< 1e-6", e)
    check("layer %s elements reported" % eps, j.get("elements", 0) > 10, "> 10",
          j.get("elements"))

# Brachistochrone: graded automatically; degree 4 reaches the time to 1e-8 relative.
T = math.pi * math.sqrt(2)
rc, j, err = run(os.path.join(data, "brachistochrone.scene"), "--degree", "4")
check("brachistochrone exit", rc == 0, 0, (rc, err.strip()))
a = j.get("action")
check("brachistochrone time to 1e-8 relative", a is not None and abs(a - T) <= 1e-8 * T,
      T, a)
check("brachistochrone says it graded the mesh", "graded" in j.get("message", ""),
      "... graded ...", j.get("message"))

# Continuation in a parameter: the catenary from c = 3 to c = 1.6.
rc, j, err = run(os.path.join(data, "catenary.scene"), "--continue", "c=3:1.6", "--degree",
                 "4", "--elements", "16")
check("continuation exit", rc == 0, 0, (rc, err.strip()))
check("continuation reported", "continuation in c" in j.get("message", ""),
      "... continuation in c ...", j.get("message"))
e = j.get("error", {}).get("max_nodal")
check("continuation reaches c = 1.6 exactly", e is not None and e < 1e-9, "< 1e-9", e)

# No solution: catenoid between rings of radius 1.4 (critical 1.50888): exit 1, not converged.
rc, j, err = run(os.path.join(rdata, "catenoid.scene"), "--degree", "2")
check("catenoid exit 1", rc == 1, 1, (rc, err.strip()))
check("catenoid not converged", j.get("status") not in (None, "converged"), "not converged",
      j.get("status"))
check("catenoid sentence", "no stationary path" in j.get("message", ""),
      "... no stationary path ...", j.get("message"))
rc, j, err = run(os.path.join(rdata, "catenoid.scene"), "--set", "R=1.52", "--degree", "2")
check("catenoid R = 1.52 solvable", rc == 0 and j.get("status") == "converged", "converged",
      (rc, j.get("status")))

# Long horizon: harmonic oscillator over [0, 100] has Morse index 31.
rc, j, err = run(os.path.join(data, "harmonic_saddle.scene"), "--degree", "4", "--elements",
                 "400")
check("harmonic [0, 4] Morse 1", j.get("morse_index") == 1, 1, j.get("morse_index"))

# Hostile input: undefined on half the domain, 1000-character and deeply nested formulas.
rc, j, err = run(os.path.join(rdata, "nan_half.scene"))
check("nan_half exit 1", rc == 1, 1, (rc, err.strip()))
check("nan_half says not finite", "not finite" in j.get("message", ""), "... not finite ...",
      j.get("message"))
for scene in ["long_expr.scene", "deep_nest.scene"]:
    rc, j, err = run(os.path.join(rdata, scene))
    check(scene + " solves", rc == 0 and j.get("status") == "converged", "converged",
          (rc, err.strip()[:200]))
# Huge and tiny parameters: an answer or an honest status, never NaN; an end value that
# overflows (c cosh(1/c) with c = 1e-150) is bad input with its line.
rc, j, err = run(os.path.join(data, "catenary.scene"), "--set", "c=1e150")
check("catenary c=1e150 exit 0 or 1", rc in (0, 1), "0 or 1", (rc, err.strip()))
rc, j, err = run(os.path.join(data, "catenary.scene"), "--set", "c=1e-150")
check("catenary c=1e-150 exit 2", rc == 2 and "catenary.scene:13:" in err and
      "not a finite number" in err, "exit 2, catenary.scene:13: ... not a finite number",
      (rc, err.strip()))

print("%d checks, %d failures" % (checks, failures))
sys.exit(1 if failures else 0)

#!/usr/bin/env python3
# tests/truth/test_floor_sentence.py — the round-off sentence of `--tol` does not contradict
# itself (issue 29, item 8; theory HP-6): "reached E and can go no lower: the round-off floor
# (about F)" only when E is within 10 F; an estimate that stalled near the floor and then
# grew is reported as such, with its cause, and "a table's rounding" is named only when
# the integrand reads a table.
# SPDX-License-Identifier: MIT
#
# usage: test_floor_sentence.py CALCVAR DATA
#
# y'^2/2 - k^2 y^2/2, y(0) = 0, y(1) = 1, next to the conjugate point k = pi (k = 3.141 and
# 3.1415; values of size 1/sin k ~ 1.7e3 and 1.1e4): --tol 1e-10 and 1e-12 end with exit 1.
# Before: "the error estimate reached 2e-08 > 1e-12 and can go no lower: that is the
# round-off floor ... (about 1e-10 ...)", and "(noise in the integrand's values, such as a
# table's rounding)" for a scene without tables. Also: the estimate reported is honest
# against the exact sin(k x)/sin(k) (at least a tenth of the true max nodal error).
import json
import math
import os
import re
import subprocess
import sys

calcvar, data = [os.path.abspath(a) for a in sys.argv[1:3]]
scene = os.path.join(data, "conjugate_k.scene")
failures = 0
checks = 0


def check(what, ok, detail=""):
    global failures, checks
    checks += 1
    if not ok:
        failures += 1
        print("FAIL %s %s" % (what, detail))


for k in ("3.141", "3.1415"):
    for T in ("1e-10", "1e-12"):
        what = "k = %s --tol %s" % (k, T)
        r = subprocess.run([calcvar, "solve", scene, "--set", "k=" + k, "--tol", T, "--json",
                            "-"], capture_output=True, text=True, timeout=300)
        check(what + " sanitizers", "Sanitizer" not in r.stderr and
              "runtime error:" not in r.stderr, r.stderr[:2000])
        try:
            d = json.loads(r.stdout)
        except ValueError:
            check(what + " JSON", False, r.stderr[:300])
            continue
        msg = d.get("message", "")
        check(what + " exit 1", r.returncode == 1, msg[:300])
        m = re.search(r"reached ([0-9.e+-]+) > [0-9.e+-]+ and can go no lower.*?about "
                      r"([0-9.e+-]+)", msg)
        if m:
            check(what + " 'can go no lower' only within 10 x the floor",
                  float(m.group(1)) <= 10 * float(m.group(2)), msg[:400])
        check(what + " no table named (the scene has none)", "table" not in msg, msg[:500])
        est = d.get("error_estimate")
        if isinstance(est, float) and "x" in d:
            kk = float(k)
            err = max(abs(y - math.sin(kk * x) / math.sin(kk)) for x, y in
                      zip(d["x"], d["y"]["y"]))
            check(what + " the estimate is honest (>= 0.1 x true error)", est >= 0.1 * err,
                  "estimate %.3g, true %.3g" % (est, err))

print("%d checks, %d failures" % (checks, failures))
sys.exit(1 if failures else 0)

#!/usr/bin/env python3
# tests/robust/test_cli_conjugate_end.py — an end that is a conjugate point of the other
# (y'' + pi^2 y = 0 on [0, 1] with y(0) = 0, y(1) = 1: no solution exists). On meshes where
# the discrete Hessian is singular to round-off the message must name both possible causes
# (reparametrisation invariance, a conjugate end), and where Newton and the retry both fail
# the second attempt's identical sentence is not repeated. Exit 1 in every case.
# SPDX-License-Identifier: MIT
#
# usage: test_cli_conjugate_end.py CALCVAR DATA_DIR
import os
import subprocess
import sys

calcvar, data = [os.path.abspath(a) for a in sys.argv[1:3]]
scene = os.path.join(data, "conjugate_end.scene")
failures = 0


def fail(what, expected, actual):
    global failures
    failures += 1
    print("FAIL %s\n  expected: %s\n  actual:   %s" % (what, expected, actual))


def solve(elements, degree):
    r = subprocess.run([calcvar, "solve", scene, "--elements", str(elements), "--degree",
                        str(degree), "--quiet"], capture_output=True, text=True, timeout=120)
    return r.returncode, r.stderr


# Degree 8 on 10 elements: the discrete eigenvalue sits on pi^2 to 4e-12, a singular Hessian.
rc, err = solve(10, 8)
if rc != 1 or "singular" not in err or "conjugate point" not in err or "energy form" not in err:
    fail("10 x 8", "exit 1, singular, naming a conjugate end and the energy form",
         "%d: %s" % (rc, err.strip()))

# Degree 4: Newton and the graded retry both fail in the same way; said once.
rc, err = solve(10, 4)
if rc != 1:
    fail("10 x 4 exit", 1, "%d: %s" % (rc, err.strip()))
first = err.split(";")[0].split(": ", 2)[-1]
if len(first) > 20 and err.count(first) > 1:
    fail("10 x 4 message", "the failure said once", err.strip())

print("%d failure(s)" % failures)
sys.exit(1 if failures else 0)

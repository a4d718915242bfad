#!/usr/bin/env python3
# tests/truth/test_continue_target.py — `solve --continue name=from:to` never goes past its
# target (issue 29, item 3): after a failed step the next value is half-way between the
# last accepted value and the failed one, so a stall is reported inside [from, to].
# SPDX-License-Identifier: MIT
#
# usage: test_continue_target.py CALCVAR DATA
#
# - k from 1 to pi on y'^2/2 - k^2 y^2/2 (the target is a conjugate point: no path there,
#   one beyond it): exit 1, no_progress, "stalled at k = K" with 1 <= K <= pi (before the
#   fix: "stalled at k = 4.36552");
# - k from 1 to 3 and from 3 to 1: converged, the answer against sin(k x)/sin(k) at the
#   target (true nodal error <= 1e-10), "reached by continuation ... to 3" (or 1).
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


def solve(*flags):
    r = subprocess.run([calcvar, "solve", scene, "--json", "-"] + list(flags),
                       capture_output=True, text=True, timeout=120)
    check("%s sanitizers" % (flags,), "Sanitizer" not in r.stderr and
          "runtime error:" not in r.stderr, r.stderr[:2000])
    try:
        return r, json.loads(r.stdout)
    except ValueError:
        check("%s JSON parses" % (flags,), False, r.stdout[:200] + r.stderr[:400])
        return r, {}


PI = "3.14159265358979"
r, d = solve("--continue", "k=1:" + PI)
check("to pi: exit 1", r.returncode == 1, r.stderr[:300])
check("to pi: no_progress", d.get("status") == "no_progress", d.get("status"))
m = re.search(r"stalled at k = ([0-9.eE+-]+)", d.get("message", ""))
check("to pi: says where it stalled", m is not None, d.get("message", "")[-300:])
if m:
    k = float(m.group(1))
    check("to pi: the stall lies inside [1, pi]", 1.0 <= k <= float(PI), k)

for a, b in (("1", "3"), ("3", "1")):
    r, d = solve("--continue", "k=%s:%s" % (a, b))
    what = "k from %s to %s" % (a, b)
    check(what + " exit 0", r.returncode == 0, r.stderr[:300])
    check(what + " reached", ("to %s in" % b) in d.get("message", ""), d.get("message", ""))
    if "x" in d:
        k = float(b)
        err = max(abs(y - math.sin(k * x) / math.sin(k)) for x, y in zip(d["x"], d["y"]["y"]))
        check(what + " the answer is the target's (nodal error <= 1e-10)", err <= 1e-10, err)

print("%d checks, %d failures" % (checks, failures))
sys.exit(1 if failures else 0)

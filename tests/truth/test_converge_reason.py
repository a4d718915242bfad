#!/usr/bin/env python3
# tests/truth/test_converge_reason.py — `calcvar converge` says why a row has no error
# estimate, as `solve` does (issue 29, item 9): the JSON row's message carries "no error
# estimate: <why>" and the text table a line under the row with "-".
# SPDX-License-Identifier: MIT
#
# usage: test_converge_reason.py CALCVAR DATA
#
# The conjugate end on 50, 100, 200 linear elements: every row converges (a discrete path)
# and none has an estimate (before: "-" and no sentence anywhere). A scene whose estimates
# exist (harmonic, no [exact]) gets no such sentence.
import json
import os
import subprocess
import sys

calcvar, data = [os.path.abspath(a) for a in sys.argv[1:3]]
failures = 0
checks = 0


def check(what, ok, detail=""):
    global failures, checks
    checks += 1
    if not ok:
        failures += 1
        print("FAIL %s %s" % (what, detail))


def converge(path, *flags, stdin=None):
    r = subprocess.run([calcvar, "converge", path] + list(flags), input=stdin,
                       capture_output=True, text=True, timeout=120)
    check("%s sanitizers" % (flags,), "Sanitizer" not in r.stderr and
          "runtime error:" not in r.stderr, r.stderr[:2000])
    return r


scene = os.path.join(data, "conjugate_end.scene")
flags = ["--degree", "1", "--elements", "50", "--levels", "3"]
r = converge(scene, *(flags + ["--json", "-", "--quiet"]))
try:
    rows = json.loads(r.stdout)
except ValueError:
    rows = []
    check("JSON parses", False, r.stdout[:300] + r.stderr[:300])
check("three rows", len(rows) == 3, len(rows))
for d in rows:
    what = "%d elements" % d.get("elements", -1)
    if "error_estimate" not in d:
        check(what + ": the message says why there is no estimate",
              "no error estimate: " in d.get("message", ""), d.get("message", ""))
check("some row has no estimate", any("error_estimate" not in d for d in rows))
r = converge(scene, *flags)
lines = r.stdout.splitlines()
for i, line in enumerate(lines):
    cols = line.split()
    if len(cols) >= 4 and cols[0].isdigit() and cols[3] == "-":
        check("text row %s: followed by the reason" % cols[0], i + 1 < len(lines) and
              lines[i + 1].strip().startswith("no error estimate: "), lines[i + 1:i + 2])

harmonic = "[scene]\ninterval = 0, 1\nunknowns = y\nintegrand = y'^2 + y^2\n[boundary]\ny = 0, 1\n"
r = converge("-", "--degree", "2", "--elements", "8", "--levels", "2", "--json", "-",
             "--quiet", stdin=harmonic)
try:
    rows = json.loads(r.stdout)
except ValueError:
    rows = []
for d in rows:
    check("harmonic %d elements: an estimate, no excuse" % d.get("elements", -1),
          "error_estimate" in d and "no error estimate" not in d.get("message", ""),
          d.get("message", ""))
check("harmonic: two rows", len(rows) == 2, len(rows))

print("%d checks, %d failures" % (checks, failures))
sys.exit(1 if failures else 0)

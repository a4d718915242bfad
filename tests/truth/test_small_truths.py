#!/usr/bin/env python3
# tests/truth/test_small_truths.py — small messages that must tell the truth (issue 29,
# item 11).
# SPDX-License-Identifier: MIT
#
# usage: test_small_truths.py CALCVAR
#
# - a [guess] that is not finite at a node (the variable called t; 1/(t - 0.5) at t = 0.5,
#   log(t - 0.5) at t = 0): exit 1, status diverged (as a non-finite integrand), and the
#   message gives the node where it fails (before: "no_progress ... near x = 0" whatever the
#   variable and wherever the failure);
# - --csv /dev/null --json /dev/null: exit 0 (a device is not a file that can be clobbered;
#   before: exit 2, "the same file"); --csv o.json --json ./o.json (not yet written): still
#   exit 2, one file under two names.
import json
import os
import subprocess
import sys
import tempfile

calcvar = os.path.abspath(sys.argv[1])
failures = 0
checks = 0
BASE = "[scene]\nvariable = t\ninterval = 0, 1\nunknowns = q\nintegrand = q'^2 + q^2\n" \
       "[boundary]\nq = 0, 1\n"


def check(what, ok, detail=""):
    global failures, checks
    checks += 1
    if not ok:
        failures += 1
        print("FAIL %s %s" % (what, detail))


def solve(text, *flags, cwd=None):
    r = subprocess.run([calcvar, "solve", "-"] + list(flags), input=text, capture_output=True,
                       text=True, timeout=60, cwd=cwd)
    check("%s sanitizers" % (flags,), "Sanitizer" not in r.stderr and
          "runtime error:" not in r.stderr, r.stderr[:2000])
    return r


for guess, at in (("1/(t - 0.5)", "0.5"), ("log(t - 0.5)", "0")):
    r = solve(BASE + "[guess]\nq = %s\n" % guess, "--json", "-")
    try:
        d = json.loads(r.stdout)
    except ValueError:
        d = {}
    what = "guess %s" % guess
    check(what + ": exit 1", r.returncode == 1, r.stderr[:300])
    check(what + ": diverged", d.get("status") == "diverged", d.get("status"))
    msg = d.get("message", "")
    check(what + ": names the node %s" % at, ("node %s of the interval" % at) in msg, msg)
    check(what + ": no 'x =' for a variable called t", "x =" not in msg, msg)

r = solve(BASE, "--csv", "/dev/null", "--json", "/dev/null", "--quiet")
check("/dev/null twice: exit 0", r.returncode == 0, r.stderr[:300])
with tempfile.TemporaryDirectory() as tmp:
    r = solve(BASE, "--csv", "o.json", "--json", "./o.json", "--quiet", cwd=tmp)
    check("o.json and ./o.json: exit 2", r.returncode == 2 and "same file" in r.stderr,
          r.stderr[:300])
    check("o.json and ./o.json: nothing written", not os.path.exists(os.path.join(tmp, "o.json")))
    r = solve(BASE, "--csv", "a.csv", "--json", "o.json", "--quiet", cwd=tmp)
    check("two files: exit 0", r.returncode == 0, r.stderr[:300])

print("%d checks, %d failures" % (checks, failures))
sys.exit(1 if failures else 0)

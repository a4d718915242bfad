#!/usr/bin/env python3
# tests/robust/test_cli_messages.py — messages that must not mislead (issue 14, item 7):
# --adapt reports the Newton iterations of all rounds (not the last round's), and the rounds;
# the adaptive cap names the option that raises it, and --max-elements does raise it; the
# summary says what Newton's convergence test is (the step), next to the residual.
# SPDX-License-Identifier: MIT
#
# usage: test_cli_messages.py CALCVAR DATA_DIR
import json
import os
import re
import subprocess
import sys

calcvar, data = [os.path.abspath(a) for a in sys.argv[1:3]]
BL = os.path.join(data, "boundary_layer.scene")
CAT = os.path.join(data, "catenary.scene")
failures = 0


def fail(what, expected, actual):
    global failures
    failures += 1
    print("FAIL %s\n  expected: %s\n  actual:   %s" % (what, expected, actual))


def run(args):
    r = subprocess.run([calcvar] + args, capture_output=True, text=True, timeout=300)
    if "Sanitizer" in r.stderr or "runtime error:" in r.stderr:
        fail("calcvar " + " ".join(args) + " sanitizer", "no finding", r.stderr[:2000])
    return r


# Adaptive refinement: the iterations are the sum over the rounds. Every round takes at
# least one Newton step, so the total is at least the number of rounds (before issue 14 the
# report gave the last round's count, 1 here), and the JSON's iterations equal the message's
# "N Newton iterations in all".
r = run(["solve", BL, "--adapt", "1e-8", "--json", "-"])
if r.returncode != 0:
    fail("boundary layer --adapt 1e-8 exit", 0, "%d: %s" % (r.returncode, r.stderr))
else:
    j = json.loads(r.stdout)
    m = re.search(r"after (\d+) rounds?, (\d+) Newton iterations in all \(and (\d+) on the "
                  r"reference meshes\)", j["message"])
    if not m:
        fail("--adapt message", "rounds and total Newton iterations", j["message"])
    else:
        rounds, total = int(m.group(1)), int(m.group(2))
        if j["iterations"] != total:
            fail("--adapt iterations", total, j["iterations"])
        if rounds < 2 or total < rounds:
            fail("--adapt totals", ">= 2 rounds and iterations >= rounds",
                 "%d rounds, %d iterations" % (rounds, total))

# The cap: named, with the option that raises it; --max-elements raises it.
r = run(["solve", BL, "--adapt", "1e-8", "--max-elements", "300", "--quiet"])
if r.returncode != 1 or "cap of 300 elements" not in r.stderr or "--max-elements" not in r.stderr:
    fail("--max-elements 300", "exit 1, 'cap of 300 elements ... --max-elements'",
         "%d: %s" % (r.returncode, r.stderr.strip()))
r = run(["solve", BL, "--adapt", "1e-8", "--max-elements", "100000", "--quiet"])
if r.returncode != 0:
    fail("--max-elements 100000", "exit 0 (the adapted mesh has ~24 000 elements)",
         "%d: %s" % (r.returncode, r.stderr.strip()))
for args, msg in ((["solve", CAT, "--max-elements", "10"], "adaptive refinement only"),
                  (["solve", CAT, "--adapt", "1e-6", "--max-elements", "0"], "--max-elements"),
                  (["converge", CAT, "--max-elements", "10"], "not of converge"),
                  (["equations", CAT, "--max-elements", "10"], "only --set")):
    r = run(args)
    if r.returncode != 2 or msg not in r.stderr:
        fail(" ".join(args[:1] + args[2:]), "exit 2, '%s'" % msg,
             "%d: %s" % (r.returncode, r.stderr.strip()))

# The summary says what was tested: the step, with the tolerance in use.
r = run(["solve", CAT, "--tolerance", "1e-9"])
if r.returncode != 0 or "Newton step within 1e-09" not in r.stdout or \
        "residual is not tested" not in r.stdout:
    fail("summary test line", "'Newton step within 1e-09 ... residual is not tested'",
         r.stdout)
r = run(["solve", CAT, "--method", "lbfgs"])
if "Newton step within" in r.stdout:
    fail("summary test line for lbfgs", "no Newton step line", r.stdout)

# An integrand singular inside the interval: y'^2 + y^2/(x - 0.5) has an infinite action
# (F ~ y(0.5)^2/|x - 0.5| along any path with y(0.5) != 0): never "converged", whatever
# the mesh (even or odd element counts, degrees); integrable singularities (log, 1/sqrt)
# and a singular point outside the interval stay converged.
import tempfile
with tempfile.TemporaryDirectory() as tmp:
    def scene(name, integrand, interval="0, 1"):
        path = os.path.join(tmp, name + ".scene")
        with open(path, "w") as f:
            f.write("[scene]\ninterval = %s\nunknowns = y\nintegrand = %s\n"
                    "[boundary]\ny = 0, 1\n" % (interval, integrand))
        return path
    sing = scene("sing", "y'^2 + y^2/(x - 0.5)")
    for extra in ([], ["--elements", "101"], ["--degree", "3", "--elements", "10"]):
        r = run(["solve", sing, "--json", "-"] + extra)
        j = json.loads(r.stdout) if r.stdout else {}
        if r.returncode != 1 or j.get("status") != "diverged" or \
                "singular at x = 0.5" not in j.get("message", "") or "morse_index" in j:
            fail("interior singularity " + " ".join(extra),
                 "exit 1, diverged, 'singular at x = 0.5', no Morse index",
                 "%d: %s" % (r.returncode, r.stdout[:300] + r.stderr))
    sing2 = scene("sing2", "y'^2 + y^2/(x^2 - 0.09)")  # zero at x = 0.3, a sign change
    r = run(["solve", sing2, "--quiet"])
    if r.returncode != 1 or "singular at x = 0.3" not in r.stderr:
        fail("interior singularity at 0.3", "exit 1, 'singular at x = 0.3'",
             "%d: %s" % (r.returncode, r.stderr))
    for name, integrand in (("log", "y'^2 + y^2*log(abs(x - 0.5))"),
                            ("sqrt", "y'^2 + y^2/sqrt(abs(x - 0.5))"),
                            ("outside", "y'^2 + y^2/(x - 1.5)")):
        r = run(["solve", scene(name, integrand), "--quiet"])
        if r.returncode != 0:
            fail("integrable or outside singularity (%s)" % name, "exit 0",
                 "%d: %s" % (r.returncode, r.stderr))

print("test_cli_messages: %d failures" % failures)
sys.exit(1 if failures else 0)

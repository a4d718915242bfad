#!/usr/bin/env python3
# tests/robust/test_cli_graded_end.py — the Morse index next to a singular end (theory M-2).
# The brachistochrone is a minimum (Morse index 0). On elements far smaller than 1e-10 of
# the interval at its cusp, the Hessian is a difference of nearly equal large terms and the
# LDL^T counted negative directions that are not the path's (1000 elements of degree 8,
# automatically graded with k = 4: Morse index 1, "saddle"). Automatic grading now keeps
# the end element >= 1e-10 of the interval: Morse index 0 and the exact time to 1e-10 on
# meshes of 300 ... 20000 elements; a user's grading that goes below gets a caution.
# SPDX-License-Identifier: MIT
#
# usage: test_cli_graded_end.py CALCVAR EXAMPLES_DIR
import json
import os
import re
import subprocess
import sys
import tempfile

calcvar, examples = [os.path.abspath(a) for a in sys.argv[1:3]]
failures = 0


def fail(what, expected, actual):
    global failures
    failures += 1
    print("FAIL %s\n  expected: %s\n  actual:   %s" % (what, expected, actual))


with open(os.path.join(examples, "brachistochrone.scene")) as f:
    text = f.read()
tmp = tempfile.mkdtemp()
auto = os.path.join(tmp, "auto.scene")  # no grading: calcvar grades the uniform mesh
with open(auto, "w") as f:
    f.write(re.sub(r"(?m)^grading.*\n", "", text))
steep = os.path.join(tmp, "steep.scene")  # a user's grading: k = 6
with open(steep, "w") as f:
    f.write(re.sub(r"(?m)^grading\s*=.*$", "grading    = 6", text))


def solve(scene, e, p):
    r = subprocess.run([calcvar, "solve", scene, "--elements", str(e), "--degree", str(p),
                        "--json", "-"], capture_output=True, text=True, timeout=300)
    if r.returncode != 0:
        return None, "%d: %s" % (r.returncode, r.stderr.strip())
    return json.loads(r.stdout), ""


for e, p in [(300, 8), (1000, 8), (3000, 8), (10000, 4), (20000, 8)]:
    j, err = solve(auto, e, p)
    if j is None:
        fail("auto %dx%d" % (e, p), "exit 0", err)
        continue
    if j["morse_index"] != 0 or j["stationary_kind"] != "minimum":
        fail("auto %dx%d Morse index" % (e, p), "0, minimum",
             "%s, %s" % (j["morse_index"], j["stationary_kind"]))
    if not j["error"]["action"] <= 1e-10 * abs(j["action"]):
        fail("auto %dx%d time" % (e, p), "relative error <= 1e-10", j["error"]["action"])

# k = 6 on 300 elements: the end element is 1.4e-15 of the interval. Whatever the count,
# a Morse index above 0 must carry the caution.
j, err = solve(steep, 300, 8)
if j is None:
    fail("k = 6, 300x8", "exit 0", err)
elif j["morse_index"] > 0 and "may belong to the mesh" not in j["message"]:
    fail("k = 6, 300x8 caution", "a caution beside Morse index %d" % j["morse_index"],
         j["message"])

print("%d failure(s)" % failures)
sys.exit(1 if failures else 0)

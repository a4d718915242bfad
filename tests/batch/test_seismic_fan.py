#!/usr/bin/env python3
# tests/batch/test_seismic_fan.py — a fan of seismic rays through the tabulated 3-D velocity
# model of examples/scenes/seismic_fan.scene (constant gradient, so every travel time has a
# closed form; issue 28): 200 source-receiver pairs spread over the shipped fan of 10^4
# (make_seismic_fan.py), `calcvar batch --tol 1e-10` on one and on two threads. Every row
# must converge with its travel time (the action) within 1e-8 relative of the closed form
# acosh(1 + |g|^2 |r1 - r0|^2 / (2 v0 v1)) / |g|, its ray within 10 T = 1e-9 km of the exact
# circular arc at the nodes (error_max_nodal) and its estimate at most T; both tables alike.
# A receiver off the grid fails its row alone (exit 1) with the table's sentence; a row that
# makes the interval empty, or a value that is not a number, is bad input (exit 2,
# TABLE:LINE) before anything is solved.
# Usage: test_seismic_fan.py CALCVAR EXAMPLES_DIR
# SPDX-License-Identifier: MIT
import csv
import io
import os
import subprocess
import sys
import tempfile

calcvar, examples = sys.argv[1], sys.argv[2]
sys.path.insert(0, examples)
import make_seismic_fan as fan  # noqa: E402

scene = os.path.join(examples, "seismic_fan.scene")
T = 1e-10        # --tol: the max nodal error of each ray, km
MAX_REL = 1e-8   # the travel times against the closed form, relative
failures = 0
checks = 0


def check(what, ok, expected, actual):
    global failures, checks
    checks += 1
    if not ok:
        failures += 1
        print("FAIL %s\n  expected: %s\n  actual:   %s" % (what, expected, actual))


def run(args):
    r = subprocess.run([calcvar] + args, capture_output=True, text=True, timeout=120)
    check("sanitizers: %s" % " ".join(args[2:]),
          "Sanitizer" not in r.stderr and "runtime error:" not in r.stderr, "no finding",
          r.stderr[:500])
    return r


tmp = tempfile.mkdtemp(prefix="cvseis")
table = os.path.join(tmp, "fan.csv")
with open(table, "w") as f:
    f.write(fan.table(200))

outputs = {}
for threads in ("1", "2"):
    tag = "--threads " + threads
    r = run(["batch", scene, table, "--tol", str(T), "--threads", threads])
    check("%s: exit 0" % tag, r.returncode == 0, 0, (r.returncode, r.stderr[:300]))
    rows = list(csv.DictReader(io.StringIO(r.stdout)))
    check("%s: 200 rows" % tag, len(rows) == 200, 200, len(rows))
    worst, over = 0.0, 0
    for i, row in enumerate(rows):
        what = "%s row %d" % (tag, i + 2)
        if row["status"] != "converged":
            check("%s: converged" % what, False, "converged", row["message"])
            continue
        r0 = [float(row[c]) for c in ("xs", "ys", "zs")]
        r1 = [float(row[c]) for c in ("xr", "yr", "zr")]
        t = fan.travel_time(r0, r1)
        rel = abs(float(row["action"]) - t) / t
        worst = max(worst, rel)
        over += rel > MAX_REL
        check("%s: travel time within %g relative" % (what, MAX_REL), rel <= MAX_REL, t,
              row["action"])
        check("%s: ray within 10 T of the arc" % what, float(row["error_max_nodal"]) <= 10 * T,
              10 * T, row["error_max_nodal"])
        check("%s: estimate <= T" % what, float(row["error_estimate"]) <= T, T,
              row["error_estimate"])
    outputs[threads] = [(row["status"], row["action"]) for row in rows]
    print("%s: 200 rays, max relative travel-time error %.3g, %d over %g" %
          (tag, worst, over, MAX_REL))
# the times agree between the tables within the tolerance (the meshes handed on may differ)
for (s1, a1), (s2, a2) in zip(outputs["1"], outputs["2"]):
    if s1 == s2 == "converged":
        check("threads 1 and 2 agree", abs(float(a1) - float(a2)) <= MAX_REL * float(a1), a1, a2)

# A receiver off the grid (y = 6 km, the grid ends at 4): that row fails, the others not.
off = os.path.join(tmp, "off.csv")
with open(off, "w") as f:
    f.write("xs,ys,zs,xr,yr,zr\n0,0,1,8,1,0\n0,0,1,8,6,0\n0,0,1,8,-1,0\n")
r = run(["batch", scene, off, "--tol", str(T), "--threads", "1"])
rows = list(csv.DictReader(io.StringIO(r.stdout)))
check("off the grid: exit 1", r.returncode == 1, 1, (r.returncode, r.stderr[:300]))
check("off the grid: 3 rows", len(rows) == 3, 3, len(rows))
if len(rows) == 3:
    check("off the grid: the others converge",
          rows[0]["status"] == rows[2]["status"] == "converged", "converged",
          (rows[0]["status"], rows[2]["status"]))
    check("off the grid: the row fails", rows[1]["status"] != "converged" and
          not rows[1]["action"], "no travel time", rows[1])
    check("off the grid: the row says which table and where",
          "left the grid of table 'v'" in rows[1]["message"] and "[-4, 4]" in rows[1]["message"],
          "the table's sentence", rows[1]["message"])

# Bad input: exit 2 with TABLE:LINE, nothing written.
for name, text, what in (("back.csv", "xs,ys,zs,xr,yr,zr\n0,0,1,8,1,0\n9,0,1,8,1,0\n",
                          "interval needs a < b"),
                         ("nan.csv", "xs,ys,zs,xr,yr,zr\n0,0,1,8,1,0\n0,0,1,8,x,0\n",
                          "not a finite number")):
    path = os.path.join(tmp, name)
    with open(path, "w") as f:
        f.write(text)
    r = run(["batch", scene, path, "--tol", str(T)])
    check("%s: exit 2" % name, r.returncode == 2, 2, (r.returncode, r.stderr[:300]))
    check("%s: TABLE:LINE" % name, r.stderr.startswith(path + ":3:") and what in r.stderr,
          path + ":3: ... " + what, r.stderr[:300])
    check("%s: nothing written" % name, r.stdout == "", "", r.stdout[:200])

print("%d checks, %d failed" % (checks, failures))
sys.exit(1 if failures else 0)

#!/usr/bin/env python3
# tests/ends/test_cli_ends.py — moving ends ([ends], theory ME-1 .. ME-4) through
# `calcvar solve`: the solved interval, the path and the action against closed forms, plain
# and under --tol, the Morse index, and an interval that collapses (exit 1).
# SPDX-License-Identifier: MIT
#
# usage: test_cli_ends.py CALCVAR SCENE_DIR
#
# Tolerances. point_to_circle's answer is a straight line, which degree-1 elements hold
# exactly: end point, path and length to 1e-12 (measured 2e-15 .. 9e-15). free_time on the
# default mesh (100 elements of degree 1): the end's error is the O(h^2) error of the end
# data, measured 1.7e-6 (bound 1e-5). Under --tol T the true errors must stay below 10 T
# (SCENES.md); measured: end points within 3e-13 of the exact ones at T = 1e-10.
import csv
import json
import math
import os
import subprocess
import sys
import tempfile

calcvar, scenes = [os.path.abspath(a) for a in sys.argv[1:3]]
failures = 0
checks = 0


def check(what, ok, expected, actual):
    global failures, checks
    checks += 1
    if not ok:
        failures += 1
        print("FAIL %s\n  expected: %s\n  actual:   %s" % (what, expected, actual))


def near(what, actual, exact, tol):
    check(what, actual is not None and abs(actual - exact) <= tol,
          "%.17g within %g" % (exact, tol), actual)


def solve(scene, *flags, expect_rc=0):
    with tempfile.TemporaryDirectory() as tmp:
        jp, cp = os.path.join(tmp, "r.json"), os.path.join(tmp, "r.csv")
        r = subprocess.run([calcvar, "solve", os.path.join(scenes, scene), "--json", jp,
                            "--csv", cp, "--quiet"] + list(flags),
                           capture_output=True, text=True, timeout=300)
        what = "%s %s" % (scene, " ".join(flags))
        check(what + " sanitizers", "Sanitizer" not in r.stderr and
              "runtime error:" not in r.stderr, "no finding", r.stderr[:2000])
        check(what + " exit status", r.returncode == expect_rc, expect_rc,
              "%d (stderr: %s)" % (r.returncode, r.stderr.strip()))
        j = json.load(open(jp)) if os.path.exists(jp) else {}
        rows = list(csv.reader(open(cp))) if os.path.exists(cp) else [[]]
        return j, rows


def common(what, j, rows, interval, action, morse=0):
    """Status, interval, action, Morse index, and the CSV's variable column on the solved
    interval (its first and last rows are the ends)."""
    check(what + " status", j.get("status") == "converged", "converged", j.get("status"))
    iv = j.get("interval", [None, None])
    near(what + " interval a", iv[0], interval[0][0], interval[0][1])
    near(what + " interval b", iv[1], interval[1][0], interval[1][1])
    near(what + " action", j.get("action"), action[0], action[1])
    check(what + " morse_index", j.get("morse_index") == morse, morse, j.get("morse_index"))
    check(what + " stationary_kind", j.get("stationary_kind") ==
          ("minimum" if morse == 0 else "saddle"), morse, j.get("stationary_kind"))
    body = rows[1:]
    check(what + " CSV rows", len(body) == j.get("nodes"), j.get("nodes"), len(body))
    if body and len(iv) == 2 and iv[0] is not None:
        check(what + " CSV variable column spans the interval",
              float(body[0][0]) == iv[0] and float(body[-1][0]) == iv[1], iv,
              [body[0][0], body[-1][0]])


def cycloid_y(x, r):
    """The cycloid x = r (f - sin f), y = r (1 - cos f) at x, f by Newton (independent of
    the solver)."""
    if x <= 0:
        return 0.0
    f = (6 * x / r) ** (1 / 3)
    for _ in range(100):
        df = (r * (f - math.sin(f)) - x) / (r * (1 - math.cos(f)))
        f -= df
        if abs(df) < 1e-16 * f:
            break
    return r * (1 - math.cos(f))


b_circle = 3 * (1 - 1 / math.sqrt(13))
length = math.sqrt(13) - 1
T = math.asinh(1)
A_time = math.sqrt(2) / 2 + T / 2

# The reference problem: its exact answer plain and with --tol 1e-8.
for flags, tol in [((), 1e-12), (("--tol", "1e-8"), 1e-12)]:
    j, rows = solve("point_to_circle.scene", *flags)
    what = "point_to_circle " + " ".join(flags)
    common(what, j, rows, [(0, 0), (b_circle, tol)], (length, tol))
    check(what + " error.max_nodal", j.get("error", {}).get("max_nodal", 1) <= tol, tol,
          j.get("error"))
    if flags:
        check(what + " error_estimate", j.get("error_estimate", 1) <= 1e-8, "<= 1e-8",
              j.get("error_estimate"))
# The same mirrored: the start moves on a circle.
j, rows = solve("circle_to_point.scene")
common("circle_to_point", j, rows, [(-b_circle, 1e-12), (0, 0)], (length, 1e-12))

# Free final time and its mirror: H(T) = 0 (ME-1).
for scene, sign in [("free_time.scene", 1), ("free_start.scene", -1)]:
    ends = [(0, 0), (T, 1e-5)] if sign > 0 else [(-T, 1e-5), (0, 0)]
    j, rows = solve(scene)
    common(scene, j, rows, ends, (A_time, 1e-5))
    check(scene + " error.max_nodal", j.get("error", {}).get("max_nodal", 1) <= 1e-5, 1e-5,
          j.get("error"))
    ends = [(0, 0), (T, 1e-9)] if sign > 0 else [(-T, 1e-9), (0, 0)]
    j, rows = solve(scene, "--tol", "1e-10")
    common(scene + " --tol 1e-10", j, rows, ends, (A_time, 1e-9))
    check(scene + " --tol 1e-10 error.max_nodal", j.get("error", {}).get("max_nodal", 1) <= 1e-9,
          1e-9, j.get("error"))

# The brachistochrone to the line x + y = pi/2: the cycloid of radius 1 meets it at a right
# angle at (pi/2 - 1, 1), time pi/sqrt(2); under --tol 1e-10 end, time and path to 1e-9.
j, rows = solve("brachistochrone_line.scene", "--tol", "1e-10")
common("brachistochrone_line --tol 1e-10", j, rows, [(0, 0), (math.pi / 2 - 1, 1e-9)],
       (math.pi / math.sqrt(2), 1e-9))
err = max(abs(float(r[1]) - cycloid_y(float(r[0]), 1.0)) for r in rows[1:]) if rows[1:] else 1
check("brachistochrone_line --tol 1e-10 nodal error against the cycloid", err <= 1e-9, 1e-9, err)
if rows[1:]:
    near("brachistochrone_line end value", float(rows[-1][1]), 1.0, 1e-9)
# To the wall x = pi: the curve fixes the end; the end value is free and the cycloid meets
# the wall horizontally at its lowest point (pi, 2).
j, rows = solve("brachistochrone_wall.scene", "--tol", "1e-10")
common("brachistochrone_wall --tol 1e-10", j, rows, [(0, 0), (math.pi, 1e-15)],
       (math.pi * math.sqrt(2), 1e-9))
if rows[1:]:
    near("brachistochrone_wall end value", float(rows[-1][1]), 2.0, 1e-9)

# --all: the near and the far side of the circle, the far one a saddle (the length has a
# maximum along the circle there: Morse index 1 = inner 0 + 1, ME-4, ME-5).
for flags in [(), ("--tol", "1e-8")]:
    j, rows = solve("point_to_circle.scene", "--all", *flags)
    what = "point_to_circle --all " + " ".join(flags)
    sols = j.get("solutions", [])
    check(what + " two paths", len(sols) == 2, 2, len(sols))
    far = 3 * (1 + 1 / math.sqrt(13))
    for k, (b, act, morse, kind) in enumerate([(b_circle, length, 0, "minimum"),
                                                (far, math.sqrt(13) + 1, 1, "saddle")]):
        s = sols[k] if k < len(sols) else {}
        near(what + " path %d end" % (k + 1), s.get("interval", [0, None])[1], b, 1e-10)
        near(what + " path %d length" % (k + 1), s.get("action"), act, 1e-10)
        check(what + " path %d morse_index" % (k + 1), s.get("morse_index") == morse, morse,
              s.get("morse_index"))
        check(what + " path %d kind" % (k + 1), s.get("stationary_kind") == kind, kind,
              s.get("stationary_kind"))
        check(what + " path %d max_nodal" % (k + 1),
              s.get("error", {}).get("max_nodal", 1) <= 1e-10, 1e-10, s.get("error"))

# Without [exact]: both paths of --all get their error estimate (the enriched solve of the
# inner problem on the solved interval; the far side's index 1 is the end's, ME-4).
j, rows = solve("point_to_circle_r.scene", "--all")
for k, s in enumerate(j.get("solutions", [])):
    check("point_to_circle_r --all path %d error_estimate" % (k + 1),
          s.get("error_estimate", 1) <= 1e-12, "<= 1e-12", s.get("error_estimate"))

# A degenerate family (every radius of a circle from its centre): reported as degenerate,
# never as a minimum.
j, rows = solve("centred_circle.scene")
check("centred_circle stationary_kind", j.get("stationary_kind") == "degenerate", "degenerate",
      j.get("stationary_kind"))
near("centred_circle length", j.get("action"), 2.0, 1e-12)

# A free end with an integral constraint: H of L = F + mu K (ME-2). T^2 = 3 sqrt(2),
# mu = -2 sqrt(2)/T, action 4T/3. Default mesh: T off by 1.0e-4 (O(h^2)); --tol 1e-10: 0.
Ta = math.sqrt(3 * math.sqrt(2))
for flags, tol in [((), 5e-4), (("--tol", "1e-10"), 1e-10)]:
    j, rows = solve("free_time_area.scene", *flags)
    what = "free_time_area " + " ".join(flags)
    common(what, j, rows, [(0, 0), (Ta, tol)], (4 * Ta / 3, tol))
    near(what + " multiplier", j.get("multipliers", {}).get("area"), -2 * math.sqrt(2) / Ta, tol)
    check(what + " error.max_nodal", j.get("error", {}).get("max_nodal", 1) <= 10 * tol, 10 * tol,
          j.get("error"))

# Both ends move (ME-6): between two circles, plain and under --tol 1e-10; measured end
# points within 2.1e-13 and paths within 5.2e-13 of the exact segment.
a2, b2 = 2 / math.sqrt(5), 6 - 2 / math.sqrt(5)
for flags in [(), ("--tol", "1e-10")]:
    j, rows = solve("two_circles.scene", *flags)
    what = "two_circles " + " ".join(flags)
    common(what, j, rows, [(a2, 1e-11), (b2, 1e-11)], (math.sqrt(45) - 2, 1e-11))
    check(what + " error.max_nodal", j.get("error", {}).get("max_nodal", 1) <= 1e-11, 1e-11,
          j.get("error"))
# An autonomous integrand with both ends free: a family of shifts, reported degenerate.
j, rows = solve("shift_family.scene")
check("shift_family stationary_kind", j.get("stationary_kind") == "degenerate", "degenerate",
      j.get("stationary_kind"))
iv = j.get("interval", [0, 0])
near("shift_family duration", iv[1] - iv[0], T, 1e-5)

# batch: a radius per row, each row's length sqrt(13) - r (the end found per row).
r = subprocess.run([calcvar, "batch", os.path.join(scenes, "point_to_circle_r.scene"),
                    os.path.join(scenes, "radius.csv"), "--threads", "2"],
                   capture_output=True, text=True, timeout=300)
check("batch exit status", r.returncode == 0, 0, "%d (%s)" % (r.returncode, r.stderr.strip()))
table = list(csv.DictReader(r.stdout.splitlines()))
check("batch rows", len(table) == 4, 4, len(table))
for row in table:
    near("batch r=%s length" % row.get("r"), float(row.get("action") or "nan"),
         math.sqrt(13) - float(row.get("r")), 1e-12)

# No stationary end point: exit 1 and a sentence, never a converged report.
j, rows = solve("collapse.scene", expect_rc=1)
check("collapse status", j.get("status") not in (None, "converged"), "not converged",
      j.get("status"))
check("collapse message", "collapses" in j.get("message", ""), "... collapses ...",
      j.get("message"))

j, rows = solve("runaway.scene", expect_rc=1)
check("runaway status", j.get("status") not in (None, "converged"), "not converged",
      j.get("status"))
check("runaway message", "runs away" in j.get("message", ""), "... runs away ...",
      j.get("message"))

print("%d checks, %d failures" % (checks, failures))
sys.exit(1 if failures else 0)

#!/usr/bin/env python3
# tests/batch/test_batch_tol_reuse.py — `calcvar batch --tol` starts each row from the mesh
# the previous row on its thread handed on (theory HP-9), verified by the estimate (issue
# 28): over a sweep of WGS84 geodesics whose needs rise and fall (examples/scenes/
# wgs84_geodesic.scene, latitude and longitude), with one and two threads and with --warm,
# every row converges with error_estimate <= T, and its length and action are those of
# `calcvar solve` of the row from scratch (both within T of the path: the length, stationary,
# to 1e-6 m, the action to 1e-12 relative); the meshes are reused (fewer rounds in all than
# the rows solved from scratch) and coarsened where a row needs less (rows that end on fewer
# elements than the row before them).
# Usage: test_batch_tol_reuse.py CALCVAR SCENE
# SPDX-License-Identifier: MIT
import csv
import io
import json
import math
import os
import re
import subprocess
import sys
import tempfile

calcvar, scene = sys.argv[1], sys.argv[2]
failures = 0
checks = 0
T = 1e-10


def check(what, ok, expected, actual):
    global failures, checks
    checks += 1
    if not ok:
        failures += 1
        print("FAIL %s\n  expected: %s\n  actual:   %s" % (what, expected, actual))


def run(args):
    r = subprocess.run([calcvar] + args, capture_output=True, text=True, timeout=300)
    check("sanitizers", "Sanitizer" not in r.stderr and "runtime error:" not in r.stderr,
          "no finding", r.stderr[:500])
    return r


ROUNDS = re.compile(r"on (\d+) elements \((\d+) nodes\) after (\d+) rounds?")
# from (60, 0) to (lat2, 120): the need for elements rises towards lat2 = 66 and falls back
lat2 = [-60 + 126 * abs(math.sin(math.pi * k / 24)) for k in range(24)]
rows = [("60", "0", "%.6f" % v, "120") for v in lat2]
tmp = tempfile.mkdtemp(prefix="cvreuse")
table = os.path.join(tmp, "sweep.csv")
with open(table, "w") as f:
    f.write("lat1,lon1,lat2,lon2\n" + "".join(",".join(r) + "\n" for r in rows))

scratch = []
for r in rows:
    s = run(["solve", scene, "--set", "lat1=" + r[0], "--set", "lon1=" + r[1], "--set",
             "lat2=" + r[2], "--set", "lon2=" + r[3], "--tol", str(T), "--json", "-"])
    js = json.loads(s.stdout) if s.stdout.strip() else {}
    m = ROUNDS.search(js.get("message", ""))
    scratch.append((js, int(m.group(3)) if m else 0))
    check("solve lat2=%s converged" % r[2], js.get("status") == "converged", "converged", js)
rounds_scratch = sum(k for _, k in scratch)

for flags in (["--threads", "1"], ["--threads", "2"], ["--threads", "1", "--warm"]):
    tag = " ".join(flags)
    b = run(["batch", scene, table, "--tol", str(T)] + flags)
    check("%s: exit 0" % tag, b.returncode == 0, 0, (b.returncode, b.stderr[:300]))
    out = list(csv.DictReader(io.StringIO(b.stdout)))
    check("%s: %d rows" % (tag, len(rows)), len(out) == len(rows), len(rows), len(out))
    rounds, coarsened, prev_e = 0, 0, None
    for r, row, (js, _) in zip(rows, out, scratch):
        rt = "%s lat2=%s" % (tag, r[2])
        check("%s: converged" % rt, row["status"] == "converged", "converged", row["message"])
        if row["status"] != "converged" or js.get("status") != "converged":
            continue
        est = float(row["error_estimate"])
        check("%s: estimate <= T" % rt, est <= T, T, est)
        s_b, s_s = float(row["s"]), js["report"]["s"]
        check("%s: length as solve's to 1e-6 m" % rt, abs(s_b - s_s) <= 1e-6, s_s, s_b)
        a_b, a_s = float(row["action"]), js["action"]
        check("%s: action as solve's" % rt, abs(a_b - a_s) <= 1e-12 * abs(a_s), a_s, a_b)
        m = ROUNDS.search(row["message"])
        check("%s: rounds in the message" % rt, m is not None, "a count", row["message"])
        if m:
            rounds += int(m.group(3))
            e = int(m.group(1))
            coarsened += prev_e is not None and e < prev_e
            prev_e = e
    if flags[1] == "1":  # on one thread every row follows the one before it
        check("%s: fewer rounds than from scratch" % tag, rounds < rounds_scratch,
              "< %d" % rounds_scratch, rounds)
        check("%s: some row coarsened" % tag, coarsened > 0, "> 0", coarsened)

print("%d checks, %d failures (rounds from scratch %d)" % (checks, failures, rounds_scratch))
sys.exit(1 if failures else 0)

#!/usr/bin/env python3
# tests/scene/test_tables.py — the [tables] section of scenes: a tabulated medium solves
# to the analytic ray; every malformed CSV is refused with exit 2 and the CSV's own
# FILE:LINE; a wrong argument count at the scene's line; a path that leaves the grid ends
# with exit 1 and a message naming the table. SPDX-License-Identifier: MIT
#
# usage: test_tables.py CALCVAR
import json
import os
import subprocess
import sys
import tempfile

calcvar = os.path.abspath(sys.argv[1])
failures = 0


def fail(what, expected, actual):
    global failures
    failures += 1
    print("FAIL %s\n  expected: %s\n  actual:   %s" % (what, expected, actual))


def run(args, cwd):
    r = subprocess.run([calcvar] + args, cwd=cwd, capture_output=True, text=True, timeout=120)
    if "Sanitizer" in r.stderr or "runtime error:" in r.stderr:
        fail(" ".join(args) + " sanitizer", "no finding", r.stderr[:2000])
    return r


# Maxwell's fish-eye n = 2/(1 + x^2 + y^2) on a 17 x 17 grid; the ray between
# (-0.8, y0) and (0.8, y0) is y = -0.5 + sqrt(1.25 - x^2).
def grid_rows(nx=17, ny=17):
    rows = []
    for i in range(nx):
        for j in range(ny):
            x = -0.8 + 1.6 * i / (nx - 1)
            y = 0.2 + 0.45 * j / (ny - 1)
            rows.append("%.17g, %.17g, %.17g" % (x, y, 2 / (1 + x * x + y * y)))
    return rows


SCENE = """[scene]
title = fish-eye from a table
interval = -0.8, 0.8
unknowns = y
integrand = %s
[tables]
n = %s
[boundary]
y = %s, %s
[exact]
y = -0.5 + sqrt(1.25 - x^2)
[mesh]
elements = 16
degree = 6
"""
Y0 = "-0.5 + sqrt(0.61)"


def write(path, text):
    with open(path, "w") as f:
        f.write(text)


with tempfile.TemporaryDirectory() as tmp:
    sub = os.path.join(tmp, "data")
    os.mkdir(sub)
    good = grid_rows()
    write(os.path.join(sub, "n.csv"), "x, y, n\n" + "\n".join(good[::-1]) + "\n")  # any order
    scene = os.path.join(tmp, "fe.scene")
    write(scene, SCENE % ("n(x, y)*sqrt(1 + y'^2)", "data/n.csv", Y0, Y0))

    # solves from another directory (the path is relative to the scene), converges, and
    # the error is that of a 17-point table (h = 0.1 and 0.028), not of the formula
    r = run(["solve", scene, "--json", "-"], "/")
    if r.returncode != 0:
        fail("good table exit", 0, "%d %s" % (r.returncode, r.stderr))
    else:
        rep = json.loads(r.stdout)
        err = rep["error"]["max_nodal"]
        print("17 x 17 table: max nodal error %.3e, %d iterations" % (err, rep["iterations"]))
        if not 1e-9 < err < 1e-5:
            fail("good table error", "between 1e-9 and 1e-5", err)

    # an absolute path works as well
    write(scene, SCENE % ("n(x, y)*sqrt(1 + y'^2)", os.path.join(sub, "n.csv"), Y0, Y0))
    r = run(["solve", scene, "--quiet"], tmp)
    if r.returncode != 0:
        fail("absolute path exit", 0, "%d %s" % (r.returncode, r.stderr))

    # malformed CSVs: (name, text, line the message must name, substring)
    header = "x, y, n"
    bad = [
        ("header_missing", "\n".join(good) + "\n", 1, "header"),
        ("header_one_column", "n\n1\n2\n", 1, "2 to 4 columns"),
        ("header_five_columns", "a, b, c, d, n\n1, 2, 3, 4, 5\n", 1, "2 to 4 columns"),
        ("header_empty_name", "x, , n\n" + "\n".join(good) + "\n", 1, "column 2 is empty"),
        ("row_short", header + "\n" + "\n".join(good[:5]) + "\n1, 2\n" + "\n".join(good[5:]),
         7, "2 values in this row, the header has 3"),
        ("row_long", header + "\n" + "\n".join(good[:2]) + "\n1, 2, 3, 4\n", 4,
         "4 values in this row"),
        ("not_a_number", header + "\n" + "\n".join(good[:3]) + "\n0.1, abc, 2\n", 5,
         "'abc' is not a number"),
        ("not_finite", header + "\n" + "\n".join(good[:8]) + "\n0.1, 0.3, nan\n", 10,
         "not a finite number"),
        ("infinite", header + "\n" + "\n".join(good[:1]) + "\n1e999, 0.3, 1\n", 3,
         "not a finite number"),
        ("repeated", header + "\n" + "\n".join(good) + "\n" + good[20] + "\n", len(good) + 2,
         "repeated grid point (also on line 22)"),
        ("missing", header + "\n" + "\n".join(good[:40] + good[41:]) + "\n", len(good),
         "1 of 289 points are missing"),
        ("three_values", header + "\n" + "\n".join(
            "%g, %g, 1" % (x, y) for x in (0, 1, 2) for y in (0, 1, 2, 3)) + "\n", 1,
         "coordinate 'x' has 3 distinct values"),
        ("no_rows", header + "\n", 1, "no rows"),
    ]
    for name, text, line, expect in bad:
        csv = os.path.join(sub, name + ".csv")
        write(csv, text)
        write(scene, SCENE % ("n(x, y)*sqrt(1 + y'^2)", "data/" + name + ".csv", Y0, Y0))
        out = os.path.join(tmp, name + ".json")
        r = run(["solve", scene, "--json", out], tmp)
        prefix = "%s:%d: " % (csv, line)
        if r.returncode != 2:
            fail(name + " exit", 2, "%d (%s)" % (r.returncode, r.stderr.strip()))
        elif not r.stderr.startswith(prefix):
            fail(name + " location", prefix + "...", r.stderr.strip())
        elif expect not in r.stderr:
            fail(name + " message", "... " + expect + " ...", r.stderr.strip())
        if os.path.exists(out):
            fail(name + " output", "no file", out)

    # faults pointing at the scene's own line: (name, integrand, table file, line, substring)
    scene_bad = [
        ("missing_file", "n(x, y)*sqrt(1 + y'^2)", "data/nosuch.csv", 7, "cannot open"),
        ("too_few_args", "n(x)*sqrt(1 + y'^2)", "data/n.csv", 5,
         "table 'n' has 2 coordinates, so it takes 2 arguments"),
        ("too_many_args", "n(x, y, y)*sqrt(1 + y'^2)", "data/n.csv", 5, "takes 2 arguments"),
        ("bad_derivative", "n.3(x, y)*sqrt(1 + y'^2)", "data/n.csv", 5, "derivative index"),
        ("not_called", "n*sqrt(1 + y'^2)", "data/n.csv", 5, "'n' is a table"),
        ("constant_outside", "n(x, 2)*sqrt(1 + y'^2)", "data/n.csv", 5,
         "table 'n' is called outside its grid: argument 2 is 2"),
    ]
    for name, F, table, line, expect in scene_bad:
        write(scene, SCENE % (F, table, Y0, Y0))
        r = run(["solve", scene], tmp)
        prefix = "%s:%d: " % (scene, line)
        if r.returncode != 2:
            fail(name + " exit", 2, "%d (%s)" % (r.returncode, r.stderr.strip()))
        elif not r.stderr.startswith(prefix):
            fail(name + " location", prefix + "...", r.stderr.strip())
        elif expect not in r.stderr:
            fail(name + " message", "... " + expect + " ...", r.stderr.strip())

    # a table name that is already taken
    write(scene, (SCENE % ("n(x, y)*sqrt(1 + y'^2)", "data/n.csv", Y0, Y0)).replace(
        "[tables]", "[parameters]\nn = 1\n[tables]"))
    r = run(["solve", scene], tmp)
    if r.returncode != 2 or "already a table" not in r.stderr:
        fail("parameter named like a table", "exit 2, 'already a table'",
             "%d %s" % (r.returncode, r.stderr.strip()))

    # leaving the grid: ends outside (0.9 > 0.65), and a path that must leave it
    for name, ya in [("ends_outside", "0.9"), ("path_leaves", "0.5")]:
        write(scene, SCENE % ("n(x, y)*sqrt(1 + y'^2)", "data/n.csv", ya, ya))
        r = run(["solve", scene, "--json", "-"], tmp)
        rep = json.loads(r.stdout) if r.stdout.strip() else {}
        msg = rep.get("message", "") + r.stderr
        print("%s: exit %d, %s" % (name, r.returncode, msg.strip()[:300]))
        if r.returncode != 1:
            fail(name + " exit", 1, "%d (%s)" % (r.returncode, r.stderr.strip()))
        if "table 'n'" not in msg:
            fail(name + " message", "names table 'n'", msg)
        if "nan" in r.stdout.lower():
            fail(name + " report", "no NaN", r.stdout)

    # an integral constraint that calls the table and forces the path out of its grid
    # (mean height 0.75 > 0.65): exit 1, and the message names the table all the same
    write(scene, """[scene]
title = integral constraint through a table
interval = -0.8, 0.8
unknowns = y
integrand = sqrt(1 + y'^2)
[tables]
n = data/n.csv
[integrals]
area = y + 1e-9*n(x, y), 1.2
[boundary]
y = 0.3, 0.3
""")
    r = run(["solve", scene, "--quiet"], tmp)
    print("constraint_leaves: exit %d, %s" % (r.returncode, r.stderr.strip()[:200]))
    if r.returncode != 1 or "table 'n'" not in r.stderr:
        fail("constraint_leaves", "exit 1 naming table 'n'",
             "%d %s" % (r.returncode, r.stderr.strip()))

print("%d failure(s)" % failures if failures else "all table scene checks passed")
sys.exit(1 if failures else 0)

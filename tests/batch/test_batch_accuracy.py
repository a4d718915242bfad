#!/usr/bin/env python3
# tests/batch/test_batch_accuracy.py — every batch row reports the accuracy figure that
# `calcvar solve` reports for it (issue 28): over every combination of the things that
# decide the columns — a scene with or without [exact], with or without [report] entries
# and [integrals] multipliers; plain, --adapt or --tol; and --quiet, --warm with threads,
# a minimiser instead of Newton — the header has error_max_nodal exactly when the scene
# has [exact] and error_estimate exactly when it has not or --tol is given (the keys of
# `solve --json`), every converged row has a finite figure in each (or says in its message
# why there is no estimate, as solve does), a failed row has none, and each figure is the
# one `solve --set ... --json -` gives for that row (the same estimator on the same mesh:
# to the 4 digits batch writes, 1 % with --warm; under --tol, where batch starts each row from the previous row's
# mesh, both at most T and the row's true error, where known, below 10 T).
# Usage: test_batch_accuracy.py CALCVAR DATA_DIR
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

calcvar, data = sys.argv[1], sys.argv[2]
failures = 0
checks = 0


def check(what, ok, expected, actual):
    global failures, checks
    checks += 1
    if not ok:
        failures += 1
        print("FAIL %s\n  expected: %s\n  actual:   %s" % (what, expected, actual))


def run(args, timeout=120):
    r = subprocess.run([calcvar] + args, capture_output=True, text=True, timeout=timeout)
    check("sanitizers: %s" % " ".join(args[:2]),
          "Sanitizer" not in r.stderr and "runtime error:" not in r.stderr, "no finding",
          r.stderr[:500])
    return r


tmp = tempfile.mkdtemp(prefix="cvbatchacc")


def without_exact(name):
    """A copy of data/name with its [exact] section removed."""
    text = open(os.path.join(data, name)).read()
    text = re.sub(r"\n\[exact\]\n(?:[^\[\n][^\n]*\n|\n)*", "\n", text)
    path = os.path.join(tmp, name.replace(".scene", "_noexact.scene"))
    with open(path, "w") as f:
        f.write(text)
    return path


def table(name, header, rows):
    path = os.path.join(tmp, name)
    with open(path, "w") as f:
        f.write(header + "\n" + "".join(",".join(r) + "\n" for r in rows))
    return path


# (scene path, has [exact], table, rows as --set lists, minimiser allowed)
line_rows = [("1", "2", "1", "0"), ("-0.5", "1.5", "2", "1.5"), ("0.3", "-1", "0.7", "-2")]
chain_rows = [("1",), ("1.5",), ("3",)]
cat_rows = [("2",), ("3",), ("1.2",)]  # R = 1.2: no catenoid, the row fails
scenes = [
    (os.path.join(data, "line.scene"), True, "A,B,L,c", line_rows, True),
    (without_exact("line.scene"), False, "A,B,L,c", line_rows, True),
    (os.path.join(data, "chain.scene"), True, "c", chain_rows, False),
    (without_exact("chain.scene"), False, "c", chain_rows, False),
    (os.path.join(data, "catenoid.scene"), False, "R", cat_rows, True),
]
accuracy = [[], ["--adapt", "1e-6"], ["--tol", "1e-9"]]
extras = [[], ["--quiet"], ["--warm", "--threads", "2"], ["--method", "lbfgs"]]


def close(a, b, rel):
    return abs(a - b) <= rel * max(abs(a), abs(b)) + 1e-15


def true_error(js):
    return js.get("error", {}).get("max_nodal")


combos = 0
for path, has_exact, header, rows, minimiser in scenes:
    names = header.split(",")
    tab = table("t_%d.csv" % combos, header, rows)
    for acc in accuracy:
        for extra in extras:
            if "lbfgs" in extra and not minimiser:
                continue
            combos += 1
            tag = "%s %s %s" % (os.path.basename(path), " ".join(acc), " ".join(extra))
            r = run(["batch", path, tab] + acc + extra)
            check("%s: exit 0 or 1" % tag, r.returncode in (0, 1), "0 or 1",
                  (r.returncode, r.stderr[:300]))
            out = list(csv.DictReader(io.StringIO(r.stdout)))
            cols = r.stdout.splitlines()[0].split(",") if r.stdout else []
            want_nodal = has_exact
            want_est = (not has_exact) or "--tol" in acc
            check("%s: error_max_nodal column" % tag, ("error_max_nodal" in cols) == want_nodal,
                  want_nodal, cols)
            check("%s: error_estimate column" % tag, ("error_estimate" in cols) == want_est,
                  want_est, cols)
            check("%s: one row per input row" % tag, len(out) == len(rows), len(rows), len(out))
            tol = float(acc[1]) if "--tol" in acc else None
            for vals, row in zip(rows, out):
                sets = sum((["--set", "%s=%s" % (n, v)] for n, v in zip(names, vals)), [])
                s = run(["solve", path] + sets + acc + [e for e in extra if e not in
                                                         ("--warm", "--threads", "2")] +
                        ["--json", "-"])
                js = json.loads(s.stdout) if s.stdout.strip() else {}
                rtag = "%s row %s" % (tag, ",".join(vals))
                conv = row["status"] == "converged"
                check("%s: status as solve's" % rtag, row["status"] == js.get("status"),
                      js.get("status"), row["status"])
                for col, key in (("error_max_nodal", "nodal"), ("error_estimate", "est")):
                    if col not in cols:
                        continue
                    text = row[col]
                    if not conv:
                        check("%s: failed row, %s empty" % (rtag, col), text == "", "", text)
                        continue
                    jv = (true_error(js) if key == "nodal" else js.get("error_estimate"))
                    if text == "":
                        # no figure only where solve has none either, and the message says why
                        check("%s: %s given" % (rtag, col),
                              jv is None and "no error estimate" in row["message"],
                              "a number, or solve's reason", (row["message"], jv))
                        continue
                    v = float(text)
                    check("%s: %s finite" % (rtag, col), math.isfinite(v), "finite", v)
                    check("%s: solve reports %s too" % (rtag, col), jv is not None, "present", js)
                    if jv is None:
                        continue
                    if key == "est" and tol is not None:
                        check("%s: estimate <= T" % rtag, v <= tol and jv <= tol, tol, (v, jv))
                    elif tol is not None:  # the true error of both meshes
                        check("%s: true error < 10 T" % rtag, v < 10 * tol and jv < 10 * tol,
                              10 * tol, (v, jv))
                    else:
                        # batch writes 4 significant digits (%.3e); a warm start's Newton
                        # path ends within round-off of solve's (1e-12 here: 0.3 % apart)
                        rel = 1e-2 if "--warm" in extra else 1e-3
                        check("%s: %s as solve's" % (rtag, col), close(v, jv, rel), jv, v)

check("every combination ran", combos == 54, 54, combos)
print("%d checks, %d failures, %d combinations" % (checks, failures, combos))
sys.exit(1 if failures else 0)

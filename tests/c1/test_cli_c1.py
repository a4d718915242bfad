#!/usr/bin/env python3
# tests/c1/test_cli_c1.py — second derivatives through the calcvar command: closed forms
# (simply supported beam, cantilever with its natural conditions at the free end, a beam
# on an elastic foundation, a C0 and a C1 unknown coupled), the observed order of the C1
# elements of degrees 3, 5, 7 against theory H-6, `--tol` on the clamped elastica against
# an independent shooting reference, `check`, `equations`, the CSV slope column and --all.
# SPDX-License-Identifier: MIT
#
# usage: test_cli_c1.py CALCVAR DATA_DIR
import csv
import io
import json
import math
import os
import subprocess
import sys

calcvar, data = [os.path.abspath(a) for a in sys.argv[1:3]]
failures = 0


def check(what, ok, detail=""):
    global failures
    if not ok:
        failures += 1
        print("FAIL %s %s" % (what, detail))


def run(*args):
    r = subprocess.run([calcvar] + list(args), capture_output=True, text=True, timeout=240)
    return r.returncode, r.stdout, r.stderr


def scene(name):
    return os.path.join(data, name)


def solve_json(name, *opts):
    rc, out, err = run("solve", scene(name), "--json", "-", "--quiet", *opts)
    return rc, (json.loads(out) if out.strip() else {}), err


def solve_csv(name, *opts):
    rc, out, err = run("solve", scene(name), "--csv", "-", "--quiet", *opts)
    return rc, list(csv.reader(io.StringIO(out)))


# ---- simply supported beam: the quartic is in the quintic space (round-off), the cubic
# ---- elements are exact at the nodes (the Green's function of y'''' is piecewise cubic)
for deg, tol_nodal in ((3, 1e-15), (5, 1e-15), (7, 1e-15)):
    rc, j, err = solve_json("simply_supported_beam.scene", "--elements", "4", "--degree", str(deg))
    check("beam degree %d exit" % deg, rc == 0, err)
    if rc == 0:
        check("beam degree %d nodal" % deg, j["error"]["max_nodal"] <= tol_nodal, j["error"])
        check("beam degree %d Morse" % deg, j["morse_index"] == 0 and j["stationary_kind"] == "minimum")
        if deg > 3:  # the action of the exact quartic, -1/240, to round-off
            check("beam degree %d action" % deg, j["error"]["action"] <= 1e-16, j["error"])
        check("beam degree %d nodes" % deg, j["nodes"] == 4 * (deg - 1) // 2 + 1, j["nodes"])

# ---- --tol must see the path between the cubic's exact vertex values (theory H-7a): on
# ---- vertices alone it stopped at 4 x p3 with an estimate of 6e-14 and an action error of
# ---- 2.7e-6. The estimate must bound the true error inside the elements (sampled at 9
# ---- points per element from the CSV's values and slopes by the cubic Hermite
# ---- interpolant, the solution's own polynomial at degree 3) within a factor 10.
for deg in (3, 5):
    rc, j, err = solve_json("simply_supported_beam.scene", "--tol", "1e-10", "--degree", str(deg))
    check("beam --tol degree %d" % deg, rc == 0 and j["error"]["action"] <= 1e-9 and
          j["error_estimate"] <= 1e-10, (rc, err, j.get("error"), j.get("error_estimate")))
rc, rows = solve_csv("simply_supported_beam.scene", "--elements", "4", "--degree", "3")
# the same scene without [exact] (with it the report gives the true error, not an estimate)
bare = os.path.join(os.environ.get("TMPDIR", "/tmp"), "c1_beam_%d.scene" % os.getpid())
with open(scene("simply_supported_beam.scene")) as f:
    text = f.read()
with open(bare, "w") as f:
    f.write(text[:text.index("[exact]")])
r = subprocess.run([calcvar, "solve", bare, "--elements", "4", "--degree", "3", "--json", "-",
                    "--quiet"], capture_output=True, text=True, timeout=60)
os.unlink(bare)
rc2, j = r.returncode, (json.loads(r.stdout) if r.stdout.strip() else {})
if rc == 0 and rc2 == 0:
    pts = [tuple(float(v) for v in r) for r in rows[1:]]
    ex = lambda x: x * (1 - 2 * x * x + x ** 3) / 24
    true = 0.0
    for (x0, w0, s0), (x1, w1, s1) in zip(pts, pts[1:]):
        h = x1 - x0
        for k in range(1, 10):
            t = k / 10
            H = (2 * t ** 3 - 3 * t * t + 1) * w0 + (t ** 3 - 2 * t * t + t) * h * s0 + \
                (-2 * t ** 3 + 3 * t * t) * w1 + (t ** 3 - t * t) * h * s1
            true = max(true, abs(H - ex(x0 + t * h)))
    est = j.get("error_estimate", 0.0)
    check("beam 4 x p3 estimate sees the interior", true > 1e-6 and 0.1 * true <= est <= 10 * true,
          (true, est))
else:
    check("beam 4 x p3 csv/estimate", False, (rc, rc2, err))

# ---- cantilever: values, the CSV slope column, and the natural conditions at the free end
# ---- (moment EI w'' and shear EI w''' zero), read off the last element's quintic through
# ---- its three nodes' values and slopes (an independent Hermite reconstruction)
rc, rows = solve_csv("cantilever.scene")
check("cantilever exit", rc == 0)
if rc == 0:
    check("cantilever CSV header", rows[0] == ["x", "w", "w'"], rows[0])
    pts = [tuple(float(v) for v in r) for r in rows[1:]]
    EI, q, L = 2.0, 3.0, 1.5
    ex = lambda x: q * x * x * (6 * L * L - 4 * L * x + x * x) / (24 * EI)
    dex = lambda x: q * (12 * L * L * x - 12 * L * x * x + 4 * x ** 3) / (24 * EI)
    check("cantilever values", max(abs(w - ex(x)) for x, w, _ in pts) < 1e-14)
    check("cantilever slopes", max(abs(s - dex(x)) for x, _, s in pts) < 1e-13)
    # quintic through (x_k, w_k, w'_k), k = last three nodes: solve the 6x6 system
    last = pts[-3:]
    A, b = [], []
    for x, w, s in last:
        A.append([x ** k for k in range(6)])
        b.append(w)
        A.append([k * x ** (k - 1) if k else 0.0 for k in range(6)])
        b.append(s)
    n = 6
    for c in range(n):  # Gaussian elimination with partial pivoting
        p = max(range(c, n), key=lambda r: abs(A[r][c]))
        A[c], A[p], b[c], b[p] = A[p], A[c], b[p], b[c]
        for r in range(c + 1, n):
            f = A[r][c] / A[c][c]
            A[r] = [a - f * ac for a, ac in zip(A[r], A[c])]
            b[r] -= f * b[c]
    co = [0.0] * n
    for r in range(n - 1, -1, -1):
        co[r] = (b[r] - sum(A[r][k] * co[k] for k in range(r + 1, n))) / A[r][r]
    d2 = sum(k * (k - 1) * co[k] * L ** (k - 2) for k in range(2, 6))
    d3 = sum(k * (k - 1) * (k - 2) * co[k] * L ** (k - 3) for k in range(3, 6))
    scale = q * L * L / EI  # the size of w'' at the clamped end
    check("cantilever moment at the free end", abs(EI * d2) < 1e-9 * EI * scale, EI * d2)
    check("cantilever shear at the free end", abs(EI * d3) < 1e-8 * EI * scale / L, EI * d3)
rc, j, err = solve_json("cantilever.scene")
if rc == 0:
    U = q * q * L ** 5 / (40 * EI)  # the bending energy: the action is -U
    check("cantilever report", abs(j["report"]["bending"] - U) < 1e-13 * U, j.get("report"))
    check("cantilever no first-order energy", "energy" not in j and "momenta" not in j)

# ---- observed orders (theory H-6): max nodal error O(h^(p+1)), vertices O(h^(2p-2))
for name in ("foundation.scene", "mixed.scene"):
    rc, out, err = run("converge", scene(name), "--degree", "3,5,7", "--elements", "4",
                       "--levels", "4", "--json", "-")
    check("%s converge exit" % name, rc == 0, err)
    rows = json.loads(out) if rc == 0 else []
    for deg in (3, 5, 7):
        errs = [(r["elements"], r["error"]["max_nodal"]) for r in rows if r["degree"] == deg]
        # the last pair above the round-off floor
        good = [(e1, a, e2, b) for (e1, a), (e2, b) in zip(errs, errs[1:]) if b > 1e-12]
        if not good:
            check("%s degree %d: a pair of errors above round-off" % (name, deg), False, errs)
            continue
        e1, a, e2, b = good[-1]
        order = math.log(a / b) / math.log(e2 / e1)
        check("%s degree %d order %.2f (expected %d)" % (name, deg, order, deg + 1),
              abs(order - (deg + 1)) < 0.5, errs)

# ---- --tol on the clamped elastica, against shooting (elastica_ref.py: pure Python,
# ---- independent of calcvar)
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import elastica_ref  # noqa: E402

for T in (1e-6, 1e-8, 1e-10):
    rc, out, err = run("solve", scene("elastica.scene"), "--tol", str(T), "--json",
                       os.devnull, "--csv", "-", "--quiet")
    check("elastica --tol %g exit" % T, rc == 0, err)
    if rc != 0:
        continue
    pts = [(float(a), float(b)) for a, b, _ in list(csv.reader(io.StringIO(out)))[1:]]
    xs = [x for x, _ in pts]
    ref, ref_err = elastica_ref.reference(xs)
    check("elastica reference accuracy %.2g" % ref_err, ref_err < 1e-12)
    true = max(abs(y - r) for (_, y), r in zip(pts, ref))
    rc, j, _ = solve_json("elastica.scene", "--tol", str(T))
    est = j.get("error_estimate", float("nan"))
    check("elastica --tol %g: true error %.2g <= 10 T" % (T, true), true <= 10 * T)
    check("elastica --tol %g: estimate %.2g not far below the true error %.2g" % (T, est, true),
          est >= 0.1 * true)
    check("elastica --tol %g: degrees" % T, len(j.get("degrees", [])) == j.get("elements"))
    check("elastica --tol %g: minimum" % T, j.get("stationary_kind") == "minimum")

# ---- check: the C1 unknowns counted, the partials in y'' against finite differences
rc, out, err = run("check", scene("cantilever.scene"))
check("check exit", rc == 0, out + err)
check("check counts", "9 values + 9 slopes - 2 fixed at the ends = 16 unknowns" in out, out)
check("check slope line", "slope        w': 0 at x = 0, free (natural)" in out, out)
rc, out, err = run("check", scene("elastica.scene"))
check("check elastica derivatives", rc == 0 and "agree with finite differences" in out, out)

# ---- equations: the fourth-order Euler-Lagrange equation and Ostrogradsky's momenta
rc, out, err = run("equations", scene("cantilever.scene"), "--json", "-")
check("equations exit", rc == 0, err)
if rc == 0:
    e = json.loads(out)
    el = e["euler_lagrange"]["w"].replace(" ", "")
    check("equations EL", el == "2*w''''-3", el)
    check("equations momenta", e["momenta"]["w"].replace(" ", "") == "-2*w'''" and
          e["momenta_second"]["w"].replace(" ", "") == "2*w''", e)

# ---- --all: the straight column past its buckling load is a saddle, the two buckled
# ---- shapes are minima of equal action
rc, out, err = run("solve", scene("buckled.scene"), "--all", "--json", "-", "--quiet")
check("--all exit", rc == 0, err)
if rc == 0:
    sols = json.loads(out)["solutions"]
    kinds = sorted((s["morse_index"], round(s["action"], 9)) for s in sols)
    check("--all paths", len(sols) == 3 and kinds[0][0] == 0 and kinds[1][0] == 0 and
          kinds[2] == (1, 0.0) and abs(kinds[0][1] - kinds[1][1]) < 1e-9, kinds)

# ---- an integral constraint on C1 elements: Euler's load as the multiplier of the shortening
rc, j, err = solve_json("euler_load.scene", "--elements", "8", "--degree", "5")
check("euler load exit", rc == 0, err)
if rc == 0:
    mu = j["multipliers"]["shortening"]
    check("euler load multiplier %.12g" % mu, abs(mu + math.pi ** 2) < 1e-8, j)
    check("euler load shape", j["error"]["max_nodal"] < 1e-8 and j["morse_index"] == 0, j)

# ---- batch: rows of (q, EI) against the closed-form action and bending energy
table = os.path.join(os.environ.get("TMPDIR", "/tmp"), "c1_rows_%d.csv" % os.getpid())
with open(table, "w") as f:
    f.write("q,EI\n1,1\n3,2\n5,0.5\n")
rc, out, err = run("batch", scene("cantilever.scene"), table)
os.unlink(table)
check("batch exit", rc == 0, err)
for row in (list(csv.DictReader(io.StringIO(out))) if rc == 0 else []):
    q_, EI_ = float(row["q"]), float(row["EI"])
    U = q_ * q_ * 1.5 ** 5 / (40 * EI_)
    check("batch row q=%g" % q_, abs(float(row["action"]) + U) < 1e-13 * U and
          abs(float(row["bending"]) - U) < 1e-13 * U, row)

# ---- a slope line that depends on a parameter: batch rows and --continue reach the
# ---- elastica of elastica.scene (t = 1) on the same mesh
rc, j, err = solve_json("elastica.scene", "--elements", "8", "--degree", "5")
A1 = j.get("action", math.nan)
table = os.path.join(os.environ.get("TMPDIR", "/tmp"), "c1_family_%d.csv" % os.getpid())
with open(table, "w") as f:
    f.write("t\n0.5\n1\n")
rc, out, err = run("batch", scene("elastica_family.scene"), table)
os.unlink(table)
rows = list(csv.DictReader(io.StringIO(out))) if rc == 0 else []
check("family batch", rc == 0 and len(rows) == 2 and abs(float(rows[1]["action"]) - A1) < 1e-12
      and float(rows[0]["action"]) < A1, (rc, err, rows, A1))
rc, j, err = solve_json("elastica_family.scene", "--continue", "t=0.1:1")
check("family --continue", rc == 0 and abs(j.get("action", math.nan) - A1) < 1e-12 and
      j.get("morse_index") == 0, (rc, err, j.get("action"), A1))

print("%d failure(s)" % failures)
sys.exit(1 if failures else 0)

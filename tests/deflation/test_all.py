#!/usr/bin/env python3
# tests/deflation/test_all.py — `calcvar solve SCENE --all` against answers computed here,
# independently of calcvar: Bratu's two paths (closed form, both roots of
# th = sqrt(2) cosh(th/4)), the two catenaries between rings (both roots of c cosh(1/c) = 2),
# the pendulum's swings from 0 to 0.5 in time 10 (RK4 shooting with the Jacobi equation
# for the conjugate points), a convex action (exactly one path), no path listed twice,
# `--max 1` gives the lowest action, the CSV `solution` column, bad input.
# SPDX-License-Identifier: MIT
#
# usage: test_all.py CALCVAR DATA_DIR
import csv
import io
import json
import math
import os
import subprocess
import sys
import tempfile

calcvar, data = [os.path.abspath(a) for a in sys.argv[1:3]]
failures = checks = 0


def check(what, ok, detail=""):
    global failures, checks
    checks += 1
    if not ok:
        failures += 1
        print("FAIL %s\n  %s" % (what, detail))


def run(*args, expect_rc=0):
    r = subprocess.run([calcvar] + list(args), capture_output=True, text=True, timeout=300)
    check(" ".join(args) + " sanitizers",
          "Sanitizer" not in r.stderr and "runtime error:" not in r.stderr, r.stderr[:2000])
    check(" ".join(args) + " exit status", r.returncode == expect_rc,
          "expected %d, got %d; stderr: %s" % (expect_rc, r.returncode, r.stderr.strip()))
    return r


def solve_all(scene, *extra):
    r = run("solve", os.path.join(data, scene), "--all", "--json", "-", *extra)
    return json.loads(r.stdout) if r.returncode == 0 else None


def bisect(f, a, b, n=200):
    fa = f(a)
    for _ in range(n):
        m = 0.5 * (a + b)
        fm = f(m)
        if fa * fm <= 0:
            b = m
        else:
            a, fa = m, fm
    return 0.5 * (a + b)


def nodes(sol):
    return sol["_x"], sol["_y"]


def with_nodes(scene, *extra):
    """JSON and CSV of one run: each solution gets its nodal x, y from the CSV."""
    with tempfile.TemporaryDirectory() as tmp:
        c = os.path.join(tmp, "all.csv")
        r = run("solve", os.path.join(data, scene), "--all", "--json", "-", "--csv", c, *extra)
        if r.returncode != 0:
            return None
        out = json.loads(r.stdout)
        rows = list(csv.reader(open(c)))
    head = rows[0]
    check(scene + " CSV first column", head[0] == "solution", head)
    for k, sol in enumerate(out["solutions"]):
        mine = [row for row in rows[1:] if row[0] == str(k + 1)]
        sol["_x"] = [float(row[1]) for row in mine]
        sol["_y"] = [float(row[2]) for row in mine]
        check(scene + " CSV rows of solution %d" % (k + 1), len(mine) == sol["nodes"],
              "%d rows, %d nodes" % (len(mine), sol["nodes"]))
    return out


def common(out, scene):
    sols = out["solutions"]
    acts = [s["action"] for s in sols]
    check(scene + " ordered by action", acts == sorted(acts), acts)
    for s in sols:
        check(scene + " converged", s["status"] == "converged", s["status"])
        check(scene + " Morse index and kind", "morse_index" in s and "stationary_kind" in s, s)
    srch = out["search"]
    for key in ("starts", "failed", "duplicates", "found", "stopped"):
        check(scene + " search." + key, key in srch, srch)
    check(scene + " search.found", srch.get("found") == len(sols), srch)
    # no path twice: every pair differs by far more than the error estimates
    for i in range(len(sols)):
        for j in range(i):
            d = max(abs(a - b) for a, b in zip(sols[i]["_y"], sols[j]["_y"]))
            check(scene + " paths %d and %d distinct" % (j + 1, i + 1), d > 1e-3, d)


# ---- Bratu, lambda = 1: both paths to 1e-10 of the closed form
out = with_nodes("bratu.scene")
if out:
    common(out, "bratu")
    sols = out["solutions"]
    check("bratu: two paths", len(sols) == 2, len(sols))
    g = lambda t: t - math.sqrt(2.0) * math.cosh(t / 4)
    thetas = [bisect(g, 0.5, 4.0), bisect(g, 4.0, 20.0)]
    for k, (s, th, morse) in enumerate(zip(sols, thetas, (0, 1))):
        x, y = nodes(s)
        exact = [-2 * math.log(math.cosh((xx - 0.5) * th / 2) / math.cosh(th / 4)) for xx in x]
        err = max(abs(a - b) for a, b in zip(y, exact))
        check("bratu path %d to 1e-10 of the closed form" % (k + 1), err < 1e-10, err)
        check("bratu path %d Morse index %d" % (k + 1, morse), s["morse_index"] == morse, s)
    check("bratu kinds", [s["stationary_kind"] for s in sols] == ["minimum", "saddle"], sols)

# ---- Bratu with --tol: every path on its own hp mesh, true error <= 10 T, estimate honest
for T in (1e-8, 1e-11):
    out = with_nodes("bratu.scene", "--tol", repr(T))
    check("bratu --tol %g: ran" % T, out is not None)
    if not out:
        continue
    sols = out["solutions"]
    check("bratu --tol %g: two paths" % T, len(sols) == 2, len(sols))
    for k, (s, th) in enumerate(zip(sols, thetas)):
        x, y = nodes(s)
        exact = [-2 * math.log(math.cosh((xx - 0.5) * th / 2) / math.cosh(th / 4)) for xx in x]
        err = max(abs(a - b) for a, b in zip(y, exact))
        est = s.get("error_estimate", -1)
        check("bratu --tol %g path %d: true error %.2g <= 10 T" % (T, k + 1, err), err <= 10 * T)
        check("bratu --tol %g path %d: estimate %.2g <= T, >= 0.1 x true" % (T, k + 1, est),
              0 <= est <= T and est >= 0.1 * err)
        check("bratu --tol %g path %d: degrees and nodes" % (T, k + 1),
              "degrees" in s and s["nodes"] == 1 + sum(s["degrees"])
              and s["degree"] == max(s["degrees"]), s.get("degrees"))

# ---- catenary between rings at x = -1, 1 of radius 2: shallow minimum, deep saddle
out = with_nodes("catenary_two.scene")
if out:
    common(out, "catenary")
    sols = out["solutions"]
    check("catenary: two paths", len(sols) == 2, len(sols))
    f = lambda c: c * math.cosh(1 / c) - 2
    cs = [bisect(f, 0.9, 5.0), bisect(f, 0.2, 0.85)]  # shallow (smaller area) first
    for k, (s, c, morse) in enumerate(zip(sols, cs, (0, 1))):
        x, y = nodes(s)
        err = max(abs(yy - c * math.cosh(xx / c)) for xx, yy in zip(x, y))
        area = c * (1 + c / 2 * math.sinh(2 / c))
        check("catenary path %d vs c cosh(x/c), c = %.6f" % (k + 1, c), err < 1e-8, err)
        check("catenary path %d action" % (k + 1), abs(s["action"] - area) < 1e-9,
              (s["action"], area))
        check("catenary path %d Morse index %d" % (k + 1, morse), s["morse_index"] == morse, s)


# ---- pendulum th'' = -sin th from 0 to 0.5 in time 10: shooting with RK4 on the
# equation and its Jacobi equation h'' = -cos(th) h, h(0) = 0, h'(0) = 1; the number of
# zeros of h in (0, 10) is the number of conjugate points = the Morse index.
def shoot(v, T=10.0, N=2000):
    h = T / N

    def f(s):
        th, w, hj, dj = s
        return (w, -math.sin(th), dj, -math.cos(th) * hj)

    s = (0.0, v, 0.0, 1.0)
    zeros, prev, amax = 0, 0.0, 0.0
    for i in range(N):
        k1 = f(s)
        k2 = f(tuple(a + h / 2 * b for a, b in zip(s, k1)))
        k3 = f(tuple(a + h / 2 * b for a, b in zip(s, k2)))
        k4 = f(tuple(a + h * b for a, b in zip(s, k3)))
        s = tuple(a + h / 6 * (b + 2 * c + 2 * d + e) for a, b, c, d, e in zip(s, k1, k2, k3, k4))
        if 0 < i < N - 1 and (s[2] > 0) != (prev > 0):
            zeros += 1
        prev = s[2]
        amax = max(amax, abs(s[0]))
    return s[0] - 0.5, zeros, amax


# every root of th(10; v) = 0.5 with |v| < 2 (beyond, the pendulum goes over the top and
# never comes back to 0.5): a grid, finer towards the separatrix v = +-2
vs = sorted(set([-1.9999 + 3.9998 * i / 200 for i in range(201)] +
                [sg * 2 * (1 - 10 ** (-e / 10)) for sg in (1, -1) for e in range(30, 130, 2)]))
fs = [shoot(v)[0] for v in vs]
roots = []
for i in range(len(vs) - 1):
    if fs[i] * fs[i + 1] < 0:
        v = bisect(lambda u: shoot(u)[0], vs[i], vs[i + 1], 50)
        _, z, amax = shoot(v)
        roots.append((v, z, amax))
out = with_nodes("pendulum_swings.scene")
if out:
    common(out, "pendulum")
    sols = out["solutions"]
    check("pendulum: shooting finds 5 paths", len(roots) == 5, roots)
    check("pendulum: every path found", len(sols) == len(roots), (len(sols), roots))
    # match by the velocity at t = 0 (slope of the first element) and the amplitude
    for v, z, amax in roots:
        best = None
        for s in sols:
            x, y = nodes(s)
            a = max(abs(t) for t in y)
            if best is None or abs(a - amax) < abs(best[0] - amax):
                best = (a, s)
        check("pendulum path v0 = %.6f found (amplitude %.5f)" % (v, amax),
              best is not None and abs(best[0] - amax) < 1e-3, best and best[0])
        if best:
            check("pendulum path v0 = %.6f: Morse index %d = conjugate points" % (v, z),
                  best[1]["morse_index"] == z, (best[1]["morse_index"], z))


# ---- the mirage, n(y) = 1 + a tanh(y/b), ends at height h, L apart: a ray turning at
# height t keeps Snell's invariant n / sqrt(1 + y'^2) = n(t), so it covers the horizontal
# distance D(t) = 2 int_t^h n(t) / sqrt(n(y)^2 - n(t)^2) dy (y = t + s^2 removes the
# inverse square root). The rays are the roots of D(t) = L, found here by bisection.
A, B, H, L = 0.01, 0.2, 1.0, 20.0
nidx = lambda y: 1 + A * math.tanh(y / B)


def reach(t, m=400):
    C, S = nidx(t), math.sqrt(H - t)
    def g(s):
        if s == 0:
            dn = A / B / math.cosh(t / B) ** 2
            return 2 * C / math.sqrt(2 * C * dn)
        y = t + s * s
        return 2 * s * C / math.sqrt(nidx(y) ** 2 - C * C)
    hs = S / m
    tot = g(0) + g(S) + sum((4 if k % 2 else 2) * g(k * hs) for k in range(1, m))
    return 2 * tot * hs / 3


ts = [-0.6 + 1.5999 * k / 400 for k in range(401)]
ds = [reach(t) - L for t in ts]
turns = [bisect(lambda u: reach(u) - L, ts[k], ts[k + 1], 60)
         for k in range(len(ts) - 1) if ds[k] * ds[k + 1] < 0]
mirage = os.path.join(os.path.dirname(data), "..", "examples", "scenes", "mirage.scene")
with tempfile.TemporaryDirectory() as tmp:
    c = os.path.join(tmp, "m.csv")
    r = run("solve", mirage, "--all", "--json", "-", "--csv", c)  # default work limit
    if r.returncode == 0:
        out = json.loads(r.stdout)
        rows = list(csv.reader(open(c)))[1:]
        lows = sorted(min(float(row[2]) for row in rows if row[0] == str(k + 1))
                      for k in range(len(out["solutions"])))
        check("mirage: three rays by Snell's invariant", len(turns) == 3, turns)
        check("mirage: every ray found", len(lows) == len(turns), (lows, turns))
        for t, lo in zip(sorted(turns), lows):
            check("mirage: a ray turns at %.6f" % t, abs(t - lo) < 1e-5, (t, lo))
        kinds = [s_["morse_index"] for s_ in out["solutions"]]
        check("mirage: two minima and a saddle", sorted(kinds) == [0, 0, 1], kinds)


# ---- constraints. Integral: int y'^2/2 on [0, pi] with int y^2 = 1 is stationary on
# y = +-sqrt(2/pi) sin(k x), action k^2/2, Morse index k - 1 (on the constraint's tangent
# space). Pointwise: great-circle arcs on the unit sphere (x^2 + y^2 + z^2 = 1).
def table(scene, *extra):
    with tempfile.TemporaryDirectory() as tmp:
        c = os.path.join(tmp, "t.csv")
        r = run("solve", os.path.join(data, scene), "--all", "--json", "-", "--csv", c, *extra)
        if r.returncode != 0:
            return None, None
        return json.loads(r.stdout), list(csv.reader(open(c)))


out, rows = table("eigen_integral.scene", "--max", "6", "--work", "100")
if out:
    sols = out["solutions"]
    check("eigen: six paths", len(sols) == 6, len(sols))
    for k, s_ in enumerate(sols):
        m = k // 2 + 1
        pts = [(float(r_[1]), float(r_[2])) for r_ in rows[1:] if r_[0] == str(k + 1)]
        sign = 1 if sum(y * math.sin(m * x) for x, y in pts) > 0 else -1
        err = max(abs(y - sign * math.sqrt(2 / math.pi) * math.sin(m * x)) for x, y in pts)
        check("eigen path %d: +-sqrt(2/pi) sin(%d x)" % (k + 1, m), err < 1e-8, err)
        check("eigen path %d: action %d^2/2" % (k + 1, m), abs(s_["action"] - m * m / 2) < 1e-9,
              s_["action"])
        check("eigen path %d: Morse index %d" % (k + 1, m - 1), s_["morse_index"] == m - 1, s_)

out, rows = table("sphere_arcs.scene")
if out:
    sols = out["solutions"]
    check("sphere: both arcs", len(sols) == 2, len(sols))
    for k, (ang, morse) in enumerate(((math.pi / 2, 0), (-3 * math.pi / 2, 1))):
        if k >= len(sols):
            break
        pts = [[float(v) for v in r_[1:5]] for r_ in rows[1:] if r_[0] == str(k + 1)]
        err = max(max(abs(x - math.cos(ang * t)), abs(y - math.sin(ang * t)), abs(z))
                  for t, x, y, z in pts)
        check("sphere arc %d: the great circle of angle %.4f" % (k + 1, ang), err < 1e-8, err)
        check("sphere arc %d: action" % (k + 1), abs(sols[k]["action"] - ang * ang / 2) < 1e-9,
              sols[k]["action"])
        check("sphere arc %d: Morse index %d" % (k + 1, morse), sols[k]["morse_index"] == morse,
              sols[k])

# ---- a convex action: exactly one path
out = with_nodes("convex.scene")
if out:
    common(out, "convex")
    check("convex: exactly one path", len(out["solutions"]) == 1, len(out["solutions"]))
    check("convex: a minimum", out["solutions"][0]["stationary_kind"] == "minimum", out)


# ---- nothing converged (Bratu has no solution beyond lambda = 3.51...): exit 1, a
# sentence on stderr, a JSON with no solutions and the search record
with tempfile.TemporaryDirectory() as tmp:
    j = os.path.join(tmp, "none.json")
    r = run("solve", os.path.join(data, "bratu.scene"), "--all", "--set", "lambda=4",
            "--json", j, expect_rc=1)
    check("no path: a sentence", "no converged stationary path" in r.stderr, r.stderr)
    if os.path.exists(j):
        d = json.load(open(j))
        check("no path: empty list", d.get("solutions") == [] and d["search"]["found"] == 0, d)

# ---- with --adapt: both catenaries, each on its own adapted mesh with its own estimate
r = run("solve", os.path.join(data, "catenary_two.scene"), "--all", "--adapt", "1e-9",
        "--elements", "8", "--degree", "4", "--json", "-")
if r.returncode == 0:
    sols = json.loads(r.stdout)["solutions"]
    check("adapt: two paths", len(sols) == 2, len(sols))
    check("adapt: Morse 0 and 1", [s_["morse_index"] for s_ in sols] == [0, 1], sols)
    f = lambda c: c * math.cosh(1 / c) - 2
    for s_, c in zip(sols, (bisect(f, 0.9, 5.0), bisect(f, 0.2, 0.85))):
        area = c * (1 + c / 2 * math.sinh(2 / c))
        check("adapt: estimate at most the tolerance", s_.get("error_estimate", 1) <= 1e-9, s_)
        check("adapt: action", abs(s_["action"] - area) < 1e-8, (s_["action"], area))

# ---- --max 1 returns the lowest-action path found
for scene in ("bratu.scene", "pendulum_swings.scene", "catenary_two.scene"):
    full = solve_all(scene)
    one = solve_all(scene, "--max", "1")
    if full and one:
        check(scene + " --max 1: one path", len(one["solutions"]) == 1, one)
        check(scene + " --max 1: the lowest action found",
              abs(one["solutions"][0]["action"] - full["solutions"][0]["action"]) < 1e-9,
              (one["solutions"][0]["action"], full["solutions"][0]["action"]))

# ---- the summary: one line per path with action, Morse index, kind
r = run("solve", os.path.join(data, "bratu.scene"), "--all")
lines = [l for l in r.stdout.splitlines() if l.strip().startswith("path ")]
check("summary: a line per path", len(lines) == 2, r.stdout)
check("summary: action, Morse index, kind",
      all("action" in l and "Morse index" in l for l in lines) and "saddle" in lines[1], lines)

# ---- bad input: exit 2, nothing written
with tempfile.TemporaryDirectory() as tmp:
    j = os.path.join(tmp, "out.json")
    run("solve", os.path.join(data, "bratu.scene"), "--max", "2", "--json", j, expect_rc=2)
    run("solve", os.path.join(data, "bratu.scene"), "--all", "--max", "0", expect_rc=2)
    run("solve", os.path.join(data, "bratu.scene"), "--all", "--method", "lbfgs", "--json", j,
        expect_rc=2)
    check("bad input: no file written", not os.path.exists(j))

print("%d checks, %d failures" % (checks, failures))
sys.exit(1 if failures else 0)

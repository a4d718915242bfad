#!/usr/bin/env python3
# tests/obstacle/test_obstacles.py — inequality constraints (docs/obstacles.md, theory
# OB-1 .. OB-4) through `calcvar solve --json/--csv` against closed forms:
#  - the path over the bump y >= 1 - x^2 from (-2, 0) to (2, 0): tangent lines and the
#    parabola, contact [sqrt(3) - 2, 2 - sqrt(3)], length 4.49071475164684, multiplier
#    lambda = (F_y')' = -2 / (1 + 4 x^2)^(3/2) on contact and 0 off it;
#  - the same mirrored, y <= -(1 - x^2): the multiplier has the other sign;
#  - the detour around the unit disk, x^2 + y^2 >= 1: length 2 sqrt(3) + pi/3, contact
#    [-1/2, 1/2];
#  - the active-set iteration count against mesh size (mesh independence);
#  - bad input with its line (exit 2) and an infeasible pair of obstacles (exit 1).
#  - the chain resting on the ground (catenary arcs tangent to y = 0 and a flat part);
#  - the bump given as a [tables] terrain (a spline through 1 - x^2, which it reproduces);
# Tolerances: --tol T bounds the nodal error; the action's error is far smaller (it is
# stationary); contact ends come from a polynomial fitted to the gap at the free nodes
# beside them (OB-4): at --tol 1e-10 measured 5.6e-13 (bump), 4.0e-12 (disk), 2.5e-11
# (chain); the bound is the 1e-9.
# SPDX-License-Identifier: MIT
import json, math, os, subprocess, sys, tempfile

calcvar = os.path.abspath(sys.argv[1])
fails = 0


def check(what, ok, detail=""):
    global fails
    if not ok:
        fails += 1
        print("FAIL", what, detail)


def run(text, *args):
    with tempfile.NamedTemporaryFile("w", suffix=".scene", delete=False) as f:
        f.write(text)
        name = f.name
    try:
        p = subprocess.run([calcvar, "solve", name, *args], capture_output=True, text=True)
        return p, name
    finally:
        os.unlink(name)


BUMP = """[scene]
title     = over a bump
interval  = -2, 2
unknowns  = y
integrand = sqrt(1 + y'^2)
[boundary]
y = 0, 0
[constraints]
over = %s
[guess]
y = %s
"""
xt = math.sqrt(3) - 2
s = 4 - 2 * math.sqrt(3)
L_BUMP = 4.49071475164684


def exact_bump(x):
    if x < xt:
        return s * (x + 2)
    if x > -xt:
        return s * (2 - x)
    return 1 - x * x


for sign, G, guess in ((1, "y - (1 - x^2) >= 0", "1.5*(1 - x^2/4)"),
                       (-1, "y + (1 - x^2) <= 0", "-1.5*(1 - x^2/4)")):
    p, _ = run(BUMP % (G, guess), "--tol", "1e-10", "--json", "-")
    check("bump %d exit" % sign, p.returncode == 0, p.stderr)
    r = json.loads(p.stdout)
    check("bump %d converged" % sign, r["status"] == "converged", r["message"])
    check("bump %d length" % sign, abs(r["action"] - L_BUMP) <= 1e-9, r["action"])
    check("bump %d minimum" % sign, r["morse_index"] == 0, r["morse_index"])
    iv = r["contact"]["over"]
    check("bump %d one contact interval" % sign, len(iv) == 1, iv)
    check("bump %d contact ends" % sign,
          abs(iv[0][0] - xt) <= 1e-9 and abs(iv[0][1] + xt) <= 1e-9, iv)
    p, _ = run(BUMP % (G, guess), "--tol", "1e-10", "--csv", "-")
    rows = [list(map(float, l.split(","))) for l in p.stdout.split("\n")[1:] if l]
    err = max(abs(y - sign * exact_bump(x)) for x, y, _ in rows)
    check("bump %d path" % sign, err <= 1e-9, err)
    for x, y, lam in rows:
        inside = abs(x) < -xt - 0.05  # the multiplier is less accurate next to the ends
        outside = abs(x) > -xt + 1e-3
        want = -sign * 2 / (1 + 4 * x * x) ** 1.5
        if inside and abs(lam - want) > 1e-4 * abs(want):  # measured 2.5e-5 relative
            check("bump %d multiplier at %g" % (sign, x), False, (lam, want))
            break
        if outside and lam != 0.0:
            check("bump %d multiplier off contact at %g" % (sign, x), False, lam)
            break

# The unit disk: the path stays outside x^2 + y^2 >= 1.
DISK = BUMP.replace("over a bump", "around the disk") % ("x^2 + y^2 - 1 >= 0", "1.5*(1 - x^2/4)")
p, _ = run(DISK, "--tol", "1e-10", "--json", "-")
r = json.loads(p.stdout)
check("disk converged", r["status"] == "converged", r["message"])
check("disk length", abs(r["action"] - (2 * math.sqrt(3) + math.pi / 3)) <= 1e-9, r["action"])
iv = r["contact"]["over"]
check("disk contact", len(iv) == 1 and abs(iv[0][0] + 0.5) <= 1e-9 and abs(iv[0][1] - 0.5) <= 1e-9,
      iv)

# The chain of length 3.5 between posts of height 1 at x = -1, 1 resting on y >= 0:
# catenary arcs y = a (cosh((|x| - c)/a) - 1) tangent to the ground at |x| = c, with
# a = 0.131597618588324, c = 0.626080413385082 solving a (cosh((1 - c)/a) - 1) = 1 and
# 2 c + 2 a sinh((1 - c)/a) = 3.5 (checked here by bisection); lambda_ground = -1 on the
# flat part (the ground carries the chain's weight), the length multiplier is a.
def chain_ac():
    def c_of(a):  # the arc from the ground to the post's height 1: (1 - c)/a = acosh(1 + 1/a)
        return 1 - a * math.acosh(1 + 1 / a)
    lo, hi = 0.05, 0.5  # total length 2 c + 2 a sinh(acosh(1 + 1/a)) decreases in a
    for _ in range(200):
        a = (lo + hi) / 2
        if 2 * c_of(a) + 2 * a * math.sinh(math.acosh(1 + 1 / a)) > 3.5:
            lo = a
        else:
            hi = a
    return a, c_of(a)


A_CH, C_CH = chain_ac()
CHAIN = """[scene]
title     = chain on the ground
interval  = -1, 1
unknowns  = y
integrand = y*sqrt(1 + y'^2)
[boundary]
y = 1, 1
[integrals]
length = sqrt(1 + y'^2), 3.5
[constraints]
ground = y >= 0
[guess]
y = 1 - 0.5*cos(pi*x/2)
"""
p, _ = run(CHAIN, "--tol", "1e-10", "--json", "-")
r = json.loads(p.stdout)
check("chain converged", r["status"] == "converged", r["message"])
check("chain a, c", abs(A_CH - 0.131597618588324) <= 1e-12 and abs(C_CH - 0.626080413385082) <= 1e-12,
      (A_CH, C_CH))
iv = r["contact"]["ground"]
check("chain contact", len(iv) == 1 and abs(iv[0][0] + C_CH) <= 1e-9 and abs(iv[0][1] - C_CH) <= 1e-9,
      (iv, C_CH))
check("chain length multiplier", abs(r["multipliers"]["length"] - A_CH) <= 1e-9, r["multipliers"])
p, _ = run(CHAIN, "--tol", "1e-10", "--csv", "-")
rows = [list(map(float, l.split(","))) for l in p.stdout.split("\n")[1:] if l]
err = max(abs(y - (A_CH * (math.cosh((abs(x) - C_CH) / A_CH) - 1) if abs(x) > C_CH else y))
          for x, y, _ in rows)
check("chain path", err <= 1e-9, err)
flat = [lam for x, y, lam in rows if abs(x) < C_CH - 0.05]
check("chain ground multiplier", flat and max(abs(l + 1) for l in flat) <= 1e-6, flat[:3])
check("chain ground multiplier off contact",
      all(lam == 0.0 for x, y, lam in rows if abs(x) > C_CH + 1e-3), "")

# The bump as a terrain given as data: [tables] h = 1 - x^2 on 45 points of [-2.2, 2.2]; the
# spline through it (not-a-knot) reproduces a quadratic, so the answer is the bump's.
with tempfile.TemporaryDirectory() as tmp:
    with open(os.path.join(tmp, "h.csv"), "w") as f:
        f.write("x, h\n")
        for i in range(45):
            x = -2.2 + 0.1 * i
            f.write("%.17g, %.17g\n" % (x, 1 - x * x))
    sc = os.path.join(tmp, "terrain.scene")
    with open(sc, "w") as f:
        f.write((BUMP % ("y - h(x) >= 0", "1.5*(1 - x^2/4)")).replace("[boundary]",
                "[tables]\nh = h.csv\n[boundary]"))
    p = subprocess.run([calcvar, "solve", sc, "--tol", "1e-10", "--json", "-"], capture_output=True,
                       text=True)
    r = json.loads(p.stdout) if p.stdout else {}
    check("terrain converged", r.get("status") == "converged", p.stderr + str(r.get("message")))
    if r.get("status") == "converged":
        check("terrain length", abs(r["action"] - L_BUMP) <= 1e-9, r["action"])
        iv = r["contact"]["over"]
        check("terrain contact", len(iv) == 1 and abs(iv[0][0] - xt) <= 1e-9 and
              abs(iv[0][1] + xt) <= 1e-9, iv)

# --all around the disk: the path over it and its mirror image under it (OB-7), both
# minima of length 2 sqrt(3) + pi/3.
p, _ = run(DISK, "--all", "--tol", "1e-10", "--json", "-")
r = json.loads(p.stdout)
paths = r.get("solutions", [])
check("disk --all two paths", len(paths) == 2, [q.get("action") for q in paths])
for q in paths:
    check("disk --all length", abs(q["action"] - (2 * math.sqrt(3) + math.pi / 3)) <= 1e-9, q)
    check("disk --all minimum", q.get("morse_index") == 0, q)

# Mesh independence of the active-set iteration (from the guess above the bump): at most
# 50 Newton iterations in all at every size from 10^2 to 10^5 elements of degree 1
# (measured: 9, 32, 33, 39 — the exact iteration alone converges at 10^2; above, the
# penalty path-following's stages take 4 .. 10 each; 9, 40, 47, 56 before OB-3b). An iteration that moved the contact
# set by one node per step, as the exact iteration does from a set that is too large,
# would need ~1000 steps at 10^5 elements.
its = {}
for E in (100, 1000, 10000, 100000):
    p, _ = run(BUMP % ("y - (1 - x^2) >= 0", "1.5*(1 - x^2/4)"), "--elements", str(E),
               "--degree", "1", "--json", "-")
    r = json.loads(p.stdout)
    check("bump E=%d converged" % E, r["status"] == "converged", r["message"])
    its[E] = r["iterations"]
check("mesh independence", max(its.values()) <= 50, its)
print("iterations against elements:", its)

# The NLopt engines take the inequality natively (OB-1): CCSAQ and AUGLAG reach the
# discrete minimum Newton reaches on the same mesh (40 elements of degree 2), whose error
# against the exact path is 3.0e-4; their answer must be within 2e-5 of Newton's action.
p, _ = run(BUMP % ("y - (1 - x^2) >= 0", "1.5*(1 - x^2/4)"), "--elements", "40", "--degree", "2",
           "--json", "-")
ref = json.loads(p.stdout)["action"]
for m in ("ccsaq", "auglag"):
    p, _ = run(BUMP % ("y - (1 - x^2) >= 0", "1.5*(1 - x^2/4)"), "--elements", "40", "--degree",
               "2", "--method", m, "--json", "-")
    r = json.loads(p.stdout)
    check("%s converged" % m, r["status"] == "converged", r["message"])
    check("%s action" % m, abs(r["action"] - ref) <= 2e-5,
          (r["action"], ref))
p, _ = run(BUMP % ("y - (1 - x^2) >= 0", "1"), "--method", "lbfgs")
check("lbfgs refuses constraints", p.returncode == 2 and "cannot impose" in p.stderr, p.stderr)

# batch: a bump of height H per row, y >= H (1 - x^2). The tangent from (-2, 0) touches at
# x_t = sqrt(3) - 2 whatever H (x_t^2 + 4 x_t + 1 = 0), so the length is
# 2 sqrt((x_t + 2)^2 + H^2 (1 - x_t^2)^2) + 2 int_0^X sqrt(1 + 4 H^2 x^2) dx with X = -x_t,
# the integral X/2 sqrt(1 + 4 H^2 X^2) + asinh(2 H X) / (4 H).
def bump_length(H):
    X = -xt
    return 2 * math.hypot(xt + 2, H * (1 - xt * xt)) + 2 * (
        X / 2 * math.sqrt(1 + 4 * H * H * X * X) + math.asinh(2 * H * X) / (4 * H))


BATCH = BUMP.replace("[boundary]", "[parameters]\nH = 1\n[boundary]") % (
    "y - H*(1 - x^2) >= 0", "(H + 0.5)*(1 - x^2/4)")
with tempfile.TemporaryDirectory() as tmp:
    sb, tb = os.path.join(tmp, "b.scene"), os.path.join(tmp, "t.csv")
    open(sb, "w").write(BATCH)
    open(tb, "w").write("H\n1\n1.5\n0.5\n")
    p = subprocess.run([calcvar, "batch", sb, tb, "--tol", "1e-10"], capture_output=True, text=True)
    lines = p.stdout.strip().split("\n")
    head = lines[0].split(",")
    check("batch exit", p.returncode == 0 and len(lines) == 4, p.stdout + p.stderr)
    for line in lines[1:]:
        row = dict(zip(head, line.split(",")))
        L = bump_length(float(row["H"]))
        check("batch H=%s" % row["H"], row["status"] == "converged" and
              abs(float(row["action"]) - L) <= 1e-9, (row, L))
check("bump length formula", abs(bump_length(1.0) - L_BUMP) <= 1e-13, bump_length(1.0))

# The Bryson-Denham problem: F = y''^2/2, y(0) = y(1) = 0, y'(0) = 1, y'(1) = -1, y <= l
# (C1 elements with an obstacle). For l = 1/9 <= 1/6 the path is a cubic up to t = 3l, on
# the obstacle to 1 - 3l, and the mirror cubic: action 4/(9l) = 4. With 1/3 and 2/3 element
# ends (elements a multiple of 3) the element space holds the exact path: action to 1e-12.
BD = """[scene]
variable  = t
interval  = 0, 1
unknowns  = y
integrand = y''^2/2
[parameters]
l = 1/9
[boundary]
y  = 0, 0
y' = 1, -1
[constraints]
cap = y - l <= 0
"""
# Degrees 5 and 7 and 300 elements need the round-off margins of OB-2b (the nodes inside
# the contact arc carry no load: without them they flip sides on round-off forever), the
# penalised action as the merit (OB-3a) and the penalty weight scaled as a fourth-order
# stiffness; 3000 x p3 and --tol still fail (docs/obstacles.md).
for E, deg in (("6", "3"), ("30", "3"), ("30", "5"), ("30", "7"), ("24", "5"), ("300", "3")):
    p, _ = run(BD, "--elements", E, "--degree", deg, "--json", "-")
    r = json.loads(p.stdout) if p.stdout else {}
    check("Bryson-Denham %sx%s" % (E, deg), r.get("status") == "converged" and
          abs(r["action"] - 4) <= 1e-12 and r["morse_index"] == 0, (r.get("message"), r.get("action")))
    if r.get("status") == "converged":
        (x0, x1), = r["contact"]["cap"]
        check("Bryson-Denham contact %sx%s" % (E, deg),
              abs(x0 - 1 / 3) <= 1e-9 and abs(x1 - 2 / 3) <= 1e-9, (x0, x1))

# Bad input: FILE:LINE and exit 2.
for G, what in (("y - (1 - x^2) >= 0 + 1", "0 on the right"), ("y - (1 - x^2) > 0", "strict"),
                ("y - 3 >= 0", "violated at the fixed end"),
                ("y >= 1 - x^2", "move '1 - x^2' into G: y - (1 - x^2) >= 0"),
                ("y - (1 - x^2) => 0", "'=>' is not an operator; write '>='"),
                ("y - (1 - x^2) == 0", "without '=='")):
    p, name = run(BUMP % (G, "1"))
    check("bad %r exit 2" % G, p.returncode == 2, p.returncode)
    check("bad %r message" % G, (":9:" in p.stderr) and (what in p.stderr), p.stderr)
p, _ = run((BUMP % ("y - (1 - x^2) >= 0", "1")).replace("sqrt(1 + y'^2)", "y'^2 >= 0"))
check("comparison in the integrand", p.returncode == 2 and ":5:" in p.stderr, p.stderr)

# Infeasible: above the bump and below y = 1/2 cannot both hold near x = 0.
INF = BUMP % ("y - (1 - x^2) >= 0\ncap = y - 0.5 <= 0", "0")
p, _ = run(INF, "--json", "-")
check("infeasible exit 1", p.returncode == 1 and "infeasible" in p.stderr, (p.returncode, p.stderr[-300:]))

print("%d failures" % fails)
sys.exit(1 if fails else 0)

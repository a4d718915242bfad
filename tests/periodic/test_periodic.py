#!/usr/bin/env python3
# tests/periodic/test_periodic.py — periodic unknowns (docs/periodic.md, theory PB-1, PB-2)
# through `calcvar solve --json -` against independent answers:
#  - the pendulum libration of period 8 (F = th'^2/2 + cos th): action 6.68858249672602
#    from elliptic functions; Morse index 1 on periodic paths with the shift pinned (the
#    constant mode is the one negative direction: the branch bifurcating from the
#    equilibrium at T = 2 pi takes the amplitude direction's sign away, docs/periodic.md);
#  - the rotating pendulum (th = periodic + 2 pi) of period 4: the action from the energy E
#    that gives the period, T(E) = int_0^2pi dth / sqrt(2 (E + cos th)),
#    A = int_0^2pi sqrt(2 (E + cos th)) dth - E T, computed here by the trapezoid rule
#    (exponentially accurate for a smooth periodic integrand) and bisection; the rotation is
#    the least action among loops that wind once: Morse index 0;
#  - the resonant oscillator y'' + y = 0 on loops of period 2 pi: a family (every
#    a cos t + b sin t), reported "degenerate", never a plain minimum or saddle;
#  - bad [boundary] lines with their line number (exit 2).
# Tolerance: --tol 1e-10 bounds the nodal error; the action's error is of second order in
# it, so 1e-9 is 10 T.
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
        return subprocess.run([calcvar, "solve", name, *args], capture_output=True, text=True)
    finally:
        os.unlink(name)


PEND = """[scene]
interval  = 0, %s
variable  = t
unknowns  = th
integrand = th'^2/2 + cos(th)
[boundary]
th = %s
[guess]
th = %s
"""
p = run(PEND % ("8", "periodic", "1.5*cos(2*pi*t/8)"), "--tol", "1e-10", "--json", "-")
r = json.loads(p.stdout)
check("libration converged", r["status"] == "converged", r["message"])
check("libration action", abs(r["action"] - 6.68858249672602) <= 1e-9, r["action"])
check("libration index", r["morse_index"] == 1, r["morse_index"])
check("libration pinned", r.get("pinned") == ["shift"] and r.get("period") == 8, r)


def rotation(T):
    N = 4000

    def trap(f):
        return sum(f(2 * math.pi * k / N) for k in range(N)) * 2 * math.pi / N

    def period(E):
        return trap(lambda th: 1 / math.sqrt(2 * (E + math.cos(th))))

    lo, hi = 1 + 1e-9, 1e4
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if period(mid) > T else (lo, mid)
    E = 0.5 * (lo + hi)
    return trap(lambda th: math.sqrt(2 * (E + math.cos(th)))) - E * T


A = rotation(4.0)
p = run(PEND % ("4", "periodic + 2*pi", "2*pi*t/4"), "--tol", "1e-10", "--json", "-")
r = json.loads(p.stdout)
check("rotation converged", r["status"] == "converged", r["message"])
check("rotation action", abs(r["action"] - A) <= 1e-9, (r["action"], A))
check("rotation index", r["morse_index"] == 0, r["morse_index"])


# The rotation's path against the exact one under --tol T: the true nodal error at most
# 10 T. The exact th(t) inverts t(th) = int_0^th dphi / sqrt(2 (E + cos phi)) (th(0) = 0:
# the guess 2 pi t / 4 has mean pi, and so has the rotation through th(0) = 0, which is odd
# about t = 2; the phase condition asks for exactly that mean), by Newton's method on
# 40-point Gauss-Legendre quadrature.
def gauss_legendre(n):
    xs, ws = [], []
    for i in range(n):
        x = math.cos(math.pi * (i + 0.75) / (n + 0.5))
        for _ in range(100):
            p0, p1 = 1.0, x
            for k in range(2, n + 1):
                p0, p1 = p1, ((2 * k - 1) * x * p1 - (k - 1) * p0) / k
            dp = n * (x * p1 - p0) / (x * x - 1)
            dx = p1 / dp
            x -= dx
            if abs(dx) < 1e-16:
                break
        xs.append(x)
        ws.append(2 / ((1 - x * x) * dp * dp))
    return xs, ws


GX, GW = gauss_legendre(40)


def energy_for(T):
    N = 4000

    def period(E):
        return sum(1 / math.sqrt(2 * (E + math.cos(2 * math.pi * k / N))) for k in range(N)) * \
            2 * math.pi / N

    lo, hi = 1 + 1e-9, 1e4
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if period(mid) > T else (lo, mid)
    return 0.5 * (lo + hi)


E4 = energy_for(4.0)


def t_of(th):
    return sum(w * 0.5 * th / math.sqrt(2 * (E4 + math.cos(0.5 * th * (x + 1))))
               for x, w in zip(GX, GW))


def th_of(t):
    th = 2 * math.pi * t / 4
    for _ in range(50):
        d = (t_of(th) - t) * math.sqrt(2 * (E4 + math.cos(th)))
        th -= d
        if abs(d) < 1e-15:
            break
    return th


for T in (1e-6, 1e-8, 1e-10):
    p = run(PEND % ("4", "periodic + 2*pi", "2*pi*t/4"), "--tol", repr(T), "--csv", "-")
    rows = [list(map(float, l.split(","))) for l in p.stdout.split("\n")[1:] if l]
    err = max(abs(th - th_of(t)) for t, th in rows)
    print("rotation --tol %g: true max nodal error %.2e on %d nodes" % (T, err, len(rows)))
    check("rotation --tol %g" % T, err <= 10 * T, err)

RES = """[scene]
interval  = 0, 2*pi
unknowns  = y
integrand = y'^2/2 - y^2/2
[boundary]
y = periodic
[guess]
y = cos(x)
"""
p = run(RES, "--json", "-")
r = json.loads(p.stdout) if p.stdout else {}
check("resonant family not a plain stationary point",
      r.get("status") != "converged" or r.get("stationary_kind") == "degenerate", r)

for line, what in (("periodic, 0", "replaces both end values"), ("periodic * 2", "'+ D'"),
                   ("0, periodic", "replaces both end values")):
    p = run(PEND % ("8", line, "1"))
    check("bad %r" % line, p.returncode == 2 and ":7:" in p.stderr and what in p.stderr,
          p.stderr)

# The three-body figure-eight (examples/scenes/figure_eight.scene) on 72 elements of
# degree 8: the published action 24.42705 to 1e-7 relative; Simo's initial position of
# body 2, (0.97000436, -0.24308753), to 1e-8 (the published digits); the choreography,
# body 2 at t = body 1 at t + T/3, to 1e-8 (T/3 is 24 elements, so node j of body 2 is node
# j + 192 of body 1); the energy K - U constant to 1e-9 along the orbit, with the velocities
# from the derivative of each element's degree-8 interpolant at its nodes (that derivative
# converges more slowly than the nodal values: drift 2.2e-7 on 24 elements, 2.2e-9 on 48).
scene = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "examples",
                     "scenes", "figure_eight.scene")
p = subprocess.run([calcvar, "solve", scene, "--elements", "72", "--degree", "8", "--json", "-"],
                   capture_output=True, text=True)
r = json.loads(p.stdout)
check("eight converged", r["status"] == "converged", r["message"])
check("eight action", abs(r["action"] - 24.42705) <= 1e-7 * 24.42705, r["action"])
check("eight pinned", r.get("pinned") == ["shift"], r.get("pinned"))
p = subprocess.run([calcvar, "solve", scene, "--elements", "72", "--degree", "8", "--csv", "-"],
                   capture_output=True, text=True)
rows = [list(map(float, l.split(","))) for l in p.stdout.split("\n")[1:] if l]
check("eight x2(0)", abs(rows[0][3] - 0.97000436) <= 1e-8 and abs(rows[0][4] + 0.24308753) <= 1e-8,
      rows[0])
N = len(rows) - 1  # 576 intervals between nodes: 72 elements of degree 8
shift = N // 3
chor = max(abs(rows[j][3] - rows[(j + shift) % N][1]) + abs(rows[j][4] - rows[(j + shift) % N][2])
           for j in range(N))
check("eight choreography", chor <= 1e-8, chor)


def gll(p):  # Gauss-Lobatto-Legendre nodes on [-1, 1] by Newton on (1 - x^2) P_p'(x)
    xs = [-math.cos(math.pi * k / p) for k in range(p + 1)]
    for _ in range(100):
        for k in range(1, p):
            x = xs[k]
            P = [1.0, x]
            for n in range(2, p + 1):
                P.append(((2 * n - 1) * x * P[-1] - (n - 1) * P[-2]) / n)
            # x_{new} = x - (x P_p - P_{p-1}) / ((p + 1) P_p)
            xs[k] = x - (x * P[p] - P[p - 1]) / ((p + 1) * P[p])
    return xs


xi = gll(8)


def dlagrange(j, k):  # derivative of the j-th Lagrange basis function at node k
    if j == k:
        return sum(1 / (xi[k] - xi[m]) for m in range(9) if m != k)
    prod = 1 / (xi[j] - xi[k])
    for m in range(9):
        if m != j and m != k:
            prod *= (xi[k] - xi[m]) / (xi[j] - xi[m])
    return prod


D = [[dlagrange(j, k) for j in range(9)] for k in range(9)]
energies = []
for e in range(72):
    pts = rows[8 * e:8 * e + 9]
    h = pts[-1][0] - pts[0][0]
    for k in range(9):
        v = [sum(D[k][j] * pts[j][c] for j in range(9)) * 2 / h for c in range(1, 7)]
        q = pts[k][1:]
        K = sum(vi * vi for vi in v) / 2
        U = sum(1 / math.hypot(q[2 * a] - q[2 * b], q[2 * a + 1] - q[2 * b + 1])
                for a, b in ((0, 1), (0, 2), (1, 2)))
        energies.append(K - U)
drift = max(energies) - min(energies)
check("eight energy", drift <= 1e-9, drift)
print("figure-eight: action %.12f, choreography %.1e, energy %.9f drift %.1e" %
      (r["action"], chor, energies[0], drift))

# The figure-eight without its [integrals]: the translations of the plane leave the
# Hessian singular; the message names both, with the lines that pin them (PB-3).
text = open(scene).read()
text = text[:text.index("\n[integrals]")]
with tempfile.NamedTemporaryFile("w", suffix=".scene", delete=False) as f:
    f.write(text)
p = subprocess.run([calcvar, "solve", f.name], capture_output=True, text=True)
os.unlink(f.name)
check("free eight is singular", p.returncode == 1 and "singular" in p.stderr, p.stderr[:300])
check("free eight names the translations", "t1 = x1 + x2 + x3, 0" in p.stderr and
      "t2 = y1 + y2 + y3, 0" in p.stderr and "rotation" in p.stderr, p.stderr)

# batch: the period per row (PB-1 and the phase condition per row, its constant from the
# row's guess); each row's action equals a plain solve's of that period to 1e-12, and the
# period 8 row is the libration above.
BATCH = PEND.replace("interval  = 0, %s", "interval  = 0, T") % ("periodic", "1.5*cos(2*pi*t/T)")
BATCH = BATCH.replace("[boundary]", "[parameters]\nT = 8\n[boundary]")
with tempfile.TemporaryDirectory() as tmp:
    scene_b, table = os.path.join(tmp, "b.scene"), os.path.join(tmp, "t.csv")
    open(scene_b, "w").write(BATCH)
    open(table, "w").write("T\n8\n10\n")
    p = subprocess.run([calcvar, "batch", scene_b, table, "--tol", "1e-10"], capture_output=True,
                       text=True)
    lines = p.stdout.strip().split("\n")
    check("batch rows", p.returncode == 0 and len(lines) == 3, p.stdout + p.stderr)
    head = lines[0].split(",")
    for line in lines[1:]:
        row = dict(zip(head, line.split(",")))
        T = row["T"]
        q = run(PEND % (T, "periodic", "1.5*cos(2*pi*t/%s)" % T), "--tol", "1e-10", "--json", "-")
        ref = json.loads(q.stdout)["action"]
        check("batch T=%s" % T, row["status"] == "converged" and
              abs(float(row["action"]) - ref) <= 1e-12, (row, ref))
        if T == "8":
            check("batch libration", abs(float(row["action"]) - 6.68858249672602) <= 1e-9, row)

print("%d failures" % fails)
sys.exit(1 if fails else 0)

#!/usr/bin/env python3
# tests/periodic/test_closed_geodesics.py — the three principal sections of the triaxial
# ellipsoid x^2/a^2 + y^2/b^2 + z^2/c^2 = 1 (a, b, c = 1.5, 1.2, 1) as closed geodesics:
# unknowns x, y, z on loops of period 2 pi, energy form |r'|^2 / 2, the surface as a
# pointwise constraint. Checked against independent computations:
#  - the action E = L^2 / (2 T) with L the ellipse's perimeter (the trapezoid rule on
#    sqrt(p^2 sin^2 t + q^2 cos^2 t), exponentially accurate for a periodic integrand);
#  - the Morse index: on loops, the index of a closed geodesic is the number of negative
#    eigenvalues of the Jacobi form Q(J) = int (J_s^2 - K J^2) ds on periodic normal fields J
#    (tangential variations add none, the shift is pinned), K the Gaussian curvature
#    K = 1 / (a^2 b^2 c^2 (x^2/a^4 + y^2/b^4 + z^2/c^4)^2). Here Q is discretised by
#    second-order finite differences in the ellipse's angle t (2000 points, periodic) and
#    its negative pivots counted by an LDL^T factorisation (Sylvester's law). No closed
#    geodesic of a convex surface is a minimum: the constant normal push shortens it.
# Tolerances: 32 elements of degree 6 give the action to ~1e-12 (smooth periodic path);
# bound 1e-9. The index must agree exactly.
# SPDX-License-Identifier: MIT
import json, math, os, subprocess, sys, tempfile

calcvar = os.path.abspath(sys.argv[1])
A, B, C = 1.5, 1.2, 1.0
fails = 0


def check(what, ok, detail=""):
    global fails
    if not ok:
        fails += 1
        print("FAIL", what, detail)


def perimeter(p, q, N=20000):
    return sum(math.sqrt((p * math.sin(2 * math.pi * k / N)) ** 2 +
                         (q * math.cos(2 * math.pi * k / N)) ** 2) for k in range(N)) * 2 * math.pi / N


def jacobi_index(p, q, curvature, N=2000):
    """Negative pivots of the periodic FD matrix of Q(J) = int (J_t^2 / v - K v J^2) dt."""
    h = 2 * math.pi / N
    t = [h * k for k in range(N)]
    v = [math.sqrt((p * math.sin(s)) ** 2 + (q * math.cos(s)) ** 2) for s in t]
    vm = [math.sqrt((p * math.sin(s + h / 2)) ** 2 + (q * math.cos(s + h / 2)) ** 2) for s in t]
    Kv = [curvature(p * math.cos(s), q * math.sin(s)) * v[k] for k, s in enumerate(t)]
    # A[k][k] = (1/vm[k-1] + 1/vm[k]) / h - K v h, A[k][k+1] = -1/(vm[k] h), cyclic: with the
    # last point as a border, A = [[T, u], [u^T, alpha]] with T tridiagonal, and
    # inertia(A) = inertia(T) + sign(alpha - u^T T^-1 u) (Haynsworth).
    diag = [(1 / vm[k - 1] + 1 / vm[k]) / h - Kv[k] * h for k in range(N)]
    off = [-1 / (vm[k] * h) for k in range(N)]  # entry (k, k+1); off[N-1] joins N-1 and 0
    n = N - 1
    u = [0.0] * n
    u[0] += off[N - 1]
    u[n - 1] += off[n - 1]
    d, l, neg = [0.0] * n, [0.0] * n, 0  # T = L D L^T, L unit lower bidiagonal (l[k]: (k+1, k))
    for k in range(n):
        d[k] = diag[k] - (l[k - 1] ** 2 * d[k - 1] if k > 0 else 0.0)
        neg += d[k] < 0
        if k < n - 1:
            l[k] = off[k] / d[k]
    z = u[:]  # solve T w = u: L z = u, D y = z, L^T w = y
    for k in range(1, n):
        z[k] -= l[k - 1] * z[k - 1]
    w = [z[k] / d[k] for k in range(n)]
    for k in range(n - 2, -1, -1):
        w[k] -= l[k] * w[k + 1]
    schur = diag[N - 1] - sum(u[k] * w[k] for k in range(n))
    return neg + (schur < 0)


def K_ellipsoid(x, y, z):
    return 1 / (A * A * B * B * C * C * (x * x / A ** 4 + y * y / B ** 4 + z * z / C ** 4) ** 2)


SCENE = """[scene]
variable  = t
interval  = 0, 2*pi
unknowns  = x, y, z
integrand = (x'^2 + y'^2 + z'^2)/2
[parameters]
a = %r
b = %r
c = %r
[constraints]
surf = x^2/a^2 + y^2/b^2 + z^2/c^2 - 1
[boundary]
x = periodic
y = periodic
z = periodic
[guess]
%s
"""
sections = (
    ("yz", B, C, "x = 0\ny = b*cos(t)\nz = c*sin(t)", lambda u, w: K_ellipsoid(0, u, w)),
    ("xz", A, C, "x = a*cos(t)\ny = 0\nz = c*sin(t)", lambda u, w: K_ellipsoid(u, 0, w)),
    ("xy", A, B, "x = a*cos(t)\ny = b*sin(t)\nz = 0", lambda u, w: K_ellipsoid(u, w, 0)),
)
for name, p, q, guess, K in sections:
    with tempfile.NamedTemporaryFile("w", suffix=".scene", delete=False) as f:
        f.write(SCENE % (A, B, C, guess))
    run = subprocess.run([calcvar, "solve", f.name, "--elements", "32", "--degree", "6",
                          "--json", "-"], capture_output=True, text=True)
    os.unlink(f.name)
    r = json.loads(run.stdout)
    L = perimeter(p, q)
    E = L * L / (2 * 2 * math.pi)
    index = jacobi_index(p, q, K)
    print("%s: action %.15f (exact %.15f), Morse index %s (Jacobi form: %d)" %
          (name, r["action"], E, r.get("morse_index"), index))
    check(name + " converged", r["status"] == "converged", r["message"])
    check(name + " action", abs(r["action"] - E) <= 1e-9, (r["action"], E))
    check(name + " index", r.get("morse_index") == index, (r.get("morse_index"), index))
    check(name + " pinned", r.get("pinned") == ["shift"], r.get("pinned"))

print("%d failures" % fails)
sys.exit(1 if fails else 0)

# tests/c1/elastica_ref.py — an independent reference for the clamped elastica of
# tests/c1/data/elastica.scene (y = 0, y' = 0 at 0; y = 0.5, y' = 2 at 1): shooting on the
# first integral of its Euler-Lagrange equation, in pure Python (no calcvar, no scipy).
# For F = y''^2 / (1 + y'^2)^(5/2), F_y = 0 gives F_y' - d/dx F_y'' = C, that is
#     y''' = (5 p q^2 / w - C w^(5/2)) / 2,   p = y', q = y'', w = 1 + p^2;
# the unknowns y''(0) and C are found by damped Newton, the ODE by RK4 with Richardson
# extrapolation (two step sizes). Used by test_cli_c1.py and bench/bench_elastica.py.
# SPDX-License-Identifier: MIT
import math


def rhs(z, C):
    y, p, q = z
    w = 1 + p * p
    return (p, q, 0.5 * (5 * p * q * q / w - C * w ** 2.5))


def rk4(z, h, C):
    k1 = rhs(z, C)
    k2 = rhs([a + 0.5 * h * b for a, b in zip(z, k1)], C)
    k3 = rhs([a + 0.5 * h * b for a, b in zip(z, k2)], C)
    k4 = rhs([a + h * b for a, b in zip(z, k3)], C)
    return [a + h / 6 * (b + 2 * c + 2 * d + e) for a, b, c, d, e in zip(z, k1, k2, k3, k4)]


def shoot(q0, C, xs, hmax):
    """y at the abscissae xs (increasing, from 0), and (y, y', y'') at 1."""
    z, x, out = [0.0, 0.0, q0], 0.0, []
    for xt in list(xs) + [1.0]:
        m = max(1, int(math.ceil((xt - x) / hmax)))
        h = (xt - x) / m
        for _ in range(m):
            z = rk4(z, h, C)
        x = xt
        out.append(z[0])
    return out[:-1], z


def residual(u, hmax):
    try:
        _, z = shoot(u[0], u[1], [], hmax)
        return [z[0] - 0.5, z[1] - 2.0]
    except OverflowError:  # a trial that blows up: rejected by the damping below
        return [math.inf, math.inf]


def solve(hmax):
    """(y''(0), C) by damped Newton, from a start that a coarse scan of the shots shows near
    (the shot (1, 0) ends at y = 0.68, y' = 2.08)."""
    u = [1.0, 0.0]
    r = residual(u, hmax)
    for _ in range(60):
        J = []
        for k in range(2):
            v = list(u)
            dv = 1e-7 * max(1.0, abs(v[k]))
            v[k] += dv
            rk = residual(v, hmax)
            J.append([(rk[0] - r[0]) / dv, (rk[1] - r[1]) / dv])
        det = J[0][0] * J[1][1] - J[1][0] * J[0][1]
        du = [(r[0] * J[1][1] - r[1] * J[1][0]) / det, (r[1] * J[0][0] - r[0] * J[0][1]) / det]
        lam = 1.0
        while lam > 1e-6:
            v = [u[0] - lam * du[0], u[1] - lam * du[1]]
            rv = residual(v, hmax)
            if max(map(abs, rv)) < max(map(abs, r)) or max(map(abs, r)) < 1e-15:
                break
            lam *= 0.5
        u, r = v, rv
        if max(abs(d) for d in du) < 1e-14 or max(map(abs, r)) < 1e-15:
            break
    return u


def reference(xs, steps=1500):
    """y at xs, and an estimate of its own error: RK4 with steps and 2 steps per unit
    length, extrapolated (Richardson, order 4)."""
    ys = []
    for hmax in (1.0 / steps, 0.5 / steps):
        u = solve(hmax)
        ys.append(shoot(u[0], u[1], xs, hmax)[0])
    ref = [b + (b - a) / 15 for a, b in zip(*ys)]
    return ref, max(abs(a - b) for a, b in zip(ref, ys[1]))

#!/usr/bin/env python3
"""bench/python_vs_scipy.py — three problems written with calcvar and with scipy's
solve_bvp, side by side (docs/python.md, "calcvar and solve_bvp"), timed in one run.

usage: CALCVAR_LIB=build/libcalcvar.so PYTHONPATH=python \\
       flock /tmp/calcvar-build.lock /usr/bin/python3 bench/python_vs_scipy.py
Each side is asked for 1e-8 (calcvar: tol, its estimate of the max nodal error; solve_bvp:
tol, the relative residual of its collocation equations; they do not mean the same thing,
so each one's true error is printed next to its time). solve_bvp gets the Euler-Lagrange
equation derived by hand as a first-order system with its Jacobian, an initial mesh of 11
points and the straight line; calcvar gets the integrand. Errors: max over 2001 points of
|y(x) - exact| (sol(x) for calcvar, res.sol(x) for solve_bvp). The pendulum has no closed
form: its reference is a shooting solution (solve_ivp, rtol 1e-13, brentq on th'(0)).
Times: the fastest of repeated calls (at least 0.3 s of calls). Not part of meson test.
SPDX-License-Identifier: MIT
"""
import math
import sys
import time

import numpy as np
from scipy.integrate import solve_bvp, solve_ivp
from scipy.optimize import brentq

import calcvar

G = 9.81


def best(f, least=0.3):
    f()
    n, t0, times = 0, time.perf_counter(), []
    while time.perf_counter() - t0 < least or n < 5:
        t = time.perf_counter()
        r = f()
        times.append(time.perf_counter() - t)
        n += 1
    return min(times), r


def pendulum_exact():
    def end(v):
        s = solve_ivp(lambda t, u: [u[1], -G * math.sin(u[0])], (0, 0.5), [0, v],
                      rtol=1e-13, atol=1e-13)
        return s.y[0, -1] - 1
    v0 = brentq(end, 0.5, 10, xtol=1e-15)
    s = solve_ivp(lambda t, u: [u[1], -G * math.sin(u[0])], (0, 0.5), [0, v0],
                  rtol=1e-13, atol=1e-13, dense_output=True)
    return lambda t: s.sol(t)[0]


def problems():
    ye = 2 * math.cosh(0.5)
    P = []
    # catenary: F = y sqrt(1 + y'^2); y'' = (1 + y'^2) / y
    P.append(dict(
        name="catenary", a=-1.0, b=1.0, ends=(ye, ye),
        problem=calcvar.Problem("y*sqrt(1 + y'^2)", (-1, 1), {"y": (ye, ye)}),
        f=lambda x, u: np.vstack([u[1], (1 + u[1]**2) / u[0]]),
        j=lambda x, u: np.array([[np.zeros_like(x), np.ones_like(x)],
                                 [-(1 + u[1]**2) / u[0]**2, 2 * u[1] / u[0]]]),
        exact=lambda x: 2 * np.cosh(x / 2)))
    # ray, n^2 = 1 + x: F = sqrt(1 + x) sqrt(1 + y'^2); y'' = -y'(1 + y'^2) / (2 (1 + x))
    yb = math.sqrt(1.75) - math.sqrt(0.75)
    P.append(dict(
        name="graded-index ray", a=0.0, b=1.0, ends=(0.0, yb),
        problem=calcvar.Problem("sqrt(1 + x)*sqrt(1 + y'^2)", (0, 1), {"y": (0, yb)}),
        f=lambda x, u: np.vstack([u[1], -u[1] * (1 + u[1]**2) / (2 * (1 + x))]),
        j=lambda x, u: np.array([[np.zeros_like(x), np.ones_like(x)],
                                 [np.zeros_like(x), -(1 + 3 * u[1]**2) / (2 * (1 + x))]]),
        exact=lambda x: np.sqrt(0.75 + x) - math.sqrt(0.75)))
    # pendulum: F = th'^2/2 + g cos(th); th'' = -g sin(th)
    P.append(dict(
        name="pendulum", a=0.0, b=0.5, ends=(0.0, 1.0),
        problem=calcvar.Problem("th'^2/2 + g*cos(th)", (0, 0.5), {"th": (0, 1)},
                                variable="t", parameters={"g": G}),
        f=lambda x, u: np.vstack([u[1], -G * np.sin(u[0])]),
        j=lambda x, u: np.array([[np.zeros_like(x), np.ones_like(x)],
                                 [-G * np.cos(u[0]), np.zeros_like(x)]]),
        exact=pendulum_exact()))
    return P


def main():
    tol = 1e-8
    print("| problem | calcvar (tol=%g) | its error | solve_bvp (tol=%g) | its error | "
          "time ratio |" % (tol, tol))
    print("|---|---|---|---|---|---|")
    for p in problems():
        a, b, (ya, yb) = p["a"], p["b"], p["ends"]
        xs = np.linspace(a, b, 2001)
        tc, sol = best(lambda: p["problem"].solve(tol=tol))
        ec = np.max(np.abs(sol(xs)[0] - p["exact"](xs)))
        x0 = np.linspace(a, b, 11)
        y0 = np.vstack([ya + (yb - ya) * (x0 - a) / (b - a), np.full(11, (yb - ya) / (b - a))])

        def bvp():
            return solve_bvp(p["f"], lambda ua, ub: np.array([ua[0] - ya, ub[0] - yb]), x0, y0,
                             fun_jac=p["j"], tol=tol)
        ts, res = best(bvp)
        assert sol.success and res.success, (p["name"], sol.message, res.message)
        es = np.max(np.abs(res.sol(xs)[0] - p["exact"](xs)))
        print("| %s | %.3g ms | %.1e | %.3g ms | %.1e | %.0fx |"
              % (p["name"], 1e3 * tc, ec, 1e3 * ts, es, ts / tc))
    return 0


if __name__ == "__main__":
    sys.exit(main())

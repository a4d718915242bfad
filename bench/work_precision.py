#!/usr/bin/env python3
# bench/work_precision.py — calcvar against scipy's solve_bvp: least run time to reach a max
# nodal error of 1e-4 .. 1e-12 on five problems, in the same run, and the time ratio.
# SPDX-License-Identifier: MIT
#
# usage: bench/work_precision.py [--build DIR] [--quick] [--figures DIR] [--markdown FILE]
#   --build DIR      meson build directory holding bench/work_precision (default: build)
#   --quick          fewer repetitions (noisier figures, a few seconds)
#   --figures DIR    also draw DIR/work_precision_PROBLEM.svg (calcvar per degree, calcvar
#                    --tol, solve_bvp)
#   --markdown FILE  also write the two comparison tables as Markdown (for the docs)
#
# solve_bvp (Debian python3-scipy) solves each problem's Euler-Lagrange equations as a
# first-order system with analytic Jacobians (fun_jac, bc_jac), from the same straight-line
# guess calcvar starts from, on an initial mesh of 11 points, for tol = 1e-2 .. 1e-13; its
# error is the max over its final mesh nodes of |y - y_exact| (the unknowns only, not y'),
# the same measure as calcvar's error.max_nodal; its time is the fastest of repeated calls
# (at least 50 ms of calls), as for calcvar. Without scipy the comparison is skipped with
# a message and only calcvar's table is printed. Not part of meson test.
#
# Second comparison, at the same requested tolerance: calcvar --tol T (automatic accuracy,
# no mesh given; bench/work_precision.c times it the same way, fresh solver per solve,
# fastest of repeats) against solve_bvp(tol=T), for each T, with each one's time and true
# max nodal error. The two tolerances do not mean the same thing: calcvar's T bounds its
# estimate of the max nodal error of y; solve_bvp's tol bounds the relative residuals of
# its collocation equations (and of the BVP's ODE between nodes), not the error.
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time

TARGETS = [1e-4, 1e-6, 1e-8, 1e-10, 1e-12]
PROBLEMS = ["catenary", "fisheye_ray", "harmonic_saddle", "boundary_layer", "sphere_geodesic"]


def problems(np):
    """Per problem: interval, fun, fun_jac, bc, bc_jac, guess (y0 at x), exact y (n rows)."""
    P = {}
    # Catenary: F = y sqrt(1 + y'^2)  ->  y'' = (1 + y'^2) / y.
    c = 2.0
    ye = c * math.cosh(1 / c)

    def cat_f(x, u):
        y, v = u
        return np.vstack([v, (1 + v * v) / y])

    def cat_j(x, u):
        y, v = u
        J = np.zeros((2, 2, x.size))
        J[0, 1] = 1
        J[1, 0] = -(1 + v * v) / (y * y)
        J[1, 1] = 2 * v / y
        return J

    P["catenary"] = dict(a=-1.0, b=1.0, n=1, f=cat_f, j=cat_j, ends=[(ye, ye)],
                         exact=lambda x: np.vstack([c * np.cosh(x / c)]))
    # Fish-eye: F = n(x, y) sqrt(1 + y'^2), n = 2/(1 + x^2 + y^2)
    #   ->  y'' = 2 (1 + y'^2)(x y' - y) / (1 + x^2 + y^2).
    yf = -2 + math.sqrt(4.75)

    def fe_f(x, u):
        y, v = u
        D = 1 + x * x + y * y
        return np.vstack([v, 2 * (1 + v * v) * (x * v - y) / D])

    def fe_j(x, u):
        y, v = u
        D = 1 + x * x + y * y
        g = x * v - y
        J = np.zeros((2, 2, x.size))
        J[0, 1] = 1
        J[1, 0] = 2 * (1 + v * v) * (-1 / D - g * 2 * y / (D * D))
        J[1, 1] = 2 * (2 * v * g + (1 + v * v) * x) / D
        return J

    P["fisheye_ray"] = dict(a=-0.5, b=0.5, n=1, f=fe_f, j=fe_j, ends=[(yf, yf)],
                            exact=lambda x: np.vstack([-2 + np.sqrt(5 - x * x)]))
    # Harmonic oscillator past the conjugate point: F = q'^2/2 - q^2/2  ->  q'' = -q.

    def ho_f(x, u):
        return np.vstack([u[1], -u[0]])

    def ho_j(x, u):
        J = np.zeros((2, 2, x.size))
        J[0, 1] = 1
        J[1, 0] = -1
        return J

    P["harmonic_saddle"] = dict(a=0.0, b=4.0, n=1, f=ho_f, j=ho_j, ends=[(0.0, 1.0)],
                                exact=lambda t: np.vstack([np.sin(t) / math.sin(4)]))
    # Boundary layers: F = (eps^2 y'^2 + (y - 1)^2)/2  ->  y'' = (y - 1)/eps^2.
    eps = 1e-2

    def bl_f(x, u):
        return np.vstack([u[1], (u[0] - 1) / eps ** 2])

    def bl_j(x, u):
        J = np.zeros((2, 2, x.size))
        J[0, 1] = 1
        J[1, 0] = 1 / eps ** 2
        return J

    P["boundary_layer"] = dict(
        a=0.0, b=1.0, n=1, f=bl_f, j=bl_j, ends=[(0.0, 0.0)],
        exact=lambda x: np.vstack([1 - (np.exp((x - 1) / eps) + np.exp(-x / eps)) /
                                   (1 + math.exp(-1 / eps))]))
    # Sphere geodesic, energy form F = th'^2 + sin(th)^2 ph'^2:
    #   th'' = sin th cos th ph'^2,  ph'' = -2 cot(th) th' ph'.

    def sg_f(s, u):
        th, ph, a, b = u
        return np.vstack([a, b, 0.5 * np.sin(2 * th) * b * b, -2 * a * b / np.tan(th)])

    def sg_j(s, u):
        th, ph, a, b = u
        J = np.zeros((4, 4, s.size))
        J[0, 2] = 1
        J[1, 3] = 1
        J[2, 0] = np.cos(2 * th) * b * b
        J[2, 3] = np.sin(2 * th) * b
        J[3, 0] = 2 * a * b / np.sin(th) ** 2
        J[3, 2] = -2 * b / np.tan(th)
        J[3, 3] = -2 * a / np.tan(th)
        return J

    P["sphere_geodesic"] = dict(
        a=0.0, b=1.0, n=2, f=sg_f, j=sg_j, ends=[(math.pi / 3, math.pi / 2), (0.0, math.pi / 2)],
        exact=lambda s: np.vstack([np.arccos(np.cos(math.pi * s / 2) / 2),
                                   np.arctan2(np.sin(math.pi * s / 2),
                                              math.sqrt(3) / 2 * np.cos(math.pi * s / 2))]))
    return P


def run_bvp(np, solve_bvp, pr, tol, budget):
    """(max nodal error, fastest time, mesh points) of solve_bvp at one tolerance; None if it
    fails."""
    n, a, b = pr["n"], pr["a"], pr["b"]
    ends = pr["ends"]

    def bc(ua, ub):
        return np.array([ua[i] - ends[i][0] for i in range(n)] +
                        [ub[i] - ends[i][1] for i in range(n)])

    def bc_jac(ua, ub):
        A = np.zeros((2 * n, 2 * n))
        B = np.zeros((2 * n, 2 * n))
        for i in range(n):
            A[i, i] = 1
            B[n + i, i] = 1
        return A, B

    x0 = np.linspace(a, b, 11)
    u0 = np.zeros((2 * n, x0.size))
    for i in range(n):  # the straight line between the end values, calcvar's default guess
        u0[i] = ends[i][0] + (ends[i][1] - ends[i][0]) * (x0 - a) / (b - a)
        u0[n + i] = (ends[i][1] - ends[i][0]) / (b - a)
    best, spent, sol = math.inf, 0.0, None
    while sol is None or (spent < budget and spent < 50 * best):
        t0 = time.perf_counter()
        sol = solve_bvp(pr["f"], bc, x0, u0, fun_jac=pr["j"], bc_jac=bc_jac, tol=tol,
                        max_nodes=1000000)
        t = time.perf_counter() - t0
        best, spent = min(best, t), spent + t
        if sol.status != 0:  # 1: max_nodes exceeded, 2: singular Jacobian, 3: tol not met
            return sol.status
    err = float(np.max(np.abs(sol.y[:n] - pr["exact"](sol.x))))
    return err, best, sol.x.size


def time_to(points, target):
    ts = [t for e, t in points if e <= target]
    return min(ts) if ts else None


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--figures")
    ap.add_argument("--markdown")
    args = ap.parse_args()
    exe = os.path.join(args.build, "bench", "work_precision")
    if not os.path.exists(exe):
        sys.exit("no %s: build first (meson setup %s && ninja -C %s)" % (exe, args.build,
                                                                           args.build))
    try:
        import numpy as np
        from scipy.integrate import solve_bvp
        import scipy
    except ImportError:
        np = None
        print("scipy is not installed (Debian: apt-get install python3-scipy): the solve_bvp "
              "comparison is skipped; calcvar alone follows.\n")

    bvp, bvp_tol = {}, {}
    if np is not None:
        import warnings
        warnings.simplefilter("ignore")  # solve_bvp warns when tol < 100 eps
        P = problems(np)
        tols = [10.0 ** (-k / 2) for k in range(4, 27)]  # 1e-2 .. 1e-13
        budget = 0.01 if args.quick else 0.05
        print("scipy %s solve_bvp: (tol, max nodal error, time, mesh points)" % scipy.__version__)
        for name in PROBLEMS:
            pts = []
            bvp_tol[name] = {}
            for tol in tols:
                r = run_bvp(np, solve_bvp, P[name], tol, budget)
                if isinstance(r, int):
                    print("  %-16s tol %.0e  failed (status %d)" % (name, tol, r))
                    bvp_tol[name]["%.1e" % tol] = "failed (status %d)" % r
                    continue
                bvp_tol[name]["%.1e" % tol] = r
                if r:
                    pts.append([r[0], r[1]])
                    print("  %-16s tol %.0e  error %.2e  %.2e s  %d points" %
                          (name, tol, r[0], r[1], r[2]))
                else:
                    print("  %-16s tol %.0e  failed" % (name, tol))
            bvp[name] = pts
        print()

    with tempfile.TemporaryDirectory() as tmp:
        cmd = [exe, "--json", os.path.join(tmp, "cv.json")]
        if args.quick:
            cmd.append("--quick")
        if bvp:
            with open(os.path.join(tmp, "bvp.json"), "w") as f:
                json.dump(bvp, f)
            cmd += ["--bvp", os.path.join(tmp, "bvp.json")]
        if args.figures:
            os.makedirs(args.figures, exist_ok=True)
            cmd += ["--svg-dir", args.figures]
        sys.stdout.flush()
        subprocess.run(cmd, check=True)
        with open(os.path.join(tmp, "cv.json")) as f:
            cv = json.load(f)
    if not bvp:
        return
    md = []
    # docs/performance.md's table: per degree the least time (elements), the best in bold
    md.append("| problem | error | p = 1 | p = 2 | p = 4 | p = 8 | solve_bvp | ratio (best "
              "calcvar) |")
    md.append("|---|---|---|---|---|---|---|---|")
    for name in PROBLEMS:
        for k, target in enumerate(TARGETS):
            cells, best = [], None
            for deg in ("1", "2", "4", "8"):
                ok = [(t, E) for E, e, t in cv[name].get(deg, []) if e <= target]
                c = min(ok) if ok else None
                cells.append(c)
                if c and (best is None or c[0] < best[0]):
                    best = c
            row = ["%.1e (%d)" % c if c else "–" for c in cells]
            row = ["**%s** (%d)" % ("%.1e" % c[0], c[1]) if c and c == best else r
                   for c, r in zip(cells, row)]
            tb = time_to(bvp[name], target)
            md.append("| %s | %.0e | %s | %s | %s |" % (
                name if k == 0 else "", target, " | ".join(row),
                "%.1e" % tb if tb else "not reached",
                "%.0f×" % (tb / best[0]) if tb and best else "–"))
    print("\ncalcvar (best degree) against solve_bvp: least time to reach the error")
    print("%-16s %7s  %-18s %-10s %8s" % ("problem", "error", "calcvar [s] (p, N)",
                                        "solve_bvp", "ratio"))
    for name in PROBLEMS:
        for k, target in enumerate(TARGETS):
            best = None
            for deg, pts in cv[name].items():
                for E, e, t in pts:
                    if e <= target and (best is None or t < best[0]):
                        best = (t, deg, E)
            tb = time_to(bvp[name], target)
            cell = "%.2e (%s,%d)" % best if best else "-"
            ratio = "%.0fx" % (tb / best[0]) if best and tb else "-"
            print("%-16s %7.0e  %-18s %-10s %8s" % (name if k == 0 else "", target, cell,
                                                   "%.2e" % tb if tb else "not reached",
                                                   ratio))
    if "tol" in cv:
        print("\nthe same requested tolerance T: calcvar --tol T (no mesh given) against "
              "solve_bvp(tol=T)")
        print("%-16s %8s | %-10s %9s %6s %-9s | %-10s %9s %6s | %7s" % (
            "problem", "T", "calcvar", "error", "nodes", "status", "solve_bvp", "error",
            "points", "t ratio"))
        md.append("")
        md.append("| problem | T | calcvar --tol [s] | its max nodal error | nodes | "
                  "solve_bvp(tol=T) [s] | its max nodal error | points | time ratio |")
        md.append("|---|---|---|---|---|---|---|---|---|")
        for name in PROBLEMS:
            first = True
            for T, err, t, nodes, status in cv["tol"][name]:
                b = bvp_tol[name].get("%.1e" % T)
                why = b if isinstance(b, str) else "failed"
                b = None if isinstance(b, str) else b
                ratio = "%.0f" % (b[1] / t) if b else "-"
                print("%-16s %8.1e | %-10s %9.2e %6d %-9s | %-10s %9s %6s | %7s" % (
                    name if first else "", T, "%.2e" % t, err, nodes, status,
                    "%.2e" % b[1] if b else why, "%.2e" % b[0] if b else "-",
                    "%d" % b[2] if b else "-", ratio))
                if abs(math.log10(T) - round(math.log10(T))) < 1e-6:  # whole decades
                    md.append("| %s | %.0e | %.1e | %.1e%s | %d | %s | %s | %s | %s |" % (
                        name if first else "", T, t, err,
                        "" if status == "converged" else " (%s)" % status, nodes,
                        "%.1e" % b[1] if b else why, "%.1e" % b[0] if b else "–",
                        "%d" % b[2] if b else "–", ratio + "×" if b else "–"))
                    first = False
    if args.markdown:
        with open(args.markdown, "w") as f:
            f.write("\n".join(md) + "\n")
        print("wrote %s" % args.markdown)


if __name__ == "__main__":
    main()

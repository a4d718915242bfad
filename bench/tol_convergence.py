#!/usr/bin/env python3
# bench/tol_convergence.py — exponential convergence in sqrt(unknowns) under --tol on the
# brachistochrone (theory HP-5), drawn: the error against sqrt(N) for T = 1e-3 .. 1e-12 with
# the least-squares line ln(error) = c - b sqrt(N) over the points above round-off.
# SPDX-License-Identifier: MIT
#
# usage: bench/tol_convergence.py [--build DIR] [--scene FILE] [--figure FILE.svg] [--png FILE]
#   --build DIR     meson build directory holding src/cli/calcvar (default: build)
#   --scene FILE    default: tests/scene/data/brachistochrone.scene (the cycloid through
#                   (0, 0) and (pi, 2), y measured downward, 2g = 1)
#   --figure FILE   the SVG to write (default: docs/performance/tol_convergence_brachistochrone.svg)
#   --png FILE      also a PNG (to look at)
#
# Each T runs `calcvar solve SCENE --tol T --json J --csv C` as a user would (no mesh given).
# Two errors, both against exact answers computed here independently of calcvar:
# - the action: |S_h - pi sqrt(2)| / pi sqrt(2) (relative, as bench/bench_tol prints it);
# - the max nodal error: at each node x the cycloid's y, from x = phi - sin(phi) solved for
#   phi (bisection, then Newton; phi - sin(phi) by its series below phi = 0.1, where the
#   subtraction would cancel) and y = 1 - cos(phi) = 2 sin(phi/2)^2.
# Needs matplotlib (Debian python3-matplotlib, in scripts/deps.sh). Not part of meson test.
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile

EXACT_ACTION = math.pi * math.sqrt(2.0)
ROUNDOFF = 1e-14  # errors at or below this are round-off: left out of the fit


def x_of_phi(phi):
    if phi > 0.1:
        return phi - math.sin(phi)
    s, term, k = 0.0, phi, 1  # phi^3/3! - phi^5/5! + ...
    while True:
        term *= phi * phi / ((2 * k) * (2 * k + 1))
        s += term if k % 2 == 1 else -term
        if term < 1e-18 * s:
            return s
        k += 1


def cycloid_y(x):
    """y of the cycloid x = phi - sin(phi), y = 1 - cos(phi), 0 <= phi <= pi, at x."""
    if x <= 0.0:
        return 0.0
    lo, hi = 0.0, math.pi
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if x_of_phi(mid) < x:
            lo = mid
        else:
            hi = mid
        if hi - lo <= 1e-15 * hi:
            break
    phi = 0.5 * (lo + hi)
    for _ in range(3):  # Newton: d(phi - sin phi) = 1 - cos phi = 2 sin(phi/2)^2
        d = 2.0 * math.sin(0.5 * phi) ** 2
        if d <= 0.0:
            break
        phi -= (x_of_phi(phi) - x) / d
    return 2.0 * math.sin(0.5 * phi) ** 2


def fit(points):
    """Least squares ln(e) = c - b r over (r, e) with e above round-off: (c, b, count,
    smallest r, largest r)."""
    pts = [(r, math.log(e)) for r, e in points if e > ROUNDOFF]
    m = len(pts)
    if m < 3:
        return None
    sx = sum(r for r, _ in pts)
    sy = sum(v for _, v in pts)
    sxx = sum(r * r for r, _ in pts)
    sxy = sum(r * v for r, v in pts)
    slope = (m * sxy - sx * sy) / (m * sxx - sx * sx)
    return (sy - slope * sx) / m, -slope, m, min(r for r, _ in pts), max(r for r, _ in pts)


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--scene", default=os.path.join(root, "tests", "scene", "data",
                                                    "brachistochrone.scene"))
    ap.add_argument("--figure", default=os.path.join(root, "docs", "performance",
                                                     "tol_convergence_brachistochrone.svg"))
    ap.add_argument("--png")
    args = ap.parse_args()
    exe = os.path.join(args.build, "src", "cli", "calcvar")
    if not os.path.exists(exe):
        sys.exit("no %s: build first (meson setup %s && ninja -C %s)" % (exe, args.build,
                                                                           args.build))
    rows = []
    print("brachistochrone under --tol: nodes, sqrt(N), relative action error, max nodal error")
    print("%8s %6s %8s %10s %10s %10s  %s" % ("T", "nodes", "sqrt(N)", "act_err", "nodal_err",
                                            "estimate", "status"))
    with tempfile.TemporaryDirectory() as tmp:
        jf, cf = os.path.join(tmp, "r.json"), os.path.join(tmp, "r.csv")
        for k in range(3, 13):
            T = 10.0 ** -k
            r = subprocess.run([exe, "solve", args.scene, "--tol", "%g" % T, "--json", jf,
                                "--csv", cf, "--quiet"], capture_output=True, text=True)
            if r.returncode not in (0, 1):
                sys.exit("calcvar --tol %g: exit %d: %s" % (T, r.returncode, r.stderr))
            with open(jf) as f:
                j = json.load(f)
            with open(cf) as f:
                lines = f.read().split("\n")[1:]
            xy = [tuple(float(v) for v in ln.split(",")) for ln in lines if ln.strip()]
            nodal = max(abs(y - cycloid_y(x)) for x, y in xy)
            act = abs(j["action"] - EXACT_ACTION) / EXACT_ACTION
            N = j["nodes"]
            rows.append((T, N, act, nodal, j["status"]))
            print("%8.0e %6d %8.2f %10.2e %10.2e %10.2e  %s" % (
                T, N, math.sqrt(N), act, nodal, j.get("error_estimate", float("nan")),
                j["status"]))
    fa = fit([(math.sqrt(N), a) for _, N, a, _, _ in rows])
    fn = fit([(math.sqrt(N), e) for _, N, _, e, _ in rows])
    for name, f in (("action error", fa), ("max nodal error", fn)):
        if f:
            print("fit ln(%s) = %.2f - %.3f sqrt(N) (%d points above %g)" % (name, f[0], f[1],
                                                                          f[2], ROUNDOFF))

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    plt.rcParams["svg.hashsalt"] = "calcvar"  # reproducible SVG ids
    fig, ax = plt.subplots(figsize=(7.5, 4.8))
    r = [math.sqrt(N) for _, N, _, _, _ in rows]
    ax.semilogy(r, [max(a, 1e-17) for _, _, a, _, _ in rows], "o", color="C0",
                label="relative action error")
    ax.semilogy(r, [max(e, 1e-17) for _, _, _, e, _ in rows], "s", color="C1", mfc="none",
                label="max nodal error (exact cycloid)")
    rr = [min(r) - 0.5, max(r) + 0.5]
    for f, col, what in ((fa, "C0", "action"), (fn, "C1", "nodal")):
        if f:  # over the points it was fitted to
            xs = [f[3] - 0.5, f[4] + 0.5]
            ax.semilogy(xs, [math.exp(f[0] - f[1] * x) for x in xs], "-", color=col, lw=1,
                        label="fit (%s): exp(%.1f - %.2f $\\sqrt{N}$)" % (what, f[0], f[1]))
    ax.axhspan(1e-17, ROUNDOFF, color="0.9", zorder=0)
    ax.text(rr[0] + 0.2, 2e-16, "round-off (not fitted)", fontsize=8, color="0.4")
    for (T, N, a, e, _), x in zip(rows, r):
        ax.annotate("%g" % T, (x, max(a, e)), textcoords="offset points", xytext=(0, 6),
                    ha="center", fontsize=7, color="0.3")
    ax.set_xlabel("$\\sqrt{N}$ (N = nodes chosen by --tol; labels: the requested T)")
    ax.set_ylabel("error")
    ax.set_ylim(1e-17, 1e-2)
    ax.set_title("Brachistochrone under --tol: error against $\\sqrt{\\mathrm{nodes}}$ (hp, HP-5)")
    ax.grid(True, which="major", color="0.85", lw=0.5)
    ax.legend(fontsize=8, loc="upper right")
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(args.figure)), exist_ok=True)
    fig.savefig(args.figure, metadata={"Date": None})
    print("wrote %s" % args.figure)
    if args.png:
        fig.savefig(args.png, dpi=110)
        print("wrote %s" % args.png)


if __name__ == "__main__":
    main()

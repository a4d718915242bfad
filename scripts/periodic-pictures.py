#!/usr/bin/env python3
"""scripts/periodic-pictures.py — the figures of docs/periodic.md, from `calcvar solve --csv`.

usage: /usr/bin/python3 scripts/periodic-pictures.py build/src/cli/calcvar
Writes docs/periodic/figure_eight.png and docs/periodic/pendulum.png (matplotlib, Debian
python3-matplotlib).
SPDX-License-Identifier: MIT
"""
import io
import os
import subprocess
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

calcvar = sys.argv[1]
root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
out = os.path.join(root, "docs", "periodic")
os.makedirs(out, exist_ok=True)


def table(scene, *args):
    text = subprocess.run([calcvar, "solve", os.path.join(root, scene), *args, "--csv", "-"],
                          capture_output=True, text=True, check=True).stdout
    return np.genfromtxt(io.StringIO(text), delimiter=",", names=True)


# 1. the figure-eight: the three bodies' paths (one curve), their places at t = 0 and the
#    guess the solve started from
d = table("examples/scenes/figure_eight.scene")
T = d["t"][-1]
fig, ax = plt.subplots(figsize=(8, 3.6), layout="constrained")
s = np.linspace(0, T, 400)
w, A, B = 2 * np.pi / T, 1.08, 0.35
ax.plot(A * np.sin(w * s), B * np.sin(2 * w * s), ":", color="0.6", label="the guess (a lemniscate)")
for k, c in zip((1, 2, 3), ("C0", "C1", "C2")):
    ax.plot(d["x%d" % k], d["y%d" % k], color=c, lw=3 - 0.8 * (k - 1), label="body %d" % k)
    ax.plot(d["x%d" % k][0], d["y%d" % k][0], "o", color=c, ms=9)
ax.set_aspect("equal")
ax.set_xlabel("x")
ax.set_ylabel("y")
ax.set_title("The figure-eight: three bodies on one closed curve, a third of a period apart "
             "(dots: t = 0)", fontsize=10)
ax.set_ylim(-0.52, 0.42)
ax.legend(fontsize=8, loc="lower center", ncol=4, frameon=False)
fig.savefig(os.path.join(out, "figure_eight.png"), dpi=110)

# 2. the pendulum: a libration (period 8) and a rotation (period 4, winding once)
lib = table("tests/periodic/data/pendulum_libration.scene", "--tol", "1e-10")
rot = table("examples/scenes/pendulum_rotation.scene")
fig, ax = plt.subplots(1, 2, figsize=(9, 3.4), layout="constrained")
ax[0].plot(lib["t"], lib["th"])
ax[0].set_title("libration, period 8: th(0) = th(8)", fontsize=10)
ax[1].plot(rot["t"], rot["th"])
ax[1].set_title("rotation, period 4: th(4) = th(0) + 2 pi", fontsize=10)
for a in ax:
    a.set_xlabel("t")
    a.set_ylabel("th")
    a.grid(alpha=0.3)
fig.savefig(os.path.join(out, "pendulum.png"), dpi=110)

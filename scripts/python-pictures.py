#!/usr/bin/env python3
"""scripts/python-pictures.py — the figures of docs/python.md, made with the module itself.

usage: CALCVAR_LIB=build/libcalcvar.so PYTHONPATH=python python3 scripts/python-pictures.py
Writes docs/python/*.png (matplotlib, Debian python3-matplotlib).
SPDX-License-Identifier: MIT
"""
import os

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import calcvar  # noqa: E402

root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
out = os.path.join(root, "docs", "python")
os.makedirs(out, exist_ok=True)

# 1. the geodesic: the path on the sphere in (th, ph) and its error between the nodes
sol = calcvar.solve(os.path.join(root, "tests", "scene", "data", "sphere_geodesic.scene"),
                    elements=8, degree=3)
s = np.linspace(0, 1, 801)
th, ph = sol(s)
th_ex = np.arccos(np.cos(np.pi * s / 2) / 2)
fig, ax = plt.subplots(1, 2, figsize=(10, 4), layout="constrained")
ax[0].plot(np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), label="sol(s)")
ax[0].plot(np.sin(sol["th"]) * np.cos(sol["ph"]), np.sin(sol["th"]) * np.sin(sol["ph"]), "o",
           ms=3, label="nodes")
ax[0].set_aspect("equal")
ax[0].set_xlabel("x = sin th cos ph")
ax[0].set_ylabel("y = sin th sin ph")
ax[0].set_title("Great circle, seen from above")
ax[0].legend(loc="lower left")
ax[1].semilogy(s, np.abs(th - th_ex) + 1e-17)
ax[1].set_xlabel("s")
ax[1].set_title("|th(s) - exact|, 8 elements of degree 3")
fig.savefig(os.path.join(out, "geodesic.png"), dpi=80)

# 2. order of sol between the nodes: h^(p+1)
fig, ax = plt.subplots(figsize=(5.5, 4), layout="constrained")
cat = os.path.join(root, "tests", "scene", "data", "catenary.scene")
for p in (1, 2, 3, 4):
    hs, es = [], []
    for E in (4, 8, 16, 32, 64):
        r = calcvar.solve(cat, elements=E, degree=p)
        xs = np.linspace(-1, 1, 2001)
        hs.append(2 / E)
        es.append(np.max(np.abs(r(xs)[0] - 2 * np.cosh(xs / 2))))
    ax.loglog(hs, es, "o-", label="degree %d" % p)
ax.set_xlabel("element width h")
ax.set_ylabel("max |y_h(x) - y(x)| over [a, b]")
ax.set_title("Catenary: sol(x) converges as h^(p+1)")
ax.legend()
fig.savefig(os.path.join(out, "order.png"), dpi=80)

# 3. a problem built in Python: the hanging chain of given length, with its multiplier
chain = calcvar.Problem(integrand="y*sqrt(1 + y'^2)", interval=(-1, 1),
                        boundary={"y": (0, 0)},
                        integrals={"length": ("sqrt(1 + y'^2)", 3)},
                        guess={"y": "x^2 - 1"})
r = chain.solve(elements=32, degree=4)
x = np.linspace(-1, 1, 401)
fig, ax = plt.subplots(figsize=(5.5, 3.6), layout="constrained")
ax.plot(x, r(x)[0])
ax.set_aspect("equal")
ax.set_title("Hanging chain of length 3 (mu = %.6f)" % r.report["multipliers"]["length"])
ax.set_xlabel("x")
ax.set_ylabel("y")
fig.savefig(os.path.join(out, "chain.png"), dpi=80)
print("docs/python/geodesic.png docs/python/order.png docs/python/chain.png")

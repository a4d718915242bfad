"""tests/python/test_c1.py — second derivatives from Python: a Problem with y'' strings
and a slope key in its boundary (written as a scene, docs/beams.md), against the closed
form of a cantilever (values exact to round-off on quintic elements, natural conditions
at the free end through the fourth-order Euler-Lagrange equation of `equations`).
SPDX-License-Identifier: MIT
"""
import numpy as np

import calcvar


def cantilever(**kw):
    return calcvar.Problem("EI/2*w''^2 - q*w", (0, 1.5), {"w": (0, None), "w'": (0, None)},
                           parameters={"EI": 2, "q": 3},
                           exact={"w": "q*x^2*(6*1.5^2 - 4*1.5*x + x^2)/(24*EI)"},
                           mesh={"elements": 4, "degree": 5}, **kw)


def test_cantilever_values():
    r = cantilever().solve()
    assert r.status == "converged"
    x = np.asarray(r.x)
    exact = 3 * x ** 2 * (6 * 1.5 ** 2 - 4 * 1.5 * x + x ** 2) / 48
    assert np.max(np.abs(np.asarray(r.values).reshape(-1) - exact)) < 1e-13  # quartic in p = 5
    assert r.degree == 5 and r.morse_index == 0


def test_cantilever_equations():
    el = cantilever().equations()["euler_lagrange"]["w"].replace(" ", "")
    assert el == "2*w''''-3"

"""tests/python/test_new_kinds.py — periodic unknowns, obstacles and moving ends from
Python (Problem(boundary={'th': 'periodic'}), constraints 'G >= 0', ends=), against the
exact answers the command's tests use (docs/periodic.md, obstacles.md, moving-ends.md).
SPDX-License-Identifier: MIT
"""
import math

import pytest

import calcvar


def test_periodic_libration():
    # elliptic functions: action 6.68858249672602 over the period 8
    p = calcvar.Problem("th'^2/2 + cos(th)", (0, 8), {"th": "periodic"}, variable="t",
                        guess={"th": "1.5*cos(2*pi*t/8)"})
    s = calcvar.solve(p, tol=1e-10)
    assert s.status == "converged"
    assert abs(s.action - 6.68858249672602) <= 1e-9
    assert s.report["pinned"] == ["shift"] and s.report["period"] == 8
    assert abs(s["th"][0] - s["th"][-1]) <= 1e-12  # closed


def test_obstacle_bump():
    # tangent lines and the parabola: length 4.49071475164684, contact +-(2 - sqrt 3)
    p = calcvar.Problem("sqrt(1 + y'^2)", (-2, 2), {"y": (0, 0)},
                        constraints={"over": "y - (1 - x^2) >= 0"},
                        guess={"y": "1.5*(1 - x^2/4)"})
    s = calcvar.solve(p, tol=1e-10)
    assert s.status == "converged"
    assert abs(s.action - 4.49071475164684) <= 1e-9
    (x0, x1), = s.report["contact"]["over"]
    assert abs(x0 - (math.sqrt(3) - 2)) <= 3e-5 and abs(x1 - (2 - math.sqrt(3))) <= 3e-5
    lam = s["lambda_over"]
    assert max(lam) == 0.0 and min(lam) < -1.9  # lambda <= 0, -2 at the top


def test_moving_end_on_circle():
    # the segment towards the centre (3, 2): end at x = 3 (1 - 1/sqrt 13), length sqrt 13 - 1
    p = calcvar.Problem("sqrt(1 + y'^2)", (0, 2), {"y": (0, "free")},
                        ends={"end": "(x - 3)^2 + (y - 2)^2 - 1"})
    s = calcvar.solve(p, tol=1e-10)
    assert s.status == "converged"
    assert abs(s.action - (math.sqrt(13) - 1)) <= 1e-9
    assert abs(s.report["interval"][1] - 3 * (1 - 1 / math.sqrt(13))) <= 1e-9


def test_bad_new_kinds():
    with pytest.raises(calcvar.InputError, match="periodic"):
        calcvar.solve(calcvar.Problem("y'^2", (0, 1), {"y": "periodic, 0"}))
    with pytest.raises(calcvar.InputError, match="0 on the right"):
        calcvar.solve(calcvar.Problem("y'^2", (0, 1), {"y": (0, 0)},
                                      constraints={"c": "y >= 1"}))
    with pytest.raises(calcvar.InputError):
        calcvar.Problem("y'^2", (0, 1), {"y": (0, 0)}, ends={"middle": "free"})

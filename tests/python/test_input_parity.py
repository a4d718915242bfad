"""tests/python/test_input_parity.py — Python-native input (numpy numbers, sympy, the hints
and refusals) and what the command and the C API offer (multiplier fields, array guesses,
warm starts, batch, scipy-like shapes), each against an exact or independent answer.
SPDX-License-Identifier: MIT
"""
import math
import os

import numpy as np
import pytest

import calcvar

SCENES = os.environ.get("CALCVAR_SCENES", os.path.join(os.path.dirname(__file__), "..",
                                                       "scene", "data"))
CAT = calcvar.Problem("y*sqrt(1 + y'^2)", (-1, 1), {"y": ("c*cosh(1/c)", "c*cosh(1/c)")},
                      parameters={"c": 2}, title="Catenary")
EXACT = 2 + 2 * math.sinh(1)  # the catenary's action for c = 2


def test_numpy_numbers_everywhere():
    """np.int64 / np.float64 / 0-d arrays as options, parameters and interval ends give
    the solve of the plain numbers, bit for bit."""
    a = CAT.solve(elements=np.int64(8), degree=np.int32(4), set={"c": np.float64(2.0)},
                  tolerance=np.float32(1e-10))
    b = CAT.solve(elements=8, degree=4, set={"c": 2}, tolerance=float(np.float32(1e-10)))
    assert a.action == b.action and np.array_equal(a.y, b.y)
    p = calcvar.Problem("y'^2/2", (np.float64(0), np.array(1.0)), {"y": (np.int64(0), 1)})
    s = p.solve(elements=2, degree=1)
    assert np.max(np.abs(s["y"] - s.x)) < 1e-14          # the straight line, exact
    with pytest.raises(ValueError, match="whole number"):
        CAT.solve(elements=np.float64(8.5))
    with pytest.raises(ValueError, match="a number is needed"):
        CAT.solve(degree=True)


def test_powers_hint_and_comment_characters():
    with pytest.raises(ValueError, match=r"use \^ for powers"):
        calcvar.Problem("y*sqrt(1 + y'**2)", (-1, 1), {"y": (1, 1)})
    text = "[scene]\ninterval = 0, 1\nunknowns = y\nintegrand = y'**2\n[boundary]\ny = 0, 1\n"
    with pytest.raises(ValueError, match=r"use \^ for powers"):
        calcvar.solve(text)
    # '#' and ';' start comments in a scene: refused in expressions, not cut silently
    for bad in ("y'^2 # half", "y'^2; y"):
        with pytest.raises(ValueError, match="cannot appear in an expression"):
            calcvar.Problem(bad, (0, 1), {"y": (0, 1)})
    with pytest.raises(ValueError, match="cannot appear"):
        calcvar.Problem("y'^2", (0, 1), {"y": (0, 1)}, definitions={"k": "2 ;3"})
    # a title is any text, kept whole in the Solution and its report
    title = "Chain #2; c = 2 # m"
    s = calcvar.Problem("y'^2/2", (0, 1), {"y": (0, 1)}, title=title).solve(elements=2)
    assert s.title == title and s.report["title"] == title


def test_python_callable_is_a_clear_type_error():
    with pytest.raises(TypeError, match="Python function cannot be used.*sympy"):
        calcvar.Problem(lambda x, y, yp: y * np.sqrt(1 + yp**2), (-1, 1), {"y": (1, 1)})


def test_sympy_integrand_constraint_and_guess():
    sp = pytest.importorskip("sympy")
    x = sp.Symbol("x")
    y = sp.Function("y")(x)
    F = y * sp.sqrt(1 + y.diff(x)**2)
    c = sp.Integer(2)
    p = calcvar.Problem(F, (-1, 1), {"y": (c * sp.cosh(1 / c), c * sp.cosh(1 / c))},
                        guess={"y": 2 + x**2 / 4})
    s = p.solve(elements=16, degree=4)
    assert abs(s.action - EXACT) < 1e-10
    assert np.max(np.abs(s["y"] - 2 * np.cosh(s.x / 2))) < 1e-9
    # a constraint and an integral written in sympy: the chain of length 3 on [-1, 1]
    yp = sp.Symbol("y'")
    chain = calcvar.Problem(sp.Symbol("y") * sp.sqrt(1 + yp**2), (-1, 1), {"y": (0, 0)},
                            integrals={"length": (sp.sqrt(1 + yp**2), 3)},
                            guess={"y": x**2 - 1})
    r = chain.solve(elements=32, degree=4)
    assert r.report["multipliers"]["length"] == pytest.approx(r.multipliers["length"])
    with pytest.raises(TypeError, match="no counterpart"):
        calcvar.Problem(sp.gamma(y), (0, 1), {"y": (0, 1)})


def test_multiplier_fields_and_integral_multipliers():
    """Pendulum in Cartesian coordinates: the rod's multiplier field s['lambda_NAME'] is
    the one the command writes (CSV lambda_NAME), and the chain's mu_length is the
    report's multiplier. u = v enforced with F = (u'^2 + v'^2)/2 + u: u = v = (t^2 - t)/4,
    and lambda = -1/2 exactly (from u'' = 1 + lambda, v'' = -lambda)."""
    p = calcvar.Problem("(u'^2 + v'^2)/2 + u", (0, 1), {"u": (0, 0), "v": (0, 0)},
                        variable="t", constraints={"same": "u - v"})
    s = p.solve(elements=4, degree=2)
    assert "lambda_same" in s.keys()
    assert np.max(np.abs(np.abs(s["lambda_same"]) - 0.5)) < 1e-9
    assert s["lambda_same"].shape == s.x.shape
    chain = calcvar.Problem("y*sqrt(1 + y'^2)", (-1, 1), {"y": (0, 0)},
                            integrals={"length": ("sqrt(1 + y'^2)", 3)},
                            guess={"y": "x^2 - 1"})
    r = chain.solve(elements=32, degree=4)
    assert r["mu_length"] == r.report["multipliers"]["length"] == r.multipliers["length"]
    with pytest.raises(KeyError, match="lambda_length"):
        r["lambda_length"]


def test_array_guess_and_warm_start():
    """Bratu (lambda = 1) has two paths; a guess near the upper one, given as arrays
    (scipy's (x, y)), lands on it; a warm start from a Solution on another mesh converges
    in at most 2 Newton steps to the same path (to 1e-7; the paths are 4 apart)."""
    bratu = "[scene]\ninterval = 0, 1\nunknowns = y\nintegrand = y'^2/2 - exp(y)\n" \
            "[boundary]\ny = 0, 0\n"
    low = calcvar.solve(bratu, elements=16, degree=6)
    xg = np.linspace(0, 1, 11)
    high = calcvar.solve(bratu, elements=16, degree=6, guess=(xg, 16 * xg * (1 - xg)))
    assert high.success and high.morse_index == 1 and low.morse_index == 0
    assert high.action > low.action + 1
    warm = calcvar.solve(bratu, elements=24, degree=6, guess=high)
    assert warm.success and warm.iterations <= 2
    # the same path: they differ by the two meshes' discretisation errors (~1e-9 here)
    assert np.max(np.abs(warm(xg) - high(xg))) < 1e-7
    with pytest.raises(ValueError, match="shape"):
        calcvar.solve(bratu, guess=(xg, np.zeros((2, 11))))
    with pytest.raises(TypeError, match="Solution or a pair"):
        calcvar.solve(bratu, guess="x")


def test_scipy_like_shapes_and_interpolant():
    """x (m,), y (n, m), yp (n, m), sol.sol(x); the numpy interpolant agrees with the C
    library's (cv_solver_eval) to 1e-13 between the nodes, and y' with the exact slope."""
    s = calcvar.solve(os.path.join(SCENES, "sphere_geodesic.scene"), elements=8, degree=5)
    n, m = len(s.unknowns), s.x.size
    assert s.y.shape == (n, m) and s.yp.shape == (n, m) and s.values.shape == (m, n)
    a, b = s.interval
    xs = np.linspace(a, b, 301)
    mine, dmine = s.sol(xs, derivative=True)
    h = s._hold
    from calcvar._lib import lib
    y, dy = np.empty((n, xs.size)), np.empty((n, xs.size))
    lib.cv_solver_eval(h.solver, xs.size, xs.ctypes.data, y.ctypes.data, dy.ctypes.data)
    assert np.max(np.abs(mine - y)) < 1e-13 and np.max(np.abs(dmine - dy)) < 1e-11
    with pytest.raises(ValueError, match="must lie in"):
        s(b + 1)
    c = CAT.solve(elements=16, degree=4)
    assert np.max(np.abs(c.yp[0] - np.sinh(c.x / 2))) < 1e-8


def test_batch_structured_array():
    """calcvar.batch over c: each row's action is c (1 + (c/2) sinh(2/c)) (the catenary's
    exact action) to 1e-8 on 16 elements of degree 4; rows in input order; a row that
    makes the scene invalid is refused naming the row."""
    cs = np.array([1.5, 2.0, 2.5, 3.0, 4.0])
    out = calcvar.batch(CAT, {"c": cs}, threads=2, elements=16, degree=4)
    assert out.dtype.names[:3] == ("c", "status", "action")
    exact = cs * (1 + cs / 2 * np.sinh(2 / cs))
    assert np.all(out["status"] == "converged")
    assert np.max(np.abs(out["action"] - exact)) < 1e-8
    assert np.array_equal(out["c"], cs)
    warm = calcvar.batch(CAT, {"c": cs}, threads=1, warm=True, elements=16, degree=4)
    assert np.max(np.abs(warm["action"] - exact)) < 1e-8 and warm["warm"][1:].all()
    with pytest.raises(ValueError, match="not a parameter|unknown|column"):
        calcvar.batch(CAT, {"k": [1.0]})
    # c = 0 makes the ends c cosh(1/c) infinite: refused naming the row, before solving
    with pytest.raises(ValueError, match=r"table row 1: <string>:\d+: \[boundary\] y at a "
                                         r"is not a finite number"):
        calcvar.batch(CAT, {"c": [2.0, 0.0]})
    with pytest.raises(ValueError, match="finite"):
        calcvar.batch(CAT, {"c": [np.nan]})
    clash = calcvar.Problem("y'^2/2", (0, 1), {"y": (0, "status")}, parameters={"status": 1})
    with pytest.raises(ValueError, match="name of a result column"):
        calcvar.batch(clash, {"status": [1.0]})


def test_plot_and_html():
    """plot() draws sol(x) and the nodes (the drawn data are the solution's own values);
    _repr_html_ escapes the title."""
    mpl = pytest.importorskip("matplotlib")
    mpl.use("Agg")
    s = calcvar.Problem("y'^2/2", (0, 1), {"y": (0, 1)}, title="<b>line</b>").solve(
        elements=4, degree=2)
    ax = s.plot(points=11)
    curve, dots = ax.get_lines()
    assert np.allclose(curve.get_ydata(), s(np.linspace(0, 1, 11))[0], atol=0, rtol=0)
    assert np.array_equal(dots.get_xdata(), s.x)
    html = s._repr_html_()
    assert "&lt;b&gt;line&lt;/b&gt;" in html and "converged" in html

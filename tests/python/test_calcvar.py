"""tests/python/test_calcvar.py — the Python module against exact answers.

Run by `meson test` (suite python) with PYTHONPATH, CALCVAR_LIB (the built libcalcvar.so),
CALCVAR_EXE (the built command) and CALCVAR_SCENES (tests/scene/data) set.
Tolerances are stated where used; the order test compares errors on two meshes.
SPDX-License-Identifier: MIT
"""
import json
import math
import os
import subprocess
import threading

import numpy as np
import pytest

import calcvar

SCENES = os.environ.get("CALCVAR_SCENES", os.path.join(os.path.dirname(__file__), "..",
                                                       "scene", "data"))
EXE = os.environ.get("CALCVAR_EXE", "calcvar")

CATENARY = """[scene]
title = Catenary
interval = -1, 1
unknowns = y
integrand = y * sqrt(1 + y'^2)
[parameters]
c = 2
[boundary]
y = c*cosh(1/c), c*cosh(1/c)
[exact]
y = c*cosh(x/c)
"""


def scene(name):
    return os.path.join(SCENES, name)


def test_geodesic_in_three_lines():
    sol = calcvar.solve(scene("sphere_geodesic.scene"), elements=16, degree=4)
    assert sol.status == "converged" and sol.success
    s = sol.x
    th = np.arccos(np.cos(np.pi * s / 2) / 2)
    ph = np.arctan2(np.sin(np.pi * s / 2), np.sqrt(3) / 2 * np.cos(np.pi * s / 2))
    # 16 elements of degree 4: 2e-11 measured, bound 1e-9
    err = max(np.max(np.abs(sol["th"] - th)), np.max(np.abs(sol.ph - ph)))
    assert err < 1e-9
    # numpy's exact values against the library's [exact] evaluation in the report
    assert sol.report["error"]["max_nodal"] == pytest.approx(err, rel=1e-6, abs=1e-14)
    assert sol.morse_index == 0
    assert sol.report["report"]["length"] == pytest.approx(math.pi / 2, abs=1e-9)


def test_catenary_text_and_options():
    sol = calcvar.solve(CATENARY, elements=32, degree=4)
    assert (sol.elements, sol.degree, sol.x.size) == (32, 4, 129)
    assert np.max(np.abs(sol.y - 2 * np.cosh(sol.x / 2))) < 1e-10
    # set= overrides a parameter: c = 3
    sol3 = calcvar.solve(CATENARY, elements=16, degree=4, set={"c": 3})
    assert np.max(np.abs(sol3.y - 3 * np.cosh(sol3.x / 3))) < 1e-9


def test_values_are_views_in_node_major_layout():
    sol = calcvar.solve(scene("sphere_geodesic.scene"))
    assert sol.values.shape == (sol.x.size, 2)
    assert np.shares_memory(sol["th"], sol.values)   # no copy per unknown
    assert sol["s"] is sol.x                         # the variable gives the nodes
    with pytest.raises(KeyError):
        sol["nosuch"]


def test_saddle_morse_index():
    sol = calcvar.solve(scene("harmonic_saddle.scene"))
    assert sol.status == "converged"
    assert sol.morse_index == 1
    assert sol.report["stationary_kind"] == "saddle"


@pytest.mark.parametrize("degree", [2, 3])
def test_sol_between_nodes_converges_at_the_interpolant_order(degree):
    """Between the nodes the error of the degree-p interpolant is O(h^(p+1))."""
    errors = []
    for elements in (8, 16):
        sol = calcvar.solve(CATENARY, elements=elements, degree=degree)
        h = 2.0 / elements
        xs = -1 + h * (np.arange(elements) + 0.3)  # 0.3 of each element: no GLL node there
        y = sol(xs)
        assert y.shape == (1, elements)
        errors.append(np.max(np.abs(y[0] - 2 * np.cosh(xs / 2))))
    order = math.log2(errors[0] / errors[1])
    assert errors[1] > 1e-13  # above round-off, so the order means something
    assert degree + 1 - 0.4 <= order <= degree + 1 + 0.6, (errors, order)


def test_sol_scalar_and_derivative():
    sol = calcvar.solve(CATENARY, elements=32, degree=4)
    y, dy = sol(0.37, derivative=True)
    assert y.shape == (1,) and dy.shape == (1,)
    assert y[0] == pytest.approx(2 * math.cosh(0.185), abs=1e-9)
    assert dy[0] == pytest.approx(math.sinh(0.185), abs=1e-7)
    with pytest.raises(ValueError, match="must lie in"):
        sol(1.5)


def test_report_is_the_commands():
    path = scene("catenary.scene")
    sol = calcvar.solve(path)
    r = subprocess.run([EXE, "solve", path, "--json", "-"], capture_output=True, text=True,
                       check=True)
    cli = json.loads(r.stdout)
    assert set(sol.report) == set(cli)
    assert sol.report["schema"] == cli["schema"] == 1
    for key in ("status", "message", "method", "elements", "degree", "nodes", "unknowns",
                "iterations", "morse_index", "stationary_kind"):
        assert sol.report[key] == cli[key], key
    # the same computation: the same numbers (printed with 17 digits)
    assert sol.report["action"] == cli["action"]
    assert sol.report["error"] == cli["error"]
    assert sol.status == cli["status"]


def test_problem_isoperimetric():
    """min int y'^2/2 with int y = 1, y(0) = y(1) = 0: y = 6(x - x^2), quadratic, so degree
    2 reproduces it to round-off (bound 1e-10)."""
    p = calcvar.Problem(integrand="y'^2/2", interval=(0, 1), boundary={"y": (0, 0)},
                        integrals={"area": ("y", 1)})
    sol = p.solve(elements=8, degree=2)
    xs = np.linspace(0, 1, 37)
    assert np.max(np.abs(sol(xs)[0] - 6 * (xs - xs**2))) < 1e-10
    assert abs(sol.report["multipliers"]["area"]) == pytest.approx(12, abs=1e-8)


def test_problem_pointwise_constraint_and_free_end():
    # u = v enforced; F = (u'^2 + v'^2)/2 + u: u = v = (t^2 - t)/4 (quadratic, exact)
    p = calcvar.Problem(integrand="(u'^2 + v'^2)/2 + u", interval=(0, 1), variable="t",
                        boundary={"u": (0, 0), "v": (0, 0)}, constraints={"same": "u - v"})
    sol = p.solve(elements=4, degree=2)
    t = sol.x
    assert np.max(np.abs(sol.u - (t * t - t) / 4)) < 1e-10
    assert np.max(np.abs(sol.v - (t * t - t) / 4)) < 1e-10
    # free end: min int y'^2/2 + y, y(0) = 0, y'(1) = 0: y = x^2/2 - x
    q = calcvar.Problem(integrand="y'^2/2 + y", interval=(0, 1), boundary={"y": (0, None)})
    s2 = q.solve(elements=4, degree=2)
    assert np.max(np.abs(s2["y"] - (s2.x**2 / 2 - s2.x))) < 1e-10


def test_problem_equations():
    p = calcvar.Problem(integrand="m*q'^2/2 - k*q^2/2", interval=(0, 1),
                        boundary={"q": (0, 1)}, parameters={"m": 2, "k": 3})
    eq = p.equations()  # from the library since cv_equations_json
    assert set(eq) >= {"momenta", "euler_lagrange", "hamiltonian"}
    assert "q'" in eq["momenta"]["q"]


@pytest.mark.parametrize("text, where", [
    ("[scene]\ninterval = 0, 1\nunknowns = y\nintegrand = y'^^2\n[boundary]\ny = 0, 1\n",
     "<string>:4:"),
    ("[scene]\ninterval = 1, 0\nunknowns = y\nintegrand = y'^2\n[boundary]\ny = 0, 1\n",
     "<string>:2:"),
    ("[scene]\ninterval = 0, 1\nunknowns = y\nintegrand = y'^2\n", "<string>:"),
])
def test_bad_scene_text_raises_value_error_with_file_line(text, where):
    with pytest.raises(ValueError) as e:
        calcvar.solve(text)
    assert str(e.value).startswith(where)
    assert e.value.status == "CVAR_EINVAL"
    assert isinstance(e.value, calcvar.CalcvarError)


def test_bad_options_raise():
    with pytest.raises(ValueError, match="nosuch.scene"):
        calcvar.solve("nosuch.scene")
    with pytest.raises(ValueError, match="degree"):
        calcvar.solve(CATENARY, degree=9)
    with pytest.raises(ValueError, match="elements"):
        calcvar.solve(CATENARY, elements=0)
    with pytest.raises(ValueError, match="unknown method"):
        calcvar.solve(CATENARY, method="simplex")
    with pytest.raises(ValueError, match="nosuch"):
        calcvar.solve(CATENARY, set={"nosuch": 1})
    with pytest.raises(ValueError):
        calcvar.solve(CATENARY, elements="many")
    with pytest.raises(TypeError):
        calcvar.solve(42)
    with pytest.raises(ValueError, match="NUL"):
        calcvar.solve(CATENARY + "\0")
    with pytest.raises(ValueError):
        calcvar.Problem(integrand="y'^2", interval=(0, 1), boundary={"y": (0, "oops(")})


def test_versions():
    assert calcvar.version() == "0.1.0"
    assert calcvar.dependency_versions().startswith("CHOLMOD ")


def test_tol_chooses_the_mesh():
    # as `calcvar solve --tol`: the estimate is at most T, the true error below 10 T and
    # not far above the estimate; degrees per element add up to the nodes
    for T in (1e-6, 1e-10):
        sol = calcvar.solve(CATENARY, tol=T)
        assert sol.status == "converged"
        r = sol.report
        assert r["error_estimate"] <= T
        true = np.max(np.abs(sol["y"] - 2 * np.cosh(sol.x / 2)))
        assert true <= 10 * T and r["error_estimate"] >= 0.1 * true
        assert r["nodes"] == 1 + sum(r["degrees"]) and r["degree"] == max(r["degrees"])
    with pytest.raises(ValueError, match="together"):
        calcvar.solve(CATENARY, tol=1e-8, adapt=1e-8)


def test_tol_same_as_the_command():
    # the same start, rounds and mesh as `calcvar solve SCENE --tol T` (the harmonic
    # oscillator has no [mesh]: both start from 4 elements of degree 4), the JSON identical
    # but for the time
    path = scene("harmonic_saddle.scene")
    sol = calcvar.solve(path, tol=1e-12)
    out = subprocess.run([EXE, "solve", path, "--tol", "1e-12", "--json", "-", "--quiet"],
                         capture_output=True, text=True, check=True).stdout
    cmd = json.loads(out)
    for r in (cmd, sol.report):
        r.pop("time_s", None)
    assert sol.report == cmd
    # the caps: a cap on the nodes below what 1e-12 needs ends the rounds with the
    # estimate reached; a bad cap is refused
    capped = calcvar.solve(path, tol=1e-12, max_nodes=30)
    assert capped.status == "max_iterations" and capped.report["nodes"] <= 30
    assert "cap of 30 nodes" in capped.report["message"]
    assert capped.report["error_estimate"] > 1e-12
    with pytest.raises(ValueError, match="max_nodes"):
        calcvar.solve(path, tol=1e-12, max_nodes=1)
    with pytest.raises(ValueError, match="time_limit"):
        calcvar.solve(path, tol=1e-12, time_limit=0)


BRATU = """[scene]
title = Bratu
interval = 0, 1
unknowns = y
integrand = y'^2/2 - exp(y)
[boundary]
y = 0, 0
"""


def _bisect(g, lo, hi):
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if g(lo) * g(mid) > 0 else (lo, mid)
    return 0.5 * (lo + hi)


def test_all_paths_bratu():
    """Bratu's problem, lambda = 1: two stationary paths y = -2 log(cosh((x - 1/2) t/2) /
    cosh(t/4)) with t = sqrt(2) cosh(t/4) (two roots), a minimum and a saddle; 24 elements
    of degree 8 reach 1e-10 (the command's test uses the same bound)."""
    sols = calcvar.solve(BRATU, elements=24, degree=8, all=True)
    assert isinstance(sols, calcvar.Solutions) and len(sols) == 2
    assert sols.search["found"] == 2 and sols.search["starts"] >= 2
    g = lambda t: t - math.sqrt(2.0) * math.cosh(t / 4)  # noqa: E731
    for sol, theta, morse in zip(sols, (_bisect(g, 0.5, 4.0), _bisect(g, 4.0, 20.0)), (0, 1)):
        x = np.linspace(0, 1, 101)
        exact = -2 * np.log(np.cosh((x - 0.5) * theta / 2) / np.cosh(theta / 4))
        assert np.max(np.abs(sol(x)[0] - exact)) < 1e-10    # between the nodes too
        assert np.max(np.abs(sol.y - (-2 * np.log(np.cosh((sol.x - 0.5) * theta / 2)
                                                  / np.cosh(theta / 4))))) < 1e-10
        assert sol.morse_index == morse
        assert sol.report["morse_index"] == morse
    assert sols[0].action < sols[1].action
    assert [s.report["stationary_kind"] for s in sols] == ["minimum", "saddle"]
    with pytest.raises(ValueError, match="max_paths"):
        calcvar.solve(BRATU, all=True, max_paths=0)
    one = calcvar.solve(BRATU, elements=24, degree=8, all=True, max_paths=1)
    assert len(one) == 1


def test_progress_and_cancel():
    seen = []
    sol = calcvar.solve(CATENARY, elements=16, degree=2, progress=seen.append)
    assert sol.success and len(seen) == sol.iterations >= 2
    assert [d["iteration"] for d in seen] == list(range(1, len(seen) + 1))
    assert seen[-1]["residual"] < seen[0]["residual"]
    assert all(d["kind"] == "newton" and d["elements"] == 16 for d in seen)
    stopped = calcvar.solve(CATENARY, elements=16, degree=2, progress=lambda d: True)
    assert not stopped.success and "cancelled" in stopped.message
    assert stopped.status_code == "CVAR_ECANCELLED"

    def boom(d):
        raise RuntimeError("from the callback")
    with pytest.raises(RuntimeError, match="from the callback"):
        calcvar.solve(CATENARY, elements=16, degree=2, progress=boom)


def test_adaptive_rounds_reported():
    rounds = []
    sol = calcvar.solve(CATENARY, elements=4, degree=2, adapt=1e-8,
                        progress=lambda d: rounds.append(d) if d["kind"] == "round" else None)
    assert sol.success
    assert len(rounds) >= 2
    assert rounds[-1]["estimate"] <= 1e-8 < rounds[0]["estimate"]
    assert "error_estimate" not in sol.report  # [exact] given: the true error instead
    assert sol.report["error"]["max_nodal"] < 1e-7


def test_solves_in_threads():
    """Distinct solutions from distinct threads (ctypes releases the GIL in cv_solve)."""
    out = {}

    def work(c):
        s = calcvar.solve(CATENARY, elements=16, degree=4, set={"c": c})
        out[c] = np.max(np.abs(s.y - c * np.cosh(s.x / c)))

    threads = [threading.Thread(target=work, args=(c,)) for c in (2, 3, 4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert sorted(out) == [2, 3, 4] and max(out.values()) < 1e-9


# ---- mechanics from the library (cv_equations / cv_modes, no subprocess) ----------------

def _evaluate(expr, values):
    """An expression printed by calcvar (scene grammar) at the given values: y'' -> y_pp,
    y' -> y_p, ^ -> **; math's functions."""
    import re
    py = re.sub(r"(\w+)''", r"\1_pp", expr)
    py = re.sub(r"(\w+)'", r"\1_p", py).replace("^", "**")
    env = {k: getattr(math, k) for k in ("sin", "cos", "tan", "exp", "log", "sqrt",
                                          "sinh", "cosh", "tanh")}
    env.update(values)
    return eval(py, {"__builtins__": {}}, env)  # noqa: S307 — our own library's text


@pytest.fixture
def no_subprocess(monkeypatch):
    def refuse(*_a, **_k):
        raise AssertionError("a subprocess was started")
    monkeypatch.setattr(subprocess, "run", refuse)
    monkeypatch.setattr(subprocess, "Popen", refuse)


def test_pendulum_euler_lagrange_exact(no_subprocess):
    # L = m l^2 th'^2/2 + m g l cos th: p = m l^2 th', E = m l^2 th'' + m g l sin th,
    # H = m l^2 th'^2/2 - m g l cos th (theory (P-3)..(P-5)); compared at random points to
    # 1e-12 relative (the printed numbers are the shortest exact decimals).
    m, l, g = 2.0, 1.5, 9.81
    p = calcvar.Problem(integrand="m*l^2*th'^2/2 + m*g*l*cos(th)", interval=(0, 0.5),
                        boundary={"th": (0, 1)}, variable="t",
                        parameters={"m": m, "l": l, "g": g})
    eq = p.equations()
    assert eq["cyclic"] == [] and eq["autonomous"] is True
    rng = np.random.default_rng(1)
    for th, thp, thpp in rng.uniform(-2, 2, size=(20, 3)):
        v = {"th": th, "th_p": thp, "th_pp": thpp}
        exact_el = m * l * l * thpp + m * g * l * math.sin(th)
        exact_p = m * l * l * thp
        exact_h = m * l * l * thp**2 / 2 - m * g * l * math.cos(th)
        for got, want in ((eq["euler_lagrange"]["th"], exact_el), (eq["momenta"]["th"], exact_p),
                          (eq["hamiltonian"], exact_h)):
            assert abs(_evaluate(got, v) - want) <= 1e-12 * (1 + abs(want)), got


def test_free_particle_is_cyclic_and_scene_functions(no_subprocess):
    # F = y'^2/2 + z'^2/2 - x*z: y cyclic (p_y conserved), F depends on x: not autonomous
    text = ("[scene]\ninterval = 0, 1\nunknowns = y, z\nintegrand = y'^2/2 + z'^2/2 - x*z\n"
            "[boundary]\ny = 0, 1\nz = 0, 1\n")
    eq = calcvar.equations(text)
    assert eq["cyclic"] == ["y"] and eq["autonomous"] is False


def test_double_pendulum_modes_exact(no_subprocess):
    # equal masses and lengths: w^2 = (g/l)(2 -+ sqrt 2), shapes b = +-sqrt(2) a; relative
    # tolerance 1e-10 (a 2x2 generalised eigenproblem, exact to round-off)
    g, l = 9.81, 2.0
    md = calcvar.modes(scene("double_pendulum.scene"), set={"l": l})
    assert md["equilibrium"] == pytest.approx({"a": 0.0, "b": 0.0}, abs=1e-12)
    w2 = [k["omega2"] for k in md["modes"]]
    exact = [g / l * (2 - math.sqrt(2)), g / l * (2 + math.sqrt(2))]
    assert w2 == pytest.approx(exact, rel=1e-10)
    assert [k["kind"] for k in md["modes"]] == ["stable", "stable"]
    for k, sign in zip(md["modes"], (1, -1)):
        assert k["shape"]["b"] / k["shape"]["a"] == pytest.approx(sign * math.sqrt(2),
                                                                  rel=1e-10)


def test_mechanics_equals_the_command():
    # the library and `calcvar equations|modes --json` share one builder: same document
    # (with a constraint's multiplier and with gyroscopic terms too)
    for cmd, fn in (("equations", calcvar.equations), ("modes", calcvar.modes)):
        for name in ("double_pendulum.scene", "pendulum_angle.scene", "pendulum_cartesian.scene",
                     os.path.abspath(os.path.join(SCENES, "..", "..", "physics", "data",
                                                  "magnetic_trap.scene"))):
            r = subprocess.run([EXE, cmd, scene(name), "--json", "-"], capture_output=True,
                               text=True, check=True)
            assert fn(scene(name)) == json.loads(r.stdout)


def test_modes_errors(no_subprocess):
    # the Lagrangian depends on the variable: modes do not apply -> ValueError, FILE:LINE
    p = calcvar.Problem(integrand="y'^2/2 + x*y", interval=(0, 1), boundary={"y": (0, 1)})
    with pytest.raises(ValueError) as e:
        p.modes()
    assert str(e.value).startswith("<string>:") and e.value.status == "CVAR_EINVAL"
    # a force nothing balances: no equilibrium -> CalcvarError, not ValueError
    q = calcvar.Problem(integrand="y'^2/2 + y", interval=(0, 1), boundary={"y": (0, 1)})
    with pytest.raises(calcvar.CalcvarError) as e:
        q.modes()
    assert not isinstance(e.value, ValueError)
    assert e.value.status == "CVAR_EMAXITER" and "no equilibrium" in str(e.value)
    with pytest.raises(ValueError, match="nosuch.scene"):
        calcvar.equations("nosuch.scene")

"""calcvar._solution — Solution: the result of one solve, an object that owns its data.

A Solution holds its nodes and nodal values as numpy arrays of its own, evaluates itself
between the nodes in numpy (_interp.py), and keeps the C handles of its solve (scene,
problem, solver) privately, behind a lock, only to read the rest on first use and to
build its report. No two Solutions share handles, except copies of one (copy.copy,
copy.deepcopy), which read them under the same lock. Pickling reads everything first
(the report too, which may cost a reference solve) and carries no handle, so a Solution
can cross processes (multiprocessing, fork or spawn) and threads.
SPDX-License-Identifier: MIT
"""
from __future__ import annotations

import copy
import ctypes
import json
import threading

import numpy as np

from . import _lib
from ._errors import CalcvarError, InputError, status_name, status_word
from ._interp import Interpolant
from ._interrupt import Guard
from ._lib import lib


class Handles:
    """The scene, problem and solver of one solve; freed once, with the last owner."""

    __slots__ = ("scene", "problem", "solver", "keep", "lock", "owned")
    _live = 0  # handle triples not yet freed (the tests check that nothing leaks)
    _count_lock = threading.Lock()

    def __init__(self):
        self.scene = self.problem = self.solver = None
        self.keep = []  # ctypes callbacks the library holds (guess)
        self.owned = False  # a Solution holds them
        self.lock = threading.RLock()
        with Handles._count_lock:
            Handles._live += 1

    def free(self):
        with self.lock:
            solver, problem, scene = self.solver, self.problem, self.scene
            if self.keep is None:
                return
            self.solver = self.problem = self.scene = None
            self.keep = None
            # in this order: a problem refers to its scene
            if solver:
                lib.cv_solver_free(solver)
            if problem:
                lib.cv_problem_free(problem)
            if scene:
                lib.cv_scene_free(scene)
            with Handles._count_lock:
                Handles._live -= 1

    @staticmethod
    def live():
        """Handle triples made and not yet freed (the tests check that nothing leaks)."""
        return Handles._live

    def __del__(self):
        try:
            self.free()
        except (AttributeError, TypeError):  # the interpreter is shutting down
            pass

    def __deepcopy__(self, memo):
        return self  # copies of a Solution share the (immutable, locked) handles

    def __reduce__(self):
        raise TypeError("calcvar's C handles cannot be pickled (a Solution pickles its data)")


def _text(p):
    return p.decode(errors="replace") if p else ""


def read_fields(h):
    """Everything a Solution reports, read from its handles (the selected path)."""
    sc, pr, sv = h.scene, h.problem, h.solver
    a, b = ctypes.c_double(), ctypes.c_double()
    lib.cv_problem_get_interval(pr, ctypes.byref(a), ctypes.byref(b))
    ne = lib.cv_solver_get_degrees(sv, None)
    degrees = np.zeros(max(ne, 0), dtype=np.intc)
    if ne > 0:
        lib.cv_solver_get_degrees(sv, degrees.ctypes.data)
    nn = lib.cv_solver_get_num_nodes(sv)
    lambdas, mus = {}, {}
    for k in range(lib.cv_scene_get_num_constraints(sc)):
        field = np.full(nn, np.nan)
        if nn > 0:
            lib.cv_solver_get_multiplier_field(sv, k, field.ctypes.data)
        field.flags.writeable = False
        lambdas[_text(lib.cv_scene_get_constraint(sc, k))] = field
    for k in range(lib.cv_scene_get_num_integrals(sc)):
        mu = ctypes.c_double(np.nan)
        lib.cv_solver_get_multiplier(sv, k, ctypes.byref(mu))
        mus[_text(lib.cv_scene_get_integral(sc, k))] = mu.value
    est = lib.cv_solver_get_error_estimate(sv)
    degrees.flags.writeable = False
    return {
        "title": _text(lib.cv_scene_get_title(sc)),
        "variable": _text(lib.cv_scene_get_variable(sc)),
        "unknowns": tuple(_text(lib.cv_scene_get_unknown(sc, i))
                          for i in range(lib.cv_scene_get_num_unknowns(sc))),
        "message": _text(lib.cv_solver_last_error(sv)),
        "method": _text(lib.cv_method_name(lib.cv_solver_get_method(sv))),
        "elements": lib.cv_solver_get_num_elements(sv),
        "degree": lib.cv_solver_get_degree(sv),
        "degrees": degrees,
        "iterations": lib.cv_solver_get_num_iterations(sv),
        "action": lib.cv_solver_get_action(sv),
        "morse": lib.cv_solver_get_morse_index(sv),
        "time": lib.cv_solver_get_time(sv),
        "interval": (a.value, b.value),
        "error_estimate": None if est != est else est,
        "lambdas": lambdas,
        "mus": mus,
    }


def build_report(h):
    """The report of `calcvar solve --json` for the handles' (selected) solve, as a dict."""
    why = ctypes.c_int()
    r = lib.cv_report_new(h.scene, h.problem, h.solver, ctypes.byref(why))
    if not r:
        raise CalcvarError(status_name(why.value), "the report could not be built: %s"
                           % lib.cv_strerror(why.value).decode())
    try:
        return json.loads(lib.cv_report_json(r).decode(errors="replace"))
    finally:
        lib.cv_report_free(r)


class Solution:
    """The result of solve(): nodes, values, the curve between them, and the report.

    x            nodes of the mesh, shape (m,)  (scipy's solve_bvp: res.x)
    y            nodal values, shape (n, m): y[i] is unknown i  (res.y)
    yp           y' at the nodes, shape (n, m)  (res.yp; at an element boundary, the
                 derivative of the element on its right)
    sol(xs)      the element polynomials anywhere in [a, b]: shape (n, len(xs)), (n,) for a
                 number; sol(xs, derivative=True) gives (y, y'); sol.sol is sol (res.sol)
    values       nodal values node-major, shape (m, n) (calcvar.h's layout); y is values.T
    s[name]      unknown `name` at the nodes; s["lambda_C"] the multiplier field of
                 constraint C, s["mu_K"] the multiplier of integral constraint K; s[variable]
                 is x; also s.name for an unknown whose name is not an attribute
    status       "converged", "max_iterations", "diverged", "singular" or "no_progress" (the
                 report's words); success is status == "converged"; status_code the
                 library's name (CVAR_ECANCELLED for a solve its progress function cancelled)
    message, method, elements, degree, degrees, iterations, action, morse_index, interval,
    time, error_estimate (of a tol/adapt solve, else None), multipliers ({K: mu_K}),
    fields ({C: lambda_C at the nodes}), unknowns, variable, title
    report       the JSON report of `calcvar solve --json` as a dict (built on first use;
                 without [exact] it makes the reference solve the command makes)
    """

    def __init__(self, hold, x, values, code, fields=None, report=None, title=None):
        self._hold = hold     # Handles, or None once everything is read
        self._f = fields      # read_fields(), filled on first use
        self._report = report
        self._title = title   # a Problem's own title (its scene text carries a plain one)
        self._note = None     # (status word, sentence) of a curve_tol that was not met
        self._interp = None
        self._curve = None
        self.x = x
        self.values = values
        self._code = code
        self.success = code == _lib.OK

    # ---- the data read from the handles on first use -------------------------------
    def _fields(self):
        f = self._f
        if f is None:
            h = self._hold
            with h.lock:
                if self._f is None:
                    self._f = read_fields(h)
                f = self._f
        return f

    def _field(name, doc):
        return property(lambda self: self._fields()[name], doc=doc)

    unknowns = _field("unknowns", "the unknowns' names, in order")
    variable = _field("variable", "the independent variable's name")
    method = _field("method", 'the method ("newton", "lbfgs", ...)')
    elements = _field("elements", "elements of the mesh")
    degree = _field("degree", "the largest element degree")
    degrees = _field("degrees", "the degree of each element (numpy array)")
    iterations = _field("iterations", "Newton (or minimiser) iterations")
    action = _field("action", "the discrete action at the solution")
    interval = _field("interval", "(a, b)")
    time = _field("time", "seconds of the solve")
    error_estimate = _field("error_estimate", "estimated max nodal error of a tol or adapt "
                            "solve (the rounds' own estimate), else None")
    multipliers = _field("mus", "{name: multiplier} of the [integrals] constraints")
    fields = _field("lambdas", "{name: multiplier field at the nodes} of the [constraints]")
    del _field

    @property
    def message(self):
        """The solver's sentence."""
        m = self._fields()["message"]
        return m if self._note is None else "%s %s" % (self._note[1], m)

    @property
    def title(self):
        return self._title if self._title is not None else self._fields()["title"]

    @property
    def status(self):
        """The report's word: "converged", "max_iterations", "diverged", "singular" or
        "no_progress"."""
        return status_word(self._code)

    @property
    def status_code(self):
        """The library's status name, e.g. "CVAR_EMAXITER"."""
        return status_name(self._code)

    @property
    def morse_index(self):
        """Negative eigenvalues of the Hessian at a converged Newton solve, else None."""
        morse = self._fields()["morse"]
        return morse if self.success and self.method == "newton" and morse >= 0 else None

    # ---- scipy-like views ----------------------------------------------------------
    @property
    def y(self):
        """Nodal values, shape (n, m) (scipy's res.y): y[i] is unknown i at the nodes."""
        return self.values.T

    @property
    def yp(self):
        """y' at the nodes, shape (n, m) (scipy's res.yp)."""
        return self(self.x, derivative=True)[1]

    @property
    def sol(self):
        """The solution as a function of the variable (scipy's res.sol): sol.sol(xs)."""
        return self

    def __getitem__(self, name):
        f = self._fields()
        if name in f["unknowns"]:
            return self.values[:, f["unknowns"].index(name)]
        if name == f["variable"]:
            return self.x
        if name.startswith("lambda_") and name[7:] in f["lambdas"]:
            return f["lambdas"][name[7:]]
        if name.startswith("mu_") and name[3:] in f["mus"]:
            return f["mus"][name[3:]]
        raise KeyError("%r is not an unknown of this scene (keys: %s)"
                       % (name, ", ".join(self.keys())))

    def __getattr__(self, name):
        # only called for names that are not attributes
        if name.startswith("_") or "_code" not in self.__dict__:
            raise AttributeError(name)
        if name in self._fields()["unknowns"]:  # not self.unknowns: no recursion
            return self[name]
        raise AttributeError("Solution has no attribute or unknown %r" % name)

    def keys(self) -> tuple:
        """The names s[name] accepts: unknowns, lambda_C and mu_K."""
        f = self._fields()
        return (f["unknowns"] + tuple("lambda_" + c for c in f["lambdas"])
                + tuple("mu_" + k for k in f["mus"]))

    def __call__(self, xs, derivative: bool = False):
        """The solution (and with derivative=True also y') at xs in [a, b]: arrays of shape
        (n, m) for m abscissae, (n,) for a scalar."""
        scalar = np.ndim(xs) == 0
        try:
            xv = np.ascontiguousarray(np.atleast_1d(xs), dtype=float)
        except (TypeError, ValueError):
            raise TypeError("xs must be a number or an array of numbers, not %s"
                            % type(xs).__name__) from None
        if xv.ndim != 1:
            raise ValueError("xs must be a number or a one-dimensional array")
        a, b = self.interval
        if xv.size and not (np.all(xv >= a) and np.all(xv <= b)):
            raise InputError("CVAR_EINVAL", "cannot evaluate the solution there: the points "
                             "must lie in [%.17g, %.17g]" % (a, b))
        y, dy = self._interp_()(xv, derivative)
        if scalar:
            y = y[:, 0]
            dy = dy[:, 0] if derivative else None
        return (y, dy) if derivative else y

    def _interp_(self):
        if self._interp is None:
            if self.x.size == 0:
                raise CalcvarError("CVAR_ESTATE", "this solve has no mesh to evaluate: %s"
                                   % self.message)
            self._interp = Interpolant(self.x, self.values, self.degrees)
        return self._interp

    @property
    def curve_error(self):
        """The estimated error of sol(x) between the nodes, as a dict: "curve", the max of
        |sol(x) - y+(x)| over 16 points inside each element and the nodes, and "nodes",
        the same at the nodes alone (about the report's nodal estimate), y+ the enriched
        solve of the report's estimate (docs/theory.md HP-2). `tol` and the report bound the
        nodal error; "curve" is what sol(x) can be off by anywhere. Costs one more solve
        (the first time); a converged solve only."""
        if self._curve is None:
            if not self.success:
                raise CalcvarError(self.status_code, "no estimate of the curve's error: the "
                                   "solve did not converge")
            h = self._hold
            if h is None:
                raise CalcvarError("CVAR_ESTATE", "this Solution was unpickled without its "
                                   "curve error (read curve_error before pickling)")
            from ._curve import estimate
            with Guard() as g, h.lock:
                tick = _lib.TICK_FN(lambda i, u: g.hit)
                if self._curve is None:
                    self._curve = estimate(self, h, tick)
        return self._curve

    @property
    def report(self):
        """The dict of `calcvar solve --json` (built on first use)."""
        if self._report is None:
            h = self._hold
            with Guard(), h.lock:
                if self._report is None:
                    if h.solver is None:
                        raise CalcvarError("CVAR_ESTATE", "the solve's handles are gone")
                    rep = build_report(h)
                    if self._title is not None:
                        rep["title"] = self._title
                    if self._note is not None:
                        rep["status"] = self._note[0]
                        rep["message"] = "%s %s" % (self._note[1], rep.get("message", ""))
                    self._report = rep
        return self._report

    # ---- copies and pickles --------------------------------------------------------
    def __copy__(self):
        new = Solution.__new__(Solution)
        new.__dict__.update(self.__dict__)
        return new

    def __deepcopy__(self, memo):
        new = Solution.__new__(Solution)
        memo[id(self)] = new
        for k, v in self.__dict__.items():
            new.__dict__[k] = v if k in ("_hold", "_interp") else copy.deepcopy(v, memo)
        return new

    def __getstate__(self):
        self._fields()
        self.report  # noqa: B018 - read now: the copy has no handles to build it from
        return {"x": self.x, "values": self.values, "code": self._code, "fields": self._f,
                "report": self._report, "title": self._title, "curve": self._curve,
                "note": self._note}

    def __setstate__(self, st):
        self.__init__(None, st["x"], st["values"], st["code"], st["fields"], st["report"],
                      st["title"])
        self._curve = st.get("curve")
        self._note = st.get("note")
        for a in (self.x, self.values):
            a.flags.writeable = False

    def plot(self, ax=None, points=801, nodes=True):
        """Draw each unknown against the variable with matplotlib (an optional import):
        sol(x) at `points` points and, with nodes=True, the nodal values as dots. Returns
        the Axes (a new figure's when ax is None)."""
        import matplotlib.pyplot as plt
        if ax is None:
            ax = plt.figure().add_subplot()
        a, b = self.interval
        xs = np.linspace(a, b, int(points))
        ys = self(xs)
        for i, name in enumerate(self.unknowns):
            line, = ax.plot(xs, ys[i], label=name)
            if nodes:
                ax.plot(self.x, self.values[:, i], ".", color=line.get_color())
        ax.set_xlabel(self.variable)
        ax.set_title("%s: %s" % (self.title, self.status))
        ax.legend()
        return ax

    def _repr_html_(self):
        """A short table for Jupyter."""
        import html
        rows = [("status", self.status), ("action", "%.15g" % self.action),
                ("morse index", self.morse_index), ("mesh", "%d elements, degree %d"
                                                   % (self.elements, self.degree)),
                ("unknowns", ", ".join(self.unknowns)), ("message", self.message)]
        return ("<table><caption>calcvar.Solution: %s</caption>%s</table>"
                % (html.escape(self.title), "".join(
                    "<tr><th>%s</th><td>%s</td></tr>" % (k, html.escape(str(v)))
                    for k, v in rows)))

    def __repr__(self):
        return ("<calcvar.Solution %s: %s, %d elements of degree %d, unknowns %s>"
                % (self.title, self.status, self.elements, self.degree,
                   ", ".join(self.unknowns)))


class Solutions(list):
    """The paths of solve(..., all=True), by increasing action: a list of Solution, each
    with its own data and report (independent objects), with `search` (starts, failed,
    duplicates, found, stopped: how the search went) and `message` (the plain solve's
    sentence when no path converged)."""
    search = None
    message = ""

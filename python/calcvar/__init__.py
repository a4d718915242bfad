"""calcvar — calculus of variations by direct discretisation, from Python.

Three lines to a solved geodesic::

    import calcvar
    sol = calcvar.solve("sphere_geodesic.scene")
    print(sol.status, sol.x, sol["th"], sol(0.5))

`solve` takes a scene (a path, or the text of a scene) and the options of the command
`calcvar solve`; `equations` and `modes` give its mechanics (as `calcvar equations` and
`calcvar modes`); `Problem` builds a scene from Python values. The work is done by the C
library libcalcvar through ctypes (docs/python.md).
SPDX-License-Identifier: MIT
"""
import ctypes
import json
import os

import numpy as np

from . import _lib
from ._lib import lib

__all__ = ["solve", "equations", "modes", "Solution", "Problem", "CalcvarError",
           "InputError", "version",
           "dependency_versions",
           "METHODS"]

METHODS = ("newton", "lbfgs", "tnewton", "mma", "ccsaq", "slsqp", "auglag")


class CalcvarError(Exception):
    """A failure of the library: `status` is the status name (e.g. "CVAR_ENOMEM"),
    `message` the sentence."""

    def __init__(self, status, message):
        super().__init__(message)
        self.status = status
        self.message = message


class InputError(CalcvarError, ValueError):
    """Bad input (a scene, an option, an argument): the message says FILE:LINE: what is
    wrong where there is a line. Also a ValueError."""


def version():
    """The library's version as a string, e.g. "0.1.0"."""
    return "%d.%d.%d" % _lib.version()


def dependency_versions():
    """The libraries linked into libcalcvar, as they report their versions."""
    buf = ctypes.create_string_buffer(256)
    lib.cv_dependency_versions(buf, len(buf))
    return buf.value.decode()


def _status_name(code):
    return lib.cv_status_name(code).decode()


# The report's status words (the same as `calcvar solve`'s JSON "status").
def _status_word(code):
    if code == _lib.OK:
        return "converged"
    name = _status_name(code)
    return {"CVAR_EMAXITER": "max_iterations", "CVAR_ENONFINITE": "diverged",
            "CVAR_EDIVERGED": "diverged", "CVAR_ESINGULAR": "singular"}.get(name, "no_progress")


def _fail(code, message):
    cls = InputError if code == _lib.EINVAL else CalcvarError
    raise cls(_status_name(code), message)


def _free_all(solver, problem, scene):
    # in this order: a problem refers to its scene
    if solver:
        lib.cv_solver_free(solver)
    if problem:
        lib.cv_problem_free(problem)
    if scene:
        lib.cv_scene_free(scene)


class _Handles:
    """The scene, problem and solver behind one or more Solutions (the paths of one
    all=True search share them); released when the last Solution goes."""

    def __init__(self, scene, problem, solver):
        self.h = (scene, problem, solver)
        self.keep = []  # ctypes callbacks the library holds

    def __del__(self):
        h, self.h = self.h, None
        if h:
            try:
                _free_all(h[2], h[1], h[0])
            except (AttributeError, TypeError):  # the interpreter is shutting down
                pass


class Solutions(list):
    """The paths of solve(..., all=True), by increasing action: a list of Solution, with
    `search` (starts, failed, duplicates, found, stopped: how the search went) and
    `message` (the plain solve's sentence when no path converged)."""
    search = None
    message = ""


class _SearchInfo(ctypes.Structure):
    _fields_ = [("starts", ctypes.c_int), ("failed", ctypes.c_int),
                ("duplicates", ctypes.c_int), ("found", ctypes.c_int),
                ("stop", ctypes.c_char * 200)]


def _load(scene, set, err=None):
    if err is None:
        err = ctypes.create_string_buffer(_lib.ERRLEN)
    pairs = []
    for name, value in (set or {}).items():
        if isinstance(value, bool) or not isinstance(value, (int, float, str)):
            raise InputError("CVAR_EINVAL", "set=%r: the value of %s must be a number or a "
                             "constant expression" % (value, name))
        pairs.append(("%s=%s" % (name, repr(float(value)) if not isinstance(value, str)
                                 else value)).encode())
    arr = (ctypes.c_char_p * len(pairs))(*pairs) if pairs else None
    if isinstance(scene, os.PathLike):
        scene = os.fspath(scene)
    if isinstance(scene, bytes):
        scene = scene.decode()
    if not isinstance(scene, str):
        raise TypeError("scene must be a path or the text of a scene, not %s"
                        % type(scene).__name__)
    if "\n" in scene or scene.lstrip().startswith("["):
        if "\0" in scene:
            raise InputError("CVAR_EINVAL", "<string>: the scene text contains a NUL byte")
        h = lib.cv_scene_load_text(scene.encode(), b"<string>", len(pairs), arr, err,
                                   _lib.ERRLEN)
    else:
        h = lib.cv_scene_load_file(scene.encode(), len(pairs), arr, err, _lib.ERRLEN)
    if not h:
        raise InputError("CVAR_EINVAL", err.value.decode(errors="replace"))
    return h


def _progress_callback(user_fn, verbose, caught):
    """A ctypes callback around the user's progress function (or the verbose printer).
    Exceptions (KeyboardInterrupt too) cannot cross C: they are kept, the solve is
    cancelled, and solve() raises them afterwards."""

    def call(info_p, _user):
        try:
            info = info_p.contents
            d = {"kind": "round" if info.kind == 1 else "newton",
                 "iteration": info.iteration, "residual": info.residual, "step": info.step,
                 "alpha": info.alpha, "action": info.action, "round": info.round,
                 "elements": info.elements, "estimate": info.estimate}
            if verbose:
                if d["kind"] == "round":
                    print("round %d: %d elements, estimated max nodal error %.3g"
                          % (d["round"], d["elements"], d["estimate"]))
                else:
                    print("  iteration %d: residual %.3e, step %.3e, line search %g"
                          % (d["iteration"], d["residual"], d["step"], d["alpha"]))
            if user_fn is not None and user_fn(d):
                return 1  # a true result cancels
            return 0
        except BaseException as e:  # noqa: B902 - re-raised after the solve
            caught.append(e)
            return 1

    return _lib.PROGRESS_FN(call)


def solve(scene, *, elements=None, degree=None, method=None, tolerance=None,
          max_iterations=None, adapt=None, set=None, tol=None, max_nodes=None,
          time_limit=None, all=False, max_paths=8, work=None, progress=None, verbose=False):
    """Solve a scene as `calcvar solve` does and return a Solution.

    scene: a path (str or os.PathLike) or the text of a scene (any str with a newline or
    starting with '[').  Options mirror the command: elements, degree (1..8), method
    ("newton", "lbfgs", ...), tolerance (Newton step), max_iterations, adapt (target max
    nodal error at a fixed degree), tol (target max nodal error: calcvar chooses the
    mesh and the degree of each element, as `calcvar solve --tol`, from the same start),
    max_nodes (the cap of tol, default 10**6), time_limit (seconds for the rounds of tol
    or adapt), set={name: value} overriding [parameters].  progress: a function called
    with a dict after every Newton iteration and adaptive round (keys kind, iteration,
    residual, step, alpha, action, round, elements, estimate); returning True cancels.
    verbose=True prints those lines.

    all=True searches for every stationary path with the same ends (`calcvar solve
    --all`: deflated Newton, at most max_paths, work limit `work` like --work) and
    returns a Solutions list, by increasing action.

    Bad input raises InputError (a ValueError) with the FILE:LINE sentence. A solve that
    does not converge is not an exception: look at Solution.status / .success.
    """
    if all and (isinstance(max_paths, bool) or not isinstance(max_paths, int)
                or max_paths < 1):
        raise InputError("CVAR_EINVAL", "max_paths=%r: a whole number >= 1 is needed"
                         % (max_paths,))
    err = ctypes.create_string_buffer(_lib.ERRLEN)
    scene_h = _load(scene, set, err)
    problem = solver = None
    try:
        options = {"elements": elements, "degree": degree, "tolerance": tolerance,
                   "max_iterations": max_iterations, "adapt": adapt, "tol": tol,
                   "max_nodes": max_nodes, "time_limit": time_limit}
        if method is not None:
            code = ctypes.c_int()
            if not isinstance(method, str) or lib.cv_method_from_name(
                    method.encode(), ctypes.byref(code)) != _lib.OK:
                raise InputError("CVAR_EINVAL", "method=%r: unknown method (known: %s)"
                                 % (method, ", ".join(METHODS)))
            options["method"] = code.value
        for name, value in options.items():
            if value is None:
                continue
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise InputError("CVAR_EINVAL", "%s=%r: a number is needed" % (name, value))
            if lib.cv_scene_set_option(scene_h, name.encode(), float(value), err,
                                       _lib.ERRLEN) != _lib.OK:
                raise InputError("CVAR_EINVAL", err.value.decode())
        problem = lib.cv_scene_problem_new(scene_h, err, _lib.ERRLEN)
        if not problem:
            raise InputError("CVAR_EINVAL", err.value.decode())
        solver = lib.cv_solver_new(None)
        if not solver:
            _fail(_lib.ENOMEM, "out of memory")
        st = lib.cv_scene_configure_solver(scene_h, solver, err, _lib.ERRLEN)
        if st != _lib.OK:
            _fail(st, err.value.decode())
        caught = []
        cb = None
        if progress is not None or verbose:
            cb = _progress_callback(progress, verbose, caught)
            lib.cv_solver_set_progress(solver, cb, None)
        if all:
            if work is not None and lib.cv_solver_set_search_work(solver, float(work)) \
                    != _lib.OK:
                raise InputError("CVAR_EINVAL", "work=%r: a factor >= 1 is needed" % (work,))
            st = lib.cv_solve_all(solver, problem, max_paths)  # the GIL is released
        else:
            st = lib.cv_solve(solver, problem)  # the GIL is released in here
        if cb is not None:
            lib.cv_solver_set_progress(solver, _lib.PROGRESS_FN(), None)
        if caught:
            raise caught[0]
        if st == _lib.EINVAL:
            # input the core refused before solving, as the command reports it
            _fail(st, "%s: %s" % ("<string>" if "\n" in str(scene) else os.fspath(scene),
                                  lib.cv_solver_last_error(solver).decode()))
        hold = _Handles(scene_h, problem, solver)
        scene_h = problem = solver = None  # hold owns them now
        if not all:
            return Solution(hold)
        return _paths(hold)
    finally:
        _free_all(solver, problem, scene_h)


def _paths(hold):
    scene, problem, solver = hold.h
    out = Solutions()
    info = _SearchInfo()
    if lib.cv_solver_get_search(solver, ctypes.byref(info)) == _lib.OK:
        out.search = {"starts": info.starts, "failed": info.failed,
                      "duplicates": info.duplicates, "found": info.found,
                      "stopped": info.stop.decode(errors="replace")}
    out.message = lib.cv_solver_last_error(solver).decode(errors="replace")
    n = lib.cv_solver_get_num_solutions(solver)
    if n > 0:
        # as the command does: the reference solve of each path's error estimate (its
        # report) starts from that path, not from the scene's guess
        a, b = ctypes.c_double(), ctypes.c_double()
        lib.cv_problem_get_interval(problem, ctypes.byref(a), ctypes.byref(b))
        lo, hi = a.value, b.value

        def guess(m, x, y, _user):
            xc = np.clip(np.ctypeslib.as_array(x, (m,)), lo, hi)
            return 0 if lib.cv_solver_eval(solver, m, xc.ctypes.data, ctypes.cast(
                y, ctypes.c_void_p), None) == _lib.OK else 1

        cb = _lib.GUESS_FN(guess)
        hold.keep.append(cb)
        lib.cv_problem_set_guess(problem, cb, None)
    for k in range(n):
        out.append(Solution(hold, k))
    return out


class Solution:
    """The result of solve().

    x           nodes of the mesh (numpy array)
    values      nodal values, shape (nodes, n): values[j, i] is unknown i at node j
    sol[name]   unknown `name` at the nodes (a view into values, no copy); also sol.name
                for unknowns whose name is not an attribute below; sol[variable] is x
    sol(xs)     the element polynomials evaluated anywhere in [a, b]: shape (n, len(xs))
                (shape (n,) for a scalar), like scipy's solve_bvp .sol
    status      "converged", "max_iterations", "diverged", "singular" or "no_progress"
    success     status == "converged"
    message     the solver's sentence
    morse_index negative eigenvalues of the Hessian at a converged Newton solve, else None
    report      the JSON report of `calcvar solve --json` as a dict (built on first use;
                without [exact] it makes the same reference solve the command does)
    """

    def __init__(self, hold, path=None):
        self._hold = hold
        self._path = path  # index among the paths of an all=True search, else None
        self._report = None
        self._unknowns = None
        scene, _, solver = self._h
        nn = lib.cv_solver_get_num_nodes(solver)
        n = lib.cv_scene_get_num_unknowns(scene)
        # numpy buffers filled by the library in place: node-major values (calcvar.h)
        self.x = np.empty(nn)
        self.values = np.empty((nn, n))
        if nn > 0:
            lib.cv_solver_get_nodes(solver, self.x.ctypes.data)
            lib.cv_solver_get_values(solver, self.values.ctypes.data)
        self.x.flags.writeable = False
        self.values.flags.writeable = False
        self._code = lib.cv_solver_get_status(solver)
        self.success = self._code == _lib.OK

    @property
    def _h(self):
        """(scene, problem, solver), with this Solution's path selected."""
        h = self._hold.h
        if self._path is not None:
            lib.cv_solver_select_solution(h[2], self._path)
        return h

    # Everything else is read from the solver when asked for (the call stays cheap).
    unknowns = property(lambda self: self._names(), doc="the unknowns' names, in order")
    variable = property(lambda self: lib.cv_scene_get_variable(self._h[0]).decode(),
                        doc="the independent variable's name")
    title = property(lambda self: lib.cv_scene_get_title(self._h[0]).decode())
    status = property(lambda self: _status_word(self._code),
                      doc='"converged", "max_iterations", "diverged", "singular" or '
                          '"no_progress" (the report\'s words)')
    status_code = property(lambda self: _status_name(self._code), doc="e.g. CVAR_EMAXITER")
    message = property(lambda self: lib.cv_solver_last_error(self._h[2]).decode(
        errors="replace"), doc="the solver's sentence")
    method = property(lambda self: lib.cv_method_name(
        lib.cv_solver_get_method(self._h[2])).decode())
    elements = property(lambda self: lib.cv_solver_get_num_elements(self._h[2]))
    degree = property(lambda self: lib.cv_solver_get_degree(self._h[2]))
    iterations = property(lambda self: lib.cv_solver_get_num_iterations(self._h[2]))
    action = property(lambda self: lib.cv_solver_get_action(self._h[2]),
                      doc="the discrete action at the solution")

    @property
    def morse_index(self):
        """Negative eigenvalues of the Hessian at a converged Newton solve, else None."""
        morse = lib.cv_solver_get_morse_index(self._h[2])
        return morse if self.success and self.method == "newton" and morse >= 0 else None

    @property
    def interval(self):
        a, b = ctypes.c_double(), ctypes.c_double()
        lib.cv_problem_get_interval(self._h[1], ctypes.byref(a), ctypes.byref(b))
        return (a.value, b.value)

    def _names(self):
        if self._unknowns is None:
            sc = self._h[0]
            self._unknowns = tuple(lib.cv_scene_get_unknown(sc, i).decode()
                                   for i in range(self.values.shape[1]))
        return self._unknowns

    def __getitem__(self, name):
        if name in self.unknowns:
            return self.values[:, self.unknowns.index(name)]
        if name == self.variable:
            return self.x
        raise KeyError("%r is not an unknown of this scene (unknowns: %s)"
                       % (name, ", ".join(self.unknowns)))

    def __getattr__(self, name):
        # only called for names that are not attributes
        if name.startswith("_") or "_hold" not in self.__dict__:
            raise AttributeError(name)
        if name in self.unknowns:
            return self[name]
        raise AttributeError("Solution has no attribute or unknown %r" % name)

    def keys(self):
        return self.unknowns

    def __call__(self, xs, derivative=False):
        """The solution (and with derivative=True also y') at xs in [a, b]: arrays of shape
        (n, m) for m abscissae, (n,) for a scalar."""
        scalar = np.ndim(xs) == 0
        xv = np.ascontiguousarray(np.atleast_1d(xs), dtype=float)
        if xv.ndim != 1:
            raise ValueError("xs must be a number or a one-dimensional array")
        m, n = xv.size, len(self.unknowns)
        y = np.empty((n, m))
        dy = np.empty((n, m)) if derivative else None
        if m > 0:
            st = lib.cv_solver_eval(self._h[2], m, xv.ctypes.data, y.ctypes.data,
                                    dy.ctypes.data if derivative else None)
            if st != _lib.OK:
                a, b = self.interval
                raise InputError(_status_name(st), "cannot evaluate the solution there: the "
                                 "points must lie in [%.17g, %.17g] (%s)"
                                 % (a, b, lib.cv_strerror(st).decode()))
        if scalar:
            y = y[:, 0]
            dy = dy[:, 0] if derivative else None
        return (y, dy) if derivative else y

    @property
    def report(self):
        if self._report is None:
            why = ctypes.c_int()
            r = lib.cv_report_new(self._h[0], self._h[1], self._h[2], ctypes.byref(why))
            if not r:
                _fail(why.value, "the report could not be built: %s"
                      % lib.cv_strerror(why.value).decode())
            try:
                self._report = json.loads(lib.cv_report_json(r).decode())
            finally:
                lib.cv_report_free(r)
        return self._report

    def __repr__(self):
        return ("<calcvar.Solution %s: %s, %d elements of degree %d, unknowns %s>"
                % (self.title, self.status, self.elements, self.degree,
                   ", ".join(self.unknowns)))


def _mechanics(new, to_json, free, scene, set):
    h = _load(scene, set)
    err = ctypes.create_string_buffer(_lib.ERRLEN)
    why = ctypes.c_int(_lib.OK)
    r = None
    try:
        r = new(h, ctypes.byref(why), err, _lib.ERRLEN)
        if not r:
            _fail(why.value, err.value.decode(errors="replace"))
        return json.loads(to_json(r).decode())
    finally:
        if r:
            free(r)
        lib.cv_scene_free(h)


def equations(scene, *, set=None):
    """The mechanics of a scene's integrand F (a path or scene text, with `set` overriding
    [parameters]) as a dict, the JSON of `calcvar equations --json` (docs/mechanics.md):
    "momenta" and "euler_lagrange" ({unknown: expression}), "hamiltonian", "cyclic" (the
    unknowns F does not contain) and "autonomous" (F does not contain the variable). The
    expressions are text in the scene grammar with the parameters as numbers."""
    return _mechanics(lib.cv_equations_new, lib.cv_equations_json, lib.cv_equations_free,
                      scene, set)


def modes(scene, *, set=None):
    """The equilibrium of a scene's Lagrangian L(y, y') found from its guess at the start
    of the interval, and the small oscillations there, as a dict: the JSON of `calcvar
    modes --json` (docs/mechanics.md): "equilibrium" ({unknown: value}), "modes" (a list of
    {"omega2", "kind", "shape"}, omega2 increasing), and "multipliers" / "gyroscopic" when
    they apply. Raises InputError when modes do not apply (L depends on the variable,
    integral constraints) and CalcvarError (status CVAR_EMAXITER, CVAR_ESINGULAR, ...) when
    no equilibrium or no modes are found."""
    return _mechanics(lib.cv_modes_new, lib.cv_modes_json, lib.cv_modes_free, scene, set)


def _num(v):
    if isinstance(v, str):
        return v
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise InputError("CVAR_EINVAL", "%r: a number or an expression is needed" % (v,))
    return repr(float(v))


class Problem:
    """A variational problem built from Python values instead of a file; it is written as
    a scene (Problem.text) and loaded by the same loader, so the rules and messages are
    those of docs/scenes.md (with line numbers in Problem.text).

    integrand   F as an expression of the variable, unknowns and primed unknowns (y', and
                y'' for a second-order integrand: C1 elements, docs/beams.md)
    interval    (a, b)
    boundary    {unknown: (value_at_a, value_at_b)}; a value None or "free" leaves that
                end free (natural boundary condition); values may be expressions; a key
                "y'" gives the slopes of a second-order unknown y (missing: both free)
    unknowns    names in order (default: the order of boundary)
    variable    the independent variable's name (default "x")
    parameters  {name: value}          definitions  {name: expression}
    constraints {name: G}              pointwise G(x, y) = 0
    integrals   {name: (K, c)}         int K dx = c
    guess, exact {unknown: expression of the variable}; exact may have "action": value
    report      {name: K}              integrals reported after solving
    mesh, solver {key: value}          [mesh] and [solver] entries
    """

    def __init__(self, integrand, interval, boundary, unknowns=None, variable="x",
                 parameters=None, definitions=None, constraints=None, integrals=None,
                 guess=None, exact=None, report=None, mesh=None, solver=None, title=None):
        if unknowns is None:  # slope lines ("y'") are not unknowns
            unknowns = [k for k in boundary if not k.endswith("'")]
        elif isinstance(unknowns, str):
            unknowns = [u.strip() for u in unknowns.split(",")]
        try:
            a, b = interval
        except (TypeError, ValueError):
            raise InputError("CVAR_EINVAL", "interval must be a pair (a, b)") from None
        lines = ["[scene]",
                 "title = %s" % (title or "Problem"),
                 "variable = %s" % variable,
                 "interval = %s, %s" % (_num(a), _num(b)),
                 "unknowns = %s" % ", ".join(unknowns),
                 "integrand = %s" % integrand]

        def section(name, items, fmt=lambda k, v: "%s = %s" % (k, v)):
            if items:
                lines.append("[%s]" % name)
                lines.extend(fmt(k, v) for k, v in items.items())

        section("parameters", parameters, lambda k, v: "%s = %s" % (k, _num(v)))
        section("definitions", definitions)
        bl = {}
        for k, v in boundary.items():
            try:
                ya, yb = v
            except (TypeError, ValueError):
                raise InputError("CVAR_EINVAL", "boundary %s: a pair (value at a, value at b) "
                                 "is needed" % k) from None
            bl[k] = "%s, %s" % tuple("free" if e is None else _num(e) for e in (ya, yb))
        section("boundary", bl)
        section("guess", guess)
        section("constraints", constraints)
        section("integrals", integrals, lambda k, v: "%s = %s, %s" % (k, v[0], _num(v[1])))
        section("exact", exact, lambda k, v: "%s = %s" % (k, _num(v) if k == "action" else v))
        section("report", report)
        section("mesh", mesh, lambda k, v: "%s = %s" % (k, v))
        section("solver", solver, lambda k, v: "%s = %s" % (k, v))
        for line in lines:
            if "\n" in line:
                raise InputError("CVAR_EINVAL", "a value contains a line break: %r" % line)
        self.text = "\n".join(lines) + "\n"
        # load once now, so that bad input is reported here
        _free_all(None, None, _load(self.text, None))

    def solve(self, **options):
        """calcvar.solve on this problem, with the same options."""
        return solve(self.text, **options)

    def equations(self):
        """Momenta, Euler-Lagrange equations and Hamiltonian as a dict: calcvar.equations
        on this problem."""
        return equations(self.text)

    def modes(self):
        """Equilibrium and small-oscillation modes as a dict: calcvar.modes on this
        problem."""
        return modes(self.text)

    def __repr__(self):
        return "<calcvar.Problem>\n" + self.text

"""calcvar._solve — solve(): a scene through the library, into a Solution (or, with
all=True, a Solutions list of independent paths).

Every handle made here belongs to a Handles object from the moment it exists, so that an
error or Ctrl-C at any point frees it; the whole call runs under an interrupt Guard, whose
flag the progress callback returns to the library after every Newton step (Ctrl-C cancels
the solve within one step, then KeyboardInterrupt is raised; docs/python.md).
SPDX-License-Identifier: MIT
"""
from __future__ import annotations

import ctypes
import os
from typing import Any, Callable, Mapping, Optional, Union

import numpy as np

from . import _lib
from ._errors import bad, fail
from ._input import expr, number, whole
from ._interrupt import Guard
from ._lib import lib
from ._problem import Problem
from ._solution import Handles, Solution, Solutions, build_report, read_fields

METHODS = ("newton", "lbfgs", "tnewton", "mma", "ccsaq", "slsqp", "auglag")


def scene_text(scene):
    """A Problem's text; a path or scene text unchanged (str, bytes, os.PathLike)."""
    if type(scene) is not str and isinstance(scene, Problem):
        return scene.text
    return scene


def load(scene, set, err=None):
    """Load a scene (a path or the text of one) with [parameters] overrides; the handle,
    or InputError with the loader's FILE:LINE sentence."""
    if err is None:
        err = ctypes.create_string_buffer(_lib.ERRLEN)
    pairs = []
    if set:
        if not isinstance(set, dict):
            raise TypeError("set must be a dict {parameter: value}")
        for key, value in set.items():
            pairs.append(("%s=%s" % (key, expr(value, "set %s" % key))).encode())
    arr = (ctypes.c_char_p * len(pairs))(*pairs) if pairs else None
    if type(scene) is not str and isinstance(scene, os.PathLike):
        scene = os.fspath(scene)
    if isinstance(scene, bytes):
        scene = scene.decode()
    if not isinstance(scene, str):
        raise TypeError("scene must be a path, the text of a scene or a calcvar.Problem, "
                        "not %s" % type(scene).__name__)
    text = "\n" in scene or scene.lstrip().startswith("[")
    if text:
        if "\0" in scene:
            raise bad("<string>: the scene text contains a NUL byte")
        h = lib.cv_scene_load_text(scene.encode(), b"<string>", len(pairs), arr, err,
                                   _lib.ERRLEN)
    else:
        h = lib.cv_scene_load_file(scene.encode(), len(pairs), arr, err, _lib.ERRLEN)
    if not h:
        msg = err.value.decode(errors="replace")
        if "'*'" in msg and (text and "**" in scene):
            msg += " (use ^ for powers in calcvar's grammar: x^2, not x**2)"
        raise bad(msg)
    return h


def _options(elements, degree, method, tolerance, max_iterations, adapt, tol, max_nodes,
             time_limit):
    """The options as (name, value) for cv_scene_set_option, checked."""
    out = []
    if elements is not None:
        out.append((b"elements", float(whole(elements, "elements"))))
    if degree is not None:
        out.append((b"degree", float(whole(degree, "degree"))))
    for key, v in (("max_iterations", max_iterations), ("max_nodes", max_nodes)):
        if v is not None:
            out.append((key.encode(), float(whole(v, key))))
    for key, v in (("tolerance", tolerance), ("adapt", adapt), ("tol", tol),
                   ("time_limit", time_limit)):
        if v is not None:
            out.append((key.encode(), number(v, key)))
    if method is not None:
        code = ctypes.c_int()
        if not isinstance(method, str) or lib.cv_method_from_name(
                method.encode(), ctypes.byref(code)) != _lib.OK:
            raise bad("method=%r: unknown method (known: %s)" % (method, ", ".join(METHODS)))
        out.append((b"method", float(code.value)))
    return out


def _progress(guard, user_fn, verbose, caught):
    """The callback the library calls after every Newton step and adaptive round: it
    cancels when Ctrl-C was pressed (guard.hit), or the user's function returned true or
    raised (kept in caught, raised by solve)."""
    if user_fn is None and not verbose:
        return _lib.TICK_FN(lambda info_p, user: guard.hit)

    def call(info_p, _user):
        if guard.hit:
            return 1
        try:
            info = _lib.Progress.from_address(info_p)
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
            return 1 if user_fn is not None and user_fn(d) else 0
        except BaseException as e:  # noqa: B902 - raised again by solve()
            caught.append(e)
            return 1

    return _lib.TICK_FN(call)


def _guess(guess, h, caught):
    """A guess callback from a Solution (warm start: its curve) or arrays (x, y) with y of
    shape (n, m) (scipy's solve_bvp(fun, bc, x, y)), linearly interpolated."""
    n = lib.cv_scene_get_num_unknowns(h.scene)
    if isinstance(guess, Solution):
        if len(guess.unknowns) != n:
            raise bad("guess: the Solution has %d unknowns, the scene %d"
                      % (len(guess.unknowns), n))
        lo, hi = guess.interval

        def curve(xs):
            return guess(np.clip(xs, lo, hi))
    else:
        try:
            xg, yg = guess
            xg = np.asarray(xg, dtype=float)
            yg = np.asarray(yg, dtype=float)
        except (TypeError, ValueError):
            raise TypeError("guess must be a Solution or a pair (x, y) of arrays, y of shape "
                            "(n, m) for m points x") from None
        if yg.ndim == 1 and n == 1:
            yg = yg[None, :]
        if xg.ndim != 1 or xg.size < 2 or yg.shape != (n, xg.size):
            raise bad("guess: x must have m >= 2 points and y the shape (n, m) = (%d, %d), "
                      "not %s" % (n, xg.size, yg.shape))
        if not (np.all(np.isfinite(xg)) and np.all(np.isfinite(yg))
                and np.all(np.diff(xg) > 0)):
            raise bad("guess: x must be increasing and x, y finite")

        def curve(xs):
            return np.array([np.interp(xs, xg, yg[i]) for i in range(n)])

    def call(m, x, y, _user):
        try:
            xs = np.ctypeslib.as_array(x, (m,))
            np.ctypeslib.as_array(y, (n * m,))[:] = np.asarray(curve(xs), float).ravel()
            return 0
        except BaseException as e:  # noqa: B902 - raised again by solve()
            caught.append(e)
            return 1

    return _lib.GUESS_FN(call)


Scene = Union[str, bytes, "os.PathLike[str]", Problem]
Number = Union[int, float, "np.number"]


def solve(scene: Scene, *, elements: Optional[Number] = None,
          degree: Optional[Number] = None, method: Optional[str] = None,
          tolerance: Optional[Number] = None, max_iterations: Optional[Number] = None,
          adapt: Optional[Number] = None, set: Optional[Mapping[str, Any]] = None,
          tol: Optional[Number] = None, max_nodes: Optional[Number] = None,
          time_limit: Optional[Number] = None, all: bool = False, max_paths: int = 8,
          work: Optional[Number] = None, guess: Any = None,
          progress: Optional[Callable[[dict], Any]] = None,
          verbose: bool = False,
          curve_tol: Optional[Number] = None) -> Union[Solution, Solutions]:
    """Solve a scene as `calcvar solve` does and return a Solution.

    scene: a path (str or os.PathLike), the text of a scene (any str with a newline or
    starting with '['), or a calcvar.Problem. Options mirror the command: elements,
    degree (1..8), method ("newton", "lbfgs", ...), tolerance (Newton step),
    max_iterations, adapt (target max nodal error at a fixed degree), tol (target max
    nodal error: calcvar chooses the mesh and the degree of each element, as `calcvar solve
    --tol`), max_nodes (the cap of tol, default 10**6), time_limit (seconds for the rounds
    of tol or adapt), set={name: value} overriding [parameters]. Numbers may be numpy
    numbers.

    guess: a Solution (a warm start: its curve is the starting path, on this solve's
    mesh) or arrays (x, y), y of shape (n, m), interpolated linearly (scipy's solve_bvp
    takes the same); it replaces the scene's [guess].

    progress: a function called with a dict after every Newton iteration and adaptive
    round (keys kind, iteration, residual, step, alpha, action, round, elements,
    estimate); returning True cancels (status_code CVAR_ECANCELLED). verbose=True prints
    those lines. Ctrl-C cancels the solve within one Newton step and raises
    KeyboardInterrupt.

    all=True searches for every stationary path with the same ends (`calcvar solve
    --all`: deflated Newton, at most max_paths, work limit `work` like --work) and
    returns a Solutions list, by increasing action, each with its report.

    curve_tol: the target for sol(x) anywhere, not only at the nodes: solves with tol
    (from curve_tol down) until Solution.curve_error["curve"] <= curve_tol, at most
    CURVE_ROUNDS solves, each started from the last; if it is not met the Solution's
    status is "max_iterations" with a sentence giving the estimate reached.

    Bad input raises InputError (a ValueError) with the FILE:LINE sentence. A solve that
    does not converge is not an exception: look at Solution.status / .success.
    """
    if curve_tol is not None:
        if tol is not None or adapt is not None or all:
            raise bad("curve_tol chooses tol itself: give curve_tol, or tol / adapt / all")
        return _curve_solve(scene, number(curve_tol, "curve_tol"), dict(
            elements=elements, degree=degree, method=method, tolerance=tolerance,
            max_iterations=max_iterations, set=set, max_nodes=max_nodes,
            time_limit=time_limit, guess=guess, progress=progress, verbose=verbose))
    title = None
    if type(scene) is not str and isinstance(scene, Problem):
        title, scene = scene.title, scene.text
    opts = _options(elements, degree, method, tolerance, max_iterations, adapt, tol,
                    max_nodes, time_limit)
    if all:
        if isinstance(max_paths, bool) or whole(max_paths, "max_paths") < 1:
            raise bad("max_paths=%r: a whole number >= 1 is needed" % (max_paths,))
        if work is not None and not number(work, "work") >= 1:
            raise bad("work=%r: a factor >= 1 is needed" % (work,))
    if progress is not None and not callable(progress):
        raise TypeError("progress must be a function of one dict")
    err = ctypes.create_string_buffer(_lib.ERRLEN)
    with Guard() as g:
        h = Handles()
        try:
            return _run(h, g, scene, set, opts, err, all, max_paths, work, guess, progress,
                        verbose, title)
        finally:
            if not h.owned:
                h.free()


CURVE_ROUNDS = 6   # solves curve_tol may make
CURVE_FLOOR = 1e-15  # tol is not asked below this (the round-off floor of the estimate)


def _curve_solve(scene, target, kw):
    """Solves with tol from target down until the curve's estimated error is at most target
    (the nodes are superconvergent, so tol must be smaller than the curve's target: each
    round divides it by the ratio just measured, with a margin of 0.8)."""
    if not target > 0:
        raise bad("curve_tol=%r: a number > 0 is needed" % (target,))
    t, sol = target, None
    for k in range(1, CURVE_ROUNDS + 1):
        sol = solve(scene, tol=t, **kw)
        if not sol.success:
            return sol
        c = sol.curve_error["curve"]
        if c <= target:
            return sol
        kw["guess"] = sol
        t_last = t
        t = t * max(min(0.8 * target / c, 0.5), 1e-4)
        if t < CURVE_FLOOR:
            break
    sol._code = _lib.EMAXITER
    sol.success = False
    sol._note = ("max_iterations", "curve_tol %.3g was not reached: after %d solve%s the "
                 "estimated error of sol(x) is %.3g (tol %.3g at the nodes)."
                 % (target, k, "" if k == 1 else "s", c, t_last))
    return sol


def _run(h, g, scene, set, opts, err, all, max_paths, work, guess, progress, verbose, title):
    h.scene = load(scene, set, err)
    for key, value in opts:
        if lib.cv_scene_set_option(h.scene, key, value, err, _lib.ERRLEN) != _lib.OK:
            raise bad(err.value.decode(errors="replace"))
    h.problem = lib.cv_scene_problem_new(h.scene, err, _lib.ERRLEN)
    if not h.problem:
        raise bad(err.value.decode(errors="replace"))
    h.solver = lib.cv_solver_new(None)
    if not h.solver:
        fail(_lib.ENOMEM, "out of memory")
    st = lib.cv_scene_configure_solver(h.scene, h.solver, err, _lib.ERRLEN)
    if st != _lib.OK:
        fail(st, err.value.decode(errors="replace"))
    caught = []
    if guess is not None:
        cb = _guess(guess, h, caught)
        h.keep.append(cb)
        lib.cv_problem_set_guess(h.problem, cb, None)
    cb = _progress(g, progress, verbose, caught)
    h.keep.append(cb)
    lib.cv_solver_set_progress(h.solver, cb, None)
    if all:
        if work is not None:
            lib.cv_solver_set_search_work(h.solver, float(work))
        st = lib.cv_solve_all(h.solver, h.problem, int(max_paths))  # the GIL is released
    else:
        st = lib.cv_solve(h.solver, h.problem)  # the GIL is released in here
    # the callback stays set: h.keep holds it as long as the solver lives
    if g.hit:
        return None  # the Guard raises KeyboardInterrupt; finally frees the handles
    if caught:
        raise caught[0]
    if st == _lib.EINVAL and lib.cv_solver_get_num_nodes(h.solver) <= 0:
        # input the core refused before solving, as the command reports it
        fail(st, "%s: %s" % ("<string>" if "\n" in scene else scene,
                             lib.cv_solver_last_error(h.solver).decode(errors="replace")))
    if all:
        return _paths(h, g, title)
    sol = Solution(h, *_arrays(h), lib.cv_solver_get_status(h.solver), title=title)
    h.owned = True
    return sol


def _arrays(h):
    nn = lib.cv_solver_get_num_nodes(h.solver)
    n = lib.cv_scene_get_num_unknowns(h.scene)
    x = np.empty(max(nn, 0))
    values = np.empty((max(nn, 0), n))
    if nn > 0:
        lib.cv_solver_get_nodes(h.solver, x.ctypes.data)
        lib.cv_solver_get_values(h.solver, values.ctypes.data)
    x.flags.writeable = False
    values.flags.writeable = False
    return x, values


class _SearchInfo(ctypes.Structure):
    _fields_ = [("starts", ctypes.c_int), ("failed", ctypes.c_int),
                ("duplicates", ctypes.c_int), ("found", ctypes.c_int),
                ("stop", ctypes.c_char * 200)]


def _paths(h, g, title):
    """Every path read out into a Solution of its own (data, fields and report), so that
    no two paths share the solver (which holds one selected path at a time)."""
    out = Solutions()
    info = _SearchInfo()
    if lib.cv_solver_get_search(h.solver, ctypes.byref(info)) == _lib.OK:
        out.search = {"starts": info.starts, "failed": info.failed,
                      "duplicates": info.duplicates, "found": info.found,
                      "stopped": info.stop.decode(errors="replace")}
    out.message = lib.cv_solver_last_error(h.solver).decode(errors="replace")
    for k in range(lib.cv_solver_get_num_solutions(h.solver)):
        if g.hit:
            return None
        lib.cv_solver_select_solution(h.solver, k)
        report = build_report(h)
        if title is not None:
            report["title"] = title
        out.append(Solution(None, *_arrays(h), _lib.OK, read_fields(h), report, title))
    return out

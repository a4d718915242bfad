"""calcvar._curve — the error of sol(x) between the nodes, estimated (Solution.curve_error).

The nodal values of a Galerkin solution are superconvergent (docs/theory.md, E-4): the
report's estimate and `tol` bound the error at the nodes, where it is smallest; between
them, sol(x) is the element's degree-p interpolant and its error is larger (7x on the
pendulum, 11x on the catenary's default mesh). The estimate here is the report's enriched
solve (HP-2) read everywhere: the same problem is solved once more on the same element
boundaries with two more degrees per element (an element of degree 7 or 8 halved into two
of degree 8), from this solution interpolated at the new nodes, and the two curves are
compared at 16 Chebyshev points inside each element and at the nodes. The enriched curve
is far more accurate than sol(x) (its degree is higher, and sol(x) between nodes is not
superconvergent), so the difference estimates sol(x)'s error.
SPDX-License-Identifier: MIT
"""
import ctypes

import numpy as np

from . import _lib
from ._errors import CalcvarError, status_name
from ._lib import lib

SAMPLES = 16  # Chebyshev points per element


def _gll(p):
    """The p+1 Gauss-Lobatto-Legendre points of degree p on [-1, 1]."""
    inner = np.polynomial.legendre.Legendre.basis(p).deriv().roots() if p > 1 else []
    return np.concatenate(([-1.0], np.sort(np.real(inner)), [1.0]))


def _enriched(xe, degrees):
    """Element boundaries and degrees of the enriched mesh (HP-2)."""
    t, deg = [xe[0]], []
    for e, p in enumerate(degrees):
        if p >= 7:
            t.append(0.5 * (xe[e] + xe[e + 1]))
            deg.append(8)
        t.append(xe[e + 1])
        deg.append(min(p + 2, 8))
    return np.array(t), np.array(deg, dtype=np.intc)


def estimate(sol, h, tick):
    """{"curve": max over the samples and nodes, "nodes": max over the nodes} of
    |sol(x) - y+(x)|, y+ the enriched solve; h the Solution's handles (locked)."""
    xe = sol._interp_().xe
    a, b = sol.interval
    t, deg = _enriched(xe, sol.degrees)
    nodes = [t[0]]
    for e, p in enumerate(deg):
        r = _gll(int(p))[1:]
        nodes.extend(t[e] + (r + 1) * (t[e + 1] - t[e]) / 2)
    nodes = np.clip(np.array(nodes), a, b)
    start = np.ascontiguousarray(sol(nodes).T)  # node-major
    f = lib.cv_solver_new(None)
    if not f:
        raise CalcvarError("CVAR_ENOMEM", "out of memory for the curve's error estimate")
    try:
        err = ctypes.create_string_buffer(_lib.ERRLEN)
        lib.cv_scene_configure_solver(h.scene, f, err, _lib.ERRLEN)
        lib.cv_solver_set_tol(f, 0.0, 0)
        lib.cv_solver_set_adapt(f, 0.0, 0)
        lib.cv_solver_set_continuation(f, 0)
        lib.cv_solver_set_breakpoints(f, 0, None)
        tr = np.ascontiguousarray((t - a) / (b - a))
        tr[0], tr[-1] = 0.0, 1.0
        st = lib.cv_solver_set_mesh_hp(f, len(deg), tr.ctypes.data, deg.ctypes.data)
        if st == _lib.OK:
            st = lib.cv_solver_set_start(f, start.size, start.ctypes.data)
        if st != _lib.OK:
            raise CalcvarError(status_name(st), "the enriched mesh was refused: %s"
                               % lib.cv_strerror(st).decode())
        lib.cv_solver_set_progress(f, tick, None)
        st = lib.cv_solve(f, h.problem)
        if st != _lib.OK:
            raise CalcvarError(status_name(st), "no estimate of the curve's error: the "
                               "enriched solve failed (%s)"
                               % lib.cv_solver_last_error(f).decode(errors="replace"))
        c = np.cos(np.pi * (np.arange(SAMPLES) + 0.5) / SAMPLES)
        xs = ((xe[:-1, None] + xe[1:, None]) / 2 + np.outer(np.diff(xe) / 2, c)).ravel()
        xs = np.clip(np.concatenate((xs, sol.x)), a, b)
        n = sol.values.shape[1]
        ref = np.empty((n, xs.size))
        lib.cv_solver_eval(f, xs.size, xs.ctypes.data, ref.ctypes.data, None)
        diff = np.abs(sol(xs) - ref)
        k = xs.size - sol.x.size
        return {"curve": float(diff.max()), "nodes": float(diff[:, k:].max())}
    finally:
        lib.cv_solver_free(f)

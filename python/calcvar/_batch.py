"""calcvar._batch — batch(): many parameter sets of one scene, as `calcvar batch` solves
them (the cv_batch_* API: the scene compiled once, rows on several threads), into a
numpy structured array.
SPDX-License-Identifier: MIT
"""
from __future__ import annotations

import ctypes
import os
import tempfile

import numpy as np

from . import _lib
from ._errors import InputError, bad, fail, status_word
from ._input import whole
from ._interrupt import Guard
from ._lib import lib

CHUNK = 256  # rows per call into the library: Ctrl-C is seen between two calls


def _columns(table):
    """{name: 1-d float array} from a dict of array-likes, a numpy structured array or a
    pandas DataFrame."""
    if hasattr(table, "columns") and hasattr(table, "to_numpy"):  # pandas
        table = {str(c): table[c].to_numpy() for c in table.columns}
    elif isinstance(table, np.ndarray) and table.dtype.names:
        table = {k: table[k] for k in table.dtype.names}
    if not isinstance(table, dict):
        raise TypeError("table must be a dict {parameter: values}, a numpy structured array "
                        "or a pandas DataFrame, not %s" % type(table).__name__)
    names = list(table)
    try:
        cols = np.broadcast_arrays(*[np.asarray(table[k], dtype=float) for k in names])
    except (TypeError, ValueError) as e:
        raise bad("table: the columns must be numbers of one length (%s)" % e) from None
    cols = [np.atleast_1d(c) for c in cols]
    if cols and cols[0].ndim != 1:
        raise bad("table: each column must be one-dimensional")
    return names, cols


def batch(scene, table, *, threads: int = 0, warm: bool = False,
          elements: int | None = None, degree: int | None = None) -> np.ndarray:
    """Solve the scene once per row of `table` (parameters of [parameters], a column per
    parameter given), as `calcvar batch SCENE TABLE` does, and return a numpy structured
    array: the table's columns, then status, action, iterations, time_s, morse_index (-1
    when unknown), error_max_nodal (against [exact], else NaN), error_estimate (of a tol or
    adapt solve, else NaN), one column per [report] entry and per [integrals] constraint
    (mu_NAME), warm (started from the previous row) and message. Rows that do not converge
    have NaN results and their status; `pandas.DataFrame(result)` makes a table of it.

    scene: a path, scene text or Problem. threads: 0 = the cores available. warm: start
    each row from the previous row's solution on the same thread. elements, degree:
    override [mesh]. Bad values (a row that makes the scene invalid) raise InputError
    naming the row (counted from 0) before anything is solved.
    """
    from ._solve import scene_text
    text = scene_text(scene)
    names, cols = _columns(table)
    nrows = cols[0].size if cols else 1
    rows = np.ascontiguousarray(np.stack(cols, axis=1) if cols else np.zeros((1, 0)))
    if not np.all(np.isfinite(rows)):
        raise bad("table: every value must be a finite number")
    threads = whole(threads, "threads")
    mesh = (0 if elements is None else whole(elements, "elements"),
            0 if degree is None else whole(degree, "degree"))
    err = ctypes.create_string_buffer(_lib.ERRLEN)
    path, tmp = text, None
    if isinstance(text, str) and ("\n" in text or text.lstrip().startswith("[")):
        fd, tmp = tempfile.mkstemp(suffix=".scene", prefix="calcvar-batch-")
        with os.fdopen(fd, "w") as f:
            f.write(text)
        path = tmp
    with Guard() as g:
        b = None
        try:
            b = lib.cv_batch_new(os.fsencode(path), err, _lib.ERRLEN)
            if not b:
                raise bad(err.value.decode(errors="replace").replace(tmp or "\0", "<string>"))
            return _run(b, g, names, rows, nrows, threads, warm, mesh, err)
        except InputError as e:
            if tmp:  # scene text: name it as solve() does, not by the temporary file
                raise bad(str(e).replace(tmp, "<string>")) from None
            raise
        finally:
            if b:
                lib.cv_batch_free(b)
            if tmp:
                os.unlink(tmp)


def _run(b, g, names, rows, nrows, threads, warm, mesh, err):
    enc = [n.encode() for n in names]
    arr = (ctypes.c_char_p * len(enc))(*enc)
    if lib.cv_batch_set_columns(b, len(enc), arr, err, _lib.ERRLEN) != _lib.OK:
        raise bad("table: " + err.value.decode(errors="replace"))
    if lib.cv_batch_set_threads(b, threads) != _lib.OK:
        raise bad("threads=%r: 0 (the cores) or a number of threads is needed" % threads)
    lib.cv_batch_set_warm_start(b, 1 if warm else 0)
    if lib.cv_batch_set_mesh(b, *mesh) != _lib.OK:
        raise bad("elements=%r, degree=%r: out of range" % mesh)
    for r in range(nrows):
        if lib.cv_batch_check_row(b, rows[r].ctypes.data, err, _lib.ERRLEN) != _lib.OK:
            raise bad("table row %d: %s" % (r, err.value.decode(errors="replace")))
    nout = lib.cv_batch_num_outputs(b)
    outs = [lib.cv_batch_output_name(b, k).decode() for k in range(nout)]
    outputs = np.full((nrows, max(nout, 1)), np.nan)
    res = (_lib.BatchResult * nrows)()
    base = outputs.ctypes.data
    for r in range(nrows):
        res[r].outputs = ctypes.cast(base + r * outputs.strides[0], _lib.dp) if nout else None
    size = ctypes.sizeof(_lib.BatchResult)
    for r0 in range(0, nrows, CHUNK):
        if g.hit:
            return None  # the Guard raises KeyboardInterrupt
        k = min(CHUNK, nrows - r0)
        st = lib.cv_batch_solve(b, k, rows[r0].ctypes.data,
                                ctypes.cast(ctypes.addressof(res) + r0 * size,
                                            ctypes.POINTER(_lib.BatchResult)))
        if st != _lib.OK:
            fail(st, "batch: the rows could not be solved (%s)" % lib.cv_strerror(st).decode())
    if g.hit:
        return None
    fixed = ("status", "action", "iterations", "time_s", "morse_index", "error_max_nodal",
             "error_estimate", "warm", "message")
    clash = [n for n in names if n in fixed or n in outs]
    if clash:
        raise bad("table: the parameter %r has the name of a result column; rename it in the "
                  "scene to use batch()" % clash[0])
    dtype = ([(n, "f8") for n in names]
             + [("status", "U16"), ("action", "f8"), ("iterations", "i4"), ("time_s", "f8"),
                ("morse_index", "i4"), ("error_max_nodal", "f8"), ("error_estimate", "f8")]
             + [(n, "f8") for n in outs] + [("warm", "?"), ("message", "O")])
    out = np.zeros(nrows, dtype=dtype)
    for i, n in enumerate(names):
        out[n] = rows[:, i]
    for r in range(nrows):
        q = res[r]
        ok = bool(q.has_result)
        out[r]["status"] = status_word(q.status)
        out[r]["action"] = q.action if ok else np.nan
        out[r]["iterations"] = q.iterations
        out[r]["time_s"] = q.time_s
        out[r]["morse_index"] = q.morse_index if ok else -1
        out[r]["error_max_nodal"] = q.error_max_nodal if ok else np.nan
        out[r]["error_estimate"] = q.error_estimate if ok else np.nan
        out[r]["warm"] = bool(q.warm)
        out[r]["message"] = q.message.decode(errors="replace")
    for k, n in enumerate(outs):
        out[n] = outputs[:, k]
    return out

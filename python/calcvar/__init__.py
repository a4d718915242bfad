"""calcvar — calculus of variations by direct discretisation, from Python.

Three lines to a solved catenary::

    import calcvar
    sol = calcvar.solve("catenary.scene")
    print(sol.status, sol.action, sol(0.5))

`solve` takes a scene (a path, the text of a scene, or a `Problem` built from Python
values) and the options of the command `calcvar solve`; `batch` solves a table of
parameter sets; `equations` and `modes` give its mechanics (as `calcvar equations` and
`calcvar modes`). The work is done by the C library libcalcvar through ctypes; a
Solution owns its data (docs/python.md).
SPDX-License-Identifier: MIT
"""
import ctypes

from . import _lib
from ._batch import batch
from ._errors import CalcvarError, InputError
from ._lib import lib
from ._mechanics import equations, modes
from ._problem import Problem
from ._solution import Solution, Solutions
from ._solve import METHODS, solve

__all__ = ["solve", "batch", "equations", "modes", "Solution", "Solutions", "Problem",
           "CalcvarError", "InputError", "version", "dependency_versions", "METHODS",
           "__version__"]


def version():
    """The library's version as a string, e.g. "0.1.0"."""
    return "%d.%d.%d" % _lib.version()


__version__ = version()


def dependency_versions():
    """The libraries linked into libcalcvar, as they report their versions."""
    buf = ctypes.create_string_buffer(256)
    lib.cv_dependency_versions(buf, len(buf))
    return buf.value.decode()

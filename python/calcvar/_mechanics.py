"""calcvar._mechanics — equations() and modes(): `calcvar equations` and `calcvar modes`
of a scene, as the dicts of their --json (docs/mechanics.md).
SPDX-License-Identifier: MIT
"""
from __future__ import annotations

import ctypes
import json

from . import _lib
from ._errors import fail
from ._interrupt import Guard
from ._lib import lib


def _mechanics(new, to_json, free, scene, set):
    from ._solve import load, scene_text
    with Guard():
        h = load(scene_text(scene), set)
        err = ctypes.create_string_buffer(_lib.ERRLEN)
        why = ctypes.c_int(_lib.OK)
        r = None
        try:
            r = new(h, ctypes.byref(why), err, _lib.ERRLEN)
            if not r:
                fail(why.value, err.value.decode(errors="replace"))
            return json.loads(to_json(r).decode(errors="replace"))
        finally:
            if r:
                free(r)
            lib.cv_scene_free(h)


def equations(scene, *, set: dict | None = None) -> dict:
    """The mechanics of a scene's integrand F (a path, scene text or Problem, with `set`
    overriding [parameters]) as a dict, the JSON of `calcvar equations --json`
    (docs/mechanics.md): "momenta" and "euler_lagrange" ({unknown: expression}),
    "hamiltonian", "cyclic" (the unknowns F does not contain) and "autonomous" (F does not
    contain the variable). The expressions are text in the scene grammar with the
    parameters as numbers."""
    return _mechanics(lib.cv_equations_new, lib.cv_equations_json, lib.cv_equations_free,
                      scene, set)


def modes(scene, *, set: dict | None = None) -> dict:
    """The equilibrium of a scene's Lagrangian L(y, y') found from its guess at the start
    of the interval, and the small oscillations there, as a dict: the JSON of `calcvar
    modes --json` (docs/mechanics.md): "equilibrium" ({unknown: value}), "modes" (a list of
    {"omega2", "kind", "shape"}, omega2 increasing), and "multipliers" / "gyroscopic" when
    they apply. Raises InputError when modes do not apply (L depends on the variable,
    integral constraints) and CalcvarError (status CVAR_EMAXITER, CVAR_ESINGULAR, ...) when
    no equilibrium or no modes are found."""
    return _mechanics(lib.cv_modes_new, lib.cv_modes_json, lib.cv_modes_free, scene, set)

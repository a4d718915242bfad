"""calcvar._lib — the C library through ctypes (internal).

The library is found, in order, at $CALCVAR_LIB, beside the module in the wheel of
`pip install .` (meson-python's .calcvar.mesonpy.libs), at the path meson wrote into
_config.py when it installed this module, or by ctypes.util.find_library. Every call
below goes through ctypes.CDLL, which releases the GIL for the duration of the call
(so a long cv_solve does not block other Python threads); callbacks take it back.
SPDX-License-Identifier: MIT
"""
import ctypes
import ctypes.util
import os
from ctypes import (CFUNCTYPE, POINTER, Structure, c_char_p, c_double, c_int, c_size_t,
                    c_void_p)

ERRLEN = 1024


def _find():
    path = os.environ.get("CALCVAR_LIB")
    if path:
        return path
    try:
        from . import _config  # written by meson at install time
    except ImportError:  # the source tree (tests set CALCVAR_LIB)
        _config = None
    if _config is not None:
        here = os.path.dirname(os.path.abspath(__file__))
        bundled = os.path.join(os.path.dirname(here), ".calcvar.mesonpy.libs", _config.BUNDLED)
        for path in (bundled, _config.LIBRARY):
            if os.path.exists(path):
                return path
    name = ctypes.util.find_library("calcvar")
    if name:
        return name
    raise ImportError("calcvar: libcalcvar.so not found; install calcvar or set CALCVAR_LIB "
                      "to the library's path")


lib = ctypes.CDLL(_find())

dp = POINTER(c_double)


class Progress(Structure):
    """cv_progress of calcvar.h."""
    _fields_ = [("kind", c_int), ("iteration", c_int), ("residual", c_double),
                ("step", c_double), ("alpha", c_double), ("action", c_double),
                ("round", c_int), ("elements", c_int), ("estimate", c_double)]


# cv_progress_fn, its arguments left as addresses (the cheapest call for the interrupt check;
# a progress function reads Progress.from_address(info))
TICK_FN = CFUNCTYPE(c_int, c_void_p, c_void_p)
GUESS_FN = CFUNCTYPE(c_int, c_int, POINTER(c_double), POINTER(c_double), c_void_p)


def _sig(name, restype, *argtypes):
    f = getattr(lib, name)
    f.restype = restype
    f.argtypes = list(argtypes)


_sig("cv_version", None, POINTER(c_int), POINTER(c_int), POINTER(c_int))
_sig("cv_strerror", c_char_p, c_int)
_sig("cv_status_name", c_char_p, c_int)
_sig("cv_dependency_versions", c_int, c_char_p, c_size_t)
_sig("cv_method_from_name", c_int, c_char_p, POINTER(c_int))
_sig("cv_method_name", c_char_p, c_int)

_sig("cv_scene_load_file", c_void_p, c_char_p, c_int, POINTER(c_char_p), c_char_p, c_size_t)
_sig("cv_scene_load_text", c_void_p, c_char_p, c_char_p, c_int, POINTER(c_char_p), c_char_p,
     c_size_t)
_sig("cv_scene_free", None, c_void_p)
_sig("cv_scene_get_num_unknowns", c_int, c_void_p)
_sig("cv_scene_get_unknown", c_char_p, c_void_p, c_int)
_sig("cv_scene_get_title", c_char_p, c_void_p)
_sig("cv_scene_get_variable", c_char_p, c_void_p)
_sig("cv_scene_get_num_constraints", c_int, c_void_p)
_sig("cv_scene_get_constraint", c_char_p, c_void_p, c_int)
_sig("cv_scene_get_num_integrals", c_int, c_void_p)
_sig("cv_scene_get_integral", c_char_p, c_void_p, c_int)
_sig("cv_scene_set_option", c_int, c_void_p, c_char_p, c_double, c_char_p, c_size_t)
_sig("cv_scene_problem_new", c_void_p, c_void_p, c_char_p, c_size_t)
_sig("cv_scene_configure_solver", c_int, c_void_p, c_void_p, c_char_p, c_size_t)
_sig("cv_report_new", c_void_p, c_void_p, c_void_p, c_void_p, POINTER(c_int))
_sig("cv_report_json", c_char_p, c_void_p)
_sig("cv_report_free", None, c_void_p)
_sig("cv_equations_new", c_void_p, c_void_p, POINTER(c_int), c_char_p, c_size_t)
_sig("cv_equations_json", c_char_p, c_void_p)
_sig("cv_equations_free", None, c_void_p)
_sig("cv_modes_new", c_void_p, c_void_p, POINTER(c_int), c_char_p, c_size_t)
_sig("cv_modes_json", c_char_p, c_void_p)
_sig("cv_modes_free", None, c_void_p)

_sig("cv_problem_free", None, c_void_p)
_sig("cv_problem_set_guess", c_int, c_void_p, GUESS_FN, c_void_p)
_sig("cv_solve_all", c_int, c_void_p, c_void_p, c_int)
_sig("cv_solver_set_search_work", c_int, c_void_p, c_double)
_sig("cv_solver_get_num_solutions", c_int, c_void_p)
_sig("cv_solver_select_solution", c_int, c_void_p, c_int)
_sig("cv_solver_get_search", c_int, c_void_p, c_void_p)
_sig("cv_problem_get_interval", None, c_void_p, dp, dp)
_sig("cv_solver_new", c_void_p, POINTER(c_int))
_sig("cv_solver_free", None, c_void_p)
_sig("cv_solver_set_progress", c_int, c_void_p, TICK_FN, c_void_p)
_sig("cv_solve", c_int, c_void_p, c_void_p)
_sig("cv_solver_get_status", c_int, c_void_p)
_sig("cv_solver_get_method", c_int, c_void_p)
_sig("cv_solver_last_error", c_char_p, c_void_p)
_sig("cv_solver_get_num_nodes", c_int, c_void_p)
_sig("cv_solver_get_num_elements", c_int, c_void_p)
_sig("cv_solver_get_degree", c_int, c_void_p)
# arrays are passed as addresses (numpy's arr.ctypes.data): cheaper than data_as
_sig("cv_solver_get_nodes", c_int, c_void_p, c_void_p)
_sig("cv_solver_get_values", c_int, c_void_p, c_void_p)
_sig("cv_solver_get_action", c_double, c_void_p)
_sig("cv_solver_get_num_iterations", c_int, c_void_p)
_sig("cv_solver_get_morse_index", c_int, c_void_p)
_sig("cv_solver_eval", c_int, c_void_p, c_int, c_void_p, c_void_p, c_void_p)
_sig("cv_solver_get_degrees", c_int, c_void_p, c_void_p)
_sig("cv_solver_get_error_estimate", c_double, c_void_p)
_sig("cv_solver_get_time", c_double, c_void_p)
_sig("cv_solver_get_multiplier_field", c_int, c_void_p, c_int, c_void_p)
_sig("cv_solver_get_multiplier", c_int, c_void_p, c_int, POINTER(c_double))
_sig("cv_solver_set_start", c_int, c_void_p, c_int, c_void_p)
_sig("cv_solver_set_mesh_hp", c_int, c_void_p, c_int, c_void_p, c_void_p)
_sig("cv_solver_set_tol", c_int, c_void_p, c_double, c_int)
_sig("cv_solver_set_adapt", c_int, c_void_p, c_double, c_int)
_sig("cv_solver_set_breakpoints", c_int, c_void_p, c_int, c_void_p)
_sig("cv_solver_set_continuation", c_int, c_void_p, c_int)
_sig("cv_problem_get_num_constraints", c_int, c_void_p)
_sig("cv_problem_get_num_integrals", c_int, c_void_p)

# cv_batch_* (the engine of `calcvar batch`)
class BatchResult(Structure):
    """cv_batch_result of calcvar.h."""
    _fields_ = [("status", c_int), ("iterations", c_int), ("time_s", c_double),
                ("has_result", c_int), ("action", c_double), ("morse_index", c_int),
                ("error_max_nodal", c_double), ("error_estimate", c_double),
                ("outputs", POINTER(c_double)), ("warm", c_int), ("message", ctypes.c_char * 1024)]


_sig("cv_batch_new", c_void_p, c_char_p, c_char_p, c_size_t)
_sig("cv_batch_free", None, c_void_p)
_sig("cv_batch_num_parameters", c_int, c_void_p)
_sig("cv_batch_parameter_name", c_char_p, c_void_p, c_int)
_sig("cv_batch_num_outputs", c_int, c_void_p)
_sig("cv_batch_output_name", c_char_p, c_void_p, c_int)
_sig("cv_batch_set_columns", c_int, c_void_p, c_int, POINTER(c_char_p), c_char_p, c_size_t)
_sig("cv_batch_set_threads", c_int, c_void_p, c_int)
_sig("cv_batch_set_warm_start", c_int, c_void_p, c_int)
_sig("cv_batch_set_mesh", c_int, c_void_p, c_int, c_int)
_sig("cv_batch_check_row", c_int, c_void_p, c_void_p, c_char_p, c_size_t)
_sig("cv_batch_solve", c_int, c_void_p, c_int, c_void_p, POINTER(BatchResult))

STATUS = {}
_k = 0
while True:
    _name = lib.cv_status_name(_k).decode()
    if _name == "CVAR_UNKNOWN" or _k > 64:
        break
    STATUS[_name] = _k
    _k += 1
OK = STATUS["CVAR_OK"]
EINVAL = STATUS["CVAR_EINVAL"]
ECANCELLED = STATUS["CVAR_ECANCELLED"]
EMAXITER = STATUS["CVAR_EMAXITER"]
ENOMEM = STATUS["CVAR_ENOMEM"]


def version():
    a, b, c = c_int(), c_int(), c_int()
    lib.cv_version(ctypes.byref(a), ctypes.byref(b), ctypes.byref(c))
    return (a.value, b.value, c.value)

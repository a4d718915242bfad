"""calcvar._errors — the exceptions, and the words for the library's status codes.
SPDX-License-Identifier: MIT
"""
from . import _lib
from ._lib import lib


class CalcvarError(Exception):
    """A failure of the library: `status` is the status name (e.g. "CVAR_ENOMEM"),
    `message` the sentence."""

    def __init__(self, status, message):
        super().__init__(message)
        self.status = status
        self.message = message

    def __reduce__(self):  # picklable (process pools send exceptions back)
        return (type(self), (self.status, self.message))


class InputError(CalcvarError, ValueError):
    """Bad input (a scene, an option, an argument): the message says FILE:LINE: what is
    wrong where there is a line. Also a ValueError."""


def bad(message):
    return InputError("CVAR_EINVAL", message)


_NAMES = {}
_WORDS = {"CVAR_EMAXITER": "max_iterations", "CVAR_ENONFINITE": "diverged",
          "CVAR_EDIVERGED": "diverged", "CVAR_ESINGULAR": "singular"}


def status_name(code):
    name = _NAMES.get(code)
    if name is None:
        name = _NAMES[code] = lib.cv_status_name(code).decode()
    return name


def status_word(code):
    """The report's status words (those of `calcvar solve`'s JSON "status")."""
    if code == _lib.OK:
        return "converged"
    return _WORDS.get(status_name(code), "no_progress")


def fail(code, message):
    cls = InputError if code == _lib.EINVAL else CalcvarError
    raise cls(status_name(code), message)

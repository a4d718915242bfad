"""calcvar._interrupt — Ctrl-C during a call into the library (docs/python.md, "Interrupts").

A solve runs in C with the GIL released; Python's own SIGINT handler would only run once
it returns. While a `Guard` is active on the main thread, SIGINT sets a flag instead of
raising: the solve's progress callback (called by the library after every Newton step and
adaptive round) sees it and cancels the solve, the library returns, every handle is
released, and the guard raises KeyboardInterrupt on leaving. A KeyboardInterrupt is thus
never raised inside a ctypes callback (where Python can only print it and go on) nor
between a C allocation and the code that owns its result.
SPDX-License-Identifier: MIT
"""
import threading

try:  # the C module behind `signal`, without its enum conversions (5x faster per call)
    import _signal as _sig
except ImportError:  # pragma: no cover - another interpreter
    import signal as _sig

SIGINT = _sig.SIGINT
_default = _sig.default_int_handler
_main = threading.main_thread().ident
_ident = threading.get_ident


class Guard:
    """`with Guard() as g:` ... `g.hit` is true once Ctrl-C was pressed; on leaving, the
    interrupt is delivered (KeyboardInterrupt, or the handler that was installed)."""

    __slots__ = ("hit", "_old")

    def __init__(self):
        self.hit = False
        self._old = None

    def _on_sigint(self, signum, frame):
        self.hit = True

    def __enter__(self):
        if _ident() == _main:
            old = _sig.getsignal(SIGINT)
            if callable(old):  # not SIG_IGN / SIG_DFL (Ctrl-C ignored, or fatal anyway)
                _sig.signal(SIGINT, self._on_sigint)
                self._old = old
        return self

    def __exit__(self, kind, value, tb):
        old, self._old = self._old, None
        if old is not None:
            _sig.signal(SIGINT, old)
            if self.hit and kind is None:
                if old is _default:
                    raise KeyboardInterrupt
                old(SIGINT, None)  # the program's own handler decides
        return False

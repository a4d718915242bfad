"""calcvar._input — Python values into calcvar's input: numbers (numpy scalars too),
expressions (text in calcvar's grammar, or sympy expressions printed into it), names.

Nothing is silently cut or changed: a value the scene format could not carry (a line break,
'#' or ';', which start comments) is refused with a sentence, and `**` gets the hint to
write powers with `^`.
SPDX-License-Identifier: MIT
"""
import numbers
import re

import numpy as np

from ._errors import bad

NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")


def number(v, what):
    """A real from a Python or numpy number (or a 0-d array)."""
    if type(v) is float or type(v) is int:  # the common case, without the ABC checks
        return float(v)
    if isinstance(v, np.ndarray) and v.ndim == 0:
        v = v[()]
    if isinstance(v, (bool, np.bool_)) or not isinstance(v, numbers.Real):
        raise bad("%s=%r: a number is needed" % (what, v))
    return float(v)


def whole(v, what):
    """A whole number from a Python or numpy integer, or a float with no fraction."""
    if type(v) is int:
        return v
    x = number(v, what)
    if not np.isfinite(x) or x != int(x):
        raise bad("%s=%r: a whole number is needed" % (what, v))
    return int(x)


def name(v, what):
    if not isinstance(v, str) or not NAME.match(v):
        raise bad("%s: %r is not a name (letters, digits and _, not starting with a digit)"
                  % (what, v))
    return v


def _sympy_text(e):
    """A sympy expression printed in calcvar's grammar (fully parenthesised)."""
    import sympy as sp
    fn = {sp.sin: "sin", sp.cos: "cos", sp.tan: "tan", sp.asin: "asin", sp.acos: "acos",
          sp.atan: "atan", sp.sinh: "sinh", sp.cosh: "cosh", sp.tanh: "tanh",
          sp.asinh: "asinh", sp.acosh: "acosh", sp.atanh: "atanh", sp.exp: "exp",
          sp.log: "log", sp.Abs: "abs", sp.atan2: "atan2"}

    def go(e):
        if e is sp.pi:
            return "pi"
        if e is sp.E:
            return "exp(1)"
        if e.is_Integer:
            return str(int(e))
        if e.is_Rational:
            return "(%d/%d)" % (e.p, e.q)
        if e.is_Float:
            return repr(float(e))
        if e.is_Symbol:
            return str(e.name)
        if isinstance(e, sp.Derivative):
            f = e.expr
            if (isinstance(f, sp.core.function.AppliedUndef) and len(e.variable_count) == 1
                    and e.variable_count[0][1] in (1, 2)):
                return f.func.__name__ + "'" * e.variable_count[0][1]
            raise TypeError("sympy: only first or second derivatives of an unknown "
                            "function, y(x).diff(x), can be written in calcvar's grammar: %s"
                            % e)
        if isinstance(e, sp.core.function.AppliedUndef):
            return e.func.__name__
        if e.is_Add:
            return "(" + " + ".join(go(a) for a in e.args) + ")"
        if e.is_Mul:
            return "(" + "*".join(go(a) for a in e.args) + ")"
        if e.is_Pow:
            return "(%s^%s)" % (go(e.base), go(e.exp))
        if isinstance(e, (sp.Min, sp.Max)):
            out = go(e.args[0])
            for a in e.args[1:]:
                out = "%s(%s, %s)" % ("min" if isinstance(e, sp.Min) else "max", out, go(a))
            return out
        for cls, fname in fn.items():
            if isinstance(e, cls):
                return "%s(%s)" % (fname, ", ".join(go(a) for a in e.args))
        raise TypeError("sympy: %s (%s) has no counterpart in calcvar's grammar "
                        "(docs/expressions.md)" % (e, type(e).__name__))

    return go(sp.sympify(e))


def _is_sympy(v):
    mod = type(v).__module__ or ""
    return mod.startswith("sympy")


def expr(v, what):
    """An expression as text in calcvar's grammar, from a str, a number or a sympy
    expression. A Python function is refused with what to pass instead."""
    if isinstance(v, str):
        text = v
    elif isinstance(v, (numbers.Real, np.ndarray)) and not isinstance(v, (bool, np.bool_)):
        return repr(number(v, what))
    elif _is_sympy(v):
        text = _sympy_text(v)
    elif callable(v):
        raise TypeError("%s: a Python function cannot be used as an expression (calcvar "
                        "differentiates its expressions symbolically and compiles them); "
                        "pass a string in calcvar's grammar, e.g. \"y*sqrt(1 + y'^2)\", or a "
                        "sympy expression" % what)
    else:
        raise TypeError("%s: an expression is needed (a string in calcvar's grammar, a "
                        "number or a sympy expression), not %s" % (what, type(v).__name__))
    check_text(text, what)
    return text


def check_text(text, what):
    """Refuse what the scene format would read otherwise than written."""
    if "**" in text:
        raise bad("%s = %s: use ^ for powers in calcvar's grammar (x^2, not x**2)"
                  % (what, text))
    for c, why in (("\n", "a line break"), ("\r", "a line break"), ("#", "'#'"),
                   (";", "';'"), ("\0", "a NUL byte")):
        if c in text:
            raise bad("%s = %r: %s cannot appear in an expression" % (what, text, why))
    if not text.strip():
        raise bad("%s: the expression is empty" % what)

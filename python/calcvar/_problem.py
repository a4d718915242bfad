"""calcvar._problem — Problem: a variational problem from Python values.

Each value is checked and converted on its own (names, numbers, expressions as text or
sympy, _input.py) before the scene text is assembled from them, so that nothing the
scene format would read differently (a '#' or ';' starting a comment, a line break) gets
in: such a value is refused with a sentence, and a title that carries them is kept by the
Problem itself (Solution.title and report["title"] are the Problem's title).
SPDX-License-Identifier: MIT
"""
from ._errors import bad
from ._input import check_text, expr, name, number


def _pair(v, what):
    try:
        a, b = v
    except (TypeError, ValueError):
        raise bad("%s: a pair (value at a, value at b) is needed" % what) from None
    return a, b


def _end(v, what):
    if v is None or (isinstance(v, str) and v.strip() == "free"):
        return "free"
    return expr(v, what)


def _setting(v, what):
    if isinstance(v, str):
        check_text(v, what)
        return v
    x = number(v, what)
    # counts (elements, degree, max_iterations) are read as whole numbers: 4, not 4.0
    return str(int(x)) if float(x).is_integer() and abs(x) < 2**53 else repr(x)


class Problem:
    """A variational problem built from Python values instead of a file, loaded by the
    scene loader (the rules and messages of docs/scenes.md; Problem.text is the scene).

    integrand   F, an expression of the variable, unknowns and primed unknowns (y', and
                y'' for a second-order integrand: C1 elements, docs/beams.md):
                a string in calcvar's grammar (powers with ^) or a sympy expression
    interval    (a, b)
    boundary    {unknown: (value_at_a, value_at_b)}; None or "free" leaves that end free
                (natural boundary condition); values may be expressions; "periodic" or
                "periodic + D" instead of the pair makes a closed path (docs/periodic.md)
    unknowns    names in order (default: the order of boundary)
    variable    the independent variable's name (default "x")
    parameters  {name: value}          definitions  {name: expression}
    constraints {name: G}              pointwise G(x, y) = 0, multiplier field lambda_name;
                                       "G >= 0" or "G <= 0": an obstacle (docs/obstacles.md)
    ends        {"start" | "end": "free" or G(x, y)}: a moving end (docs/moving-ends.md)
    integrals   {name: (K, c)}         int K dx = c, multiplier mu_name
    guess, exact {unknown: expression of the variable}; exact may have "action": value
    report      {name: K}              integrals reported after solving
    mesh, solver {key: value}          [mesh] and [solver] entries
    title       any text (kept as given)

    Numbers may be Python or numpy numbers; expressions strings or sympy expressions.
    """

    def __init__(self, integrand, interval, boundary, unknowns=None, variable="x",
                 parameters=None, definitions=None, constraints=None, integrals=None,
                 guess=None, exact=None, report=None, mesh=None, solver=None, title=None,
                 ends=None):
        if not isinstance(boundary, dict):
            raise bad("boundary must be a dict {unknown: (value at a, value at b)}")
        if unknowns is None:  # slope lines ("y'") are not unknowns
            unknowns = [k for k in boundary if not str(k).endswith("'")]
        elif isinstance(unknowns, str):
            unknowns = [u.strip() for u in unknowns.split(",")]
        unknowns = [name(u, "unknowns") for u in unknowns]
        a, b = _pair(interval, "interval")
        self.title = "Problem" if title is None else str(title)
        plain = all(c not in self.title for c in "#;\n\r\0") and self.title.strip()
        lines = ["[scene]",
                 "title = %s" % (self.title.strip() if plain else "Problem"),
                 "variable = %s" % name(variable, "variable"),
                 "interval = %s, %s" % (expr(a, "interval"), expr(b, "interval")),
                 "unknowns = %s" % ", ".join(unknowns),
                 "integrand = %s" % expr(integrand, "integrand")]

        def section(title, items, fmt):
            if items:
                if not isinstance(items, dict):
                    raise bad("%s must be a dict" % title)
                lines.append("[%s]" % title)
                for k, v in items.items():
                    # a slope line "y'" of a second-order unknown (docs/beams.md)
                    slope = title == "boundary" and isinstance(k, str) and k.endswith("'")
                    key = name(k[:-1], title) + "'" if slope else name(k, title)
                    lines.append("%s = %s" % (key, fmt(k, v, "[%s] %s" % (title, k))))

        def ex(k, v, what):
            return expr(v, what)

        def values(k, v, what):
            if isinstance(v, str) and v.strip().startswith("periodic"):  # docs/periodic.md
                check_text(v, what)
                return v.strip()
            ya, yb = _pair(v, what)
            return "%s, %s" % (_end(ya, what), _end(yb, what))

        def moving(k, v, what):  # docs/moving-ends.md
            if k not in ("start", "end"):
                raise bad("%s: the keys of ends are 'start' and 'end'" % what)
            return _end(v, what)

        def integral(k, v, what):
            K, c = _pair(v, what + " (K, c)")
            return "%s, %s" % (expr(K, what), expr(c, what))

        section("parameters", parameters, ex)
        section("definitions", definitions, ex)
        section("boundary", boundary, values)
        section("guess", guess, ex)
        section("constraints", constraints, ex)
        section("integrals", integrals, integral)
        section("exact", exact, ex)
        section("ends", ends, moving)
        section("report", report, ex)
        section("mesh", mesh, lambda k, v, w: _setting(v, w))
        section("solver", solver, lambda k, v, w: _setting(v, w))
        self.text = "\n".join(lines) + "\n"
        # load once now, so that bad input is reported here
        from ._solve import load
        from ._lib import lib
        lib.cv_scene_free(load(self.text, None))

    def solve(self, **options):
        """calcvar.solve on this problem, with the same options."""
        from ._solve import solve
        return solve(self, **options)

    def equations(self):
        """Momenta, Euler-Lagrange equations and Hamiltonian as a dict: calcvar.equations
        on this problem."""
        from ._mechanics import equations
        return equations(self.text)

    def modes(self):
        """Equilibrium and small-oscillation modes as a dict: calcvar.modes on this
        problem."""
        from ._mechanics import modes
        return modes(self.text)

    def __repr__(self):
        return "<calcvar.Problem %r>\n%s" % (self.title, self.text)

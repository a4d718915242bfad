#!/usr/bin/env python3
# tests/periodic/test_periodic.py — periodic unknowns (docs/periodic.md, theory PB-1, PB-2)
# through `calcvar solve --json -` against independent answers:
#  - the pendulum libration of period 8 (F = th'^2/2 + cos th): action 6.68858249672602
#    from elliptic functions; Morse index 1 on periodic paths with the shift pinned (the
#    constant mode is the one negative direction: the branch bifurcating from the
#    equilibrium at T = 2 pi takes the amplitude direction's sign away, docs/periodic.md);
#  - the rotating pendulum (th = periodic + 2 pi) of period 4: the action from the energy E
#    that gives the period, T(E) = int_0^2pi dth / sqrt(2 (E + cos th)),
#    A = int_0^2pi sqrt(2 (E + cos th)) dth - E T, computed here by the trapezoid rule
#    (exponentially accurate for a smooth periodic integrand) and bisection; the rotation is
#    the least action among loops that wind once: Morse index 0;
#  - the resonant oscillator y'' + y = 0 on loops of period 2 pi: a family (every
#    a cos t + b sin t), reported "degenerate", never a plain minimum or saddle;
#  - bad [boundary] lines with their line number (exit 2).
# Tolerance: --tol 1e-10 bounds the nodal error; the action's error is of second order in
# it, so 1e-9 is 10 T.
# SPDX-License-Identifier: MIT
import json, math, os, subprocess, sys, tempfile

calcvar = os.path.abspath(sys.argv[1])
fails = 0


def check(what, ok, detail=""):
    global fails
    if not ok:
        fails += 1
        print("FAIL", what, detail)


def run(text, *args):
    with tempfile.NamedTemporaryFile("w", suffix=".scene", delete=False) as f:
        f.write(text)
        name = f.name
    try:
        return subprocess.run([calcvar, "solve", name, *args], capture_output=True, text=True)
    finally:
        os.unlink(name)


PEND = """[scene]
interval  = 0, %s
variable  = t
unknowns  = th
integrand = th'^2/2 + cos(th)
[boundary]
th = %s
[guess]
th = %s
"""
p = run(PEND % ("8", "periodic", "1.5*cos(2*pi*t/8)"), "--tol", "1e-10", "--json", "-")
r = json.loads(p.stdout)
check("libration converged", r["status"] == "converged", r["message"])
check("libration action", abs(r["action"] - 6.68858249672602) <= 1e-9, r["action"])
check("libration index", r["morse_index"] == 1, r["morse_index"])
check("libration pinned", r.get("pinned") == ["shift"] and r.get("period") == 8, r)


def rotation(T):
    N = 4000

    def trap(f):
        return sum(f(2 * math.pi * k / N) for k in range(N)) * 2 * math.pi / N

    def period(E):
        return trap(lambda th: 1 / math.sqrt(2 * (E + math.cos(th))))

    lo, hi = 1 + 1e-9, 1e4
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if period(mid) > T else (lo, mid)
    E = 0.5 * (lo + hi)
    return trap(lambda th: math.sqrt(2 * (E + math.cos(th)))) - E * T


A = rotation(4.0)
p = run(PEND % ("4", "periodic + 2*pi", "2*pi*t/4"), "--tol", "1e-10", "--json", "-")
r = json.loads(p.stdout)
check("rotation converged", r["status"] == "converged", r["message"])
check("rotation action", abs(r["action"] - A) <= 1e-9, (r["action"], A))
check("rotation index", r["morse_index"] == 0, r["morse_index"])

RES = """[scene]
interval  = 0, 2*pi
unknowns  = y
integrand = y'^2/2 - y^2/2
[boundary]
y = periodic
[guess]
y = cos(x)
"""
p = run(RES, "--json", "-")
r = json.loads(p.stdout) if p.stdout else {}
check("resonant family not a plain stationary point",
      r.get("status") != "converged" or r.get("stationary_kind") == "degenerate", r)

for line, what in (("periodic, 0", "replaces both end values"), ("periodic * 2", "'+ D'"),
                   ("0, periodic", "replaces both end values")):
    p = run(PEND % ("8", line, "1"))
    check("bad %r" % line, p.returncode == 2 and ":7:" in p.stderr and what in p.stderr,
          p.stderr)

print("%d failures" % fails)
sys.exit(1 if fails else 0)

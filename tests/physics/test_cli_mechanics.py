#!/usr/bin/env python3
# tests/physics/test_cli_mechanics.py — `calcvar equations`, `calcvar modes` and
# `calcvar check` through the binary: the JSON of SCENES.md (exact key sets and types),
# the expressions parsed and evaluated at random points against hand-derived mechanics,
# normal modes, and bad inputs (exit status, message, nothing written).
# SPDX-License-Identifier: MIT
#
# usage: test_cli_mechanics.py CALCVAR PROBLEMS_DIR DATA_DIR
#   PROBLEMS_DIR: copies of shared/problems; DATA_DIR: this folder's extra scenes.
import json
import math
import os
import random
import re
import subprocess
import sys
import tempfile

calcvar, problems, data = [os.path.abspath(a) for a in sys.argv[1:4]]
failures = 0
checks = 0


def check(what, ok, detail=""):
    global failures, checks
    checks += 1
    if not ok:
        failures += 1
        print("FAIL %s\n  %s" % (what, detail))


def run(*args, expect_rc=0):
    r = subprocess.run([calcvar] + list(args), capture_output=True, text=True, timeout=120)
    check(" ".join(args) + " sanitizers",
          "Sanitizer" not in r.stderr and "runtime error:" not in r.stderr, r.stderr[:2000])
    check(" ".join(args) + " exit status", r.returncode == expect_rc,
          "expected %d, got %d; stderr: %s" % (expect_rc, r.returncode, r.stderr.strip()))
    return r


def run_json(*args):
    r = run(*args, "--json", "-")
    try:
        return json.loads(r.stdout)
    except ValueError:
        check(" ".join(args) + " JSON parses", False, r.stdout[:300])
        return {}


# The scene grammar as Python: y'' -> y__pp, y' -> y__p, ^ -> **, if -> if_.
FUNCS = {f: getattr(math, f) for f in ("sin", "cos", "tan", "asin", "acos", "atan", "sinh",
                                       "cosh", "tanh", "asinh", "acosh", "atanh", "exp", "log",
                                       "sqrt", "atan2", "pow")}
FUNCS.update(abs=abs, min=min, max=max, pi=math.pi,
             if_=lambda c, a, b: a if c else b)


def to_python(expr):
    s = re.sub(r"([A-Za-z_]\w*)''", r"\1__pp", expr)
    s = re.sub(r"([A-Za-z_]\w*)'", r"\1__p", s)
    s = re.sub(r"\bif\(", "if_(", s)
    return compile(s.replace("^", "**"), expr, "eval")


def evaluate(code, values):
    env = dict(FUNCS)
    for k, v in values.items():
        env[k.replace("''", "__pp").replace("'", "__p")] = v
    return eval(code, {"__builtins__": {}}, env)


def pendulum_equations(m, l, g, *sets):
    o = run_json("equations", os.path.join(problems, "pendulum_angle.scene"), *sets)
    check("equations JSON keys", set(o) == {"momenta", "euler_lagrange", "hamiltonian", "cyclic",
                                            "autonomous"}, sorted(o))
    if set(o) != {"momenta", "euler_lagrange", "hamiltonian", "cyclic", "autonomous"}:
        return
    check("equations JSON types", isinstance(o["momenta"]["th"], str) and
          isinstance(o["euler_lagrange"]["th"], str) and isinstance(o["hamiltonian"], str) and
          o["cyclic"] == [] and o["autonomous"] is True, json.dumps(o))
    E = to_python(o["euler_lagrange"]["th"])
    P = to_python(o["momenta"]["th"])
    H = to_python(o["hamiltonian"])
    rng = random.Random(7)
    ratio = None
    for k in range(200):
        v = {"t": rng.uniform(0, 1), "th": rng.uniform(-10, 10), "th'": rng.uniform(-7, 7),
             "th''": rng.uniform(-50, 50)}
        he = m * l * l * v["th''"] + m * g * l * math.sin(v["th"])
        hp = m * l * l * v["th'"]
        hh = m * l * l * v["th'"] ** 2 / 2 - m * g * l * math.cos(v["th"])
        scale = m * l * l * (abs(v["th''"]) + v["th'"] ** 2) + m * g * l
        e = evaluate(E, v)
        # SCENES.md: any nonzero constant multiple of the Euler–Lagrange expression.
        if ratio is None and abs(he) > 1e-3 * scale:
            ratio = e / he
        if ratio is not None:
            check("pendulum E point %d (m=%g)" % (k, m), abs(e - ratio * he) <= 1e-12 * scale *
                  abs(ratio), "%r vs %r * %r" % (e, ratio, he))
        check("pendulum p point %d" % k, abs(evaluate(P, v) - hp) <= 1e-12 * scale,
              "%r vs %r" % (evaluate(P, v), hp))
        check("pendulum H point %d" % k, abs(evaluate(H, v) - hh) <= 1e-12 * scale,
              "%r vs %r" % (evaluate(H, v), hh))
    check("pendulum E is normalised (y'' coefficient m l^2)", ratio is not None and
          abs(ratio - 1) < 1e-12, repr(ratio))


pendulum_equations(1, 1, 9.81)
pendulum_equations(2, 3, 1.5, "--set", "m=2", "--set", "l=3", "--set", "g=1.5")

# The person's view reads like the textbook.
r = run("equations", os.path.join(problems, "pendulum_angle.scene"))
check("equations text: EL", "th'' + 9.81*sin(th) = 0" in r.stdout, r.stdout)
check("equations text: H", "H = 0.5*th'^2 - 9.81*cos(th)" in r.stdout, r.stdout)
check("equations text: momentum", "p_th = dF/dth' = th'" in r.stdout, r.stdout)

# Cyclic and autonomous flags; expressions with the variable in them still evaluate.
o = run_json("equations", os.path.join(problems, "graded_index_ray.scene"))
check("graded_index_ray cyclic", o.get("cyclic") == ["y"] and o.get("autonomous") is False,
      json.dumps(o))
if "momenta" in o:
    x, yp = 0.3, 0.7
    p = evaluate(to_python(o["momenta"]["y"]), {"x": x, "y": 0.1, "y'": yp})
    check("graded_index_ray momentum", abs(p - math.sqrt(1 + x) * yp / math.sqrt(1 + yp * yp))
          < 1e-14, repr(p))
o = run_json("equations", os.path.join(problems, "sphere_geodesic.scene"))
check("sphere cyclic", o.get("cyclic") == ["ph"] and o.get("autonomous") is True, json.dumps(o))
o = run_json("equations", os.path.join(problems, "pendulum_cartesian.scene"))
check("cartesian pendulum EL carries the multiplier field",
      "lambda_rod" in o.get("euler_lagrange", {}).get("x", ""), json.dumps(o))

# --json FILE writes the file and still prints the summary.
with tempfile.TemporaryDirectory() as tmp:
    out = os.path.join(tmp, "eq.json")
    r = run("equations", os.path.join(problems, "double_pendulum.scene"), "--json", out)
    check("equations --json FILE written", os.path.exists(out))
    check("equations --json FILE summary", "Hamiltonian" in r.stdout, r.stdout)
    # Bad input: nothing written.
    out2 = os.path.join(tmp, "bad.json")
    run("modes", os.path.join(problems, "graded_index_ray.scene"), "--json", out2, expect_rc=2)
    check("modes exit 2 writes nothing", not os.path.exists(out2) and
          os.listdir(tmp) == ["eq.json"], str(os.listdir(tmp)))
    out3 = os.path.join(tmp, "singular.json")
    run("modes", os.path.join(data, "no_kinetic.scene"), "--json", out3, expect_rc=1)
    check("modes exit 1 writes nothing", not os.path.exists(out3), str(os.listdir(tmp)))

# Modes: double pendulum, w^2 = (g/l)(2 -+ sqrt 2).
for sets, l, g in (((), 1.0, 9.81), (("--set", "l=0.7", "--set", "g=3.25"), 0.7, 3.25)):
    o = run_json("modes", os.path.join(problems, "double_pendulum.scene"), *sets)
    check("modes JSON keys", set(o) == {"equilibrium", "modes"}, sorted(o))
    modes = o.get("modes", [])
    check("modes count", len(modes) == 2, json.dumps(o))
    for k, md in enumerate(modes):
        check("mode keys", set(md) == {"omega2", "kind", "shape"} and
              set(md["shape"]) == {"a", "b"}, json.dumps(md))
        w2 = g / l * (2 - math.sqrt(2) if k == 0 else 2 + math.sqrt(2))
        check("double pendulum omega2[%d] l=%g" % (k, l), abs(md["omega2"] - w2) <= 1e-12 * w2,
              "%r vs %r" % (md["omega2"], w2))
        check("double pendulum kind", md["kind"] == "stable", md["kind"])
        a, b = md["shape"]["a"], md["shape"]["b"]
        # Unit M-norm with M = m l^2 [[2, 1], [1, 1]].
        vmv = l * l * (2 * a * a + 2 * a * b + b * b)
        check("double pendulum mode %d unit M-norm" % k, abs(vmv - 1) < 1e-13, repr(vmv))
    check("modes increasing", all(modes[i]["omega2"] <= modes[i + 1]["omega2"]
                                  for i in range(len(modes) - 1)), json.dumps(modes))
    check("equilibrium", o.get("equilibrium") == {"a": 0.0, "b": 0.0}, json.dumps(o))

# The pendulum about the top: unstable, growth rate sqrt(g/l); from th0 = 3 Newton finds pi.
for sets in ((), ("--set", "th0=3")):
    o = run_json("modes", os.path.join(data, "pendulum_top.scene"), *sets)
    md = o.get("modes", [{}])[0]
    check("inverted pendulum unstable", md.get("kind") == "unstable", json.dumps(o))
    check("inverted pendulum growth rate", abs(math.sqrt(-md.get("omega2", 0)) -
                                               math.sqrt(9.81)) < 1e-12 * math.sqrt(9.81),
          json.dumps(o))
    check("inverted pendulum equilibrium", abs(o.get("equilibrium", {}).get("th", 0) - math.pi)
          < 1e-14, json.dumps(o))
r = run("modes", os.path.join(data, "pendulum_top.scene"))
check("modes text: growth rate", "unstable" in r.stdout and "growth rate 3.13209" in r.stdout,
      r.stdout)

# Neutral mode of a free pair.
o = run_json("modes", os.path.join(data, "free_pair.scene"))
kinds = [m["kind"] for m in o.get("modes", [])]
check("free pair kinds", kinds == ["neutral", "stable"], json.dumps(o))
if kinds == ["neutral", "stable"]:
    check("free pair omega2", abs(o["modes"][1]["omega2"] - 6) < 1e-12, json.dumps(o))

# Gyroscopic terms (docs/theory.md (P-12)): the motions of M y'' + G y' + K y = 0, an
# addition to the contract under the key "gyroscopic", absent when G = 0 (checked above).
def gyro(path, *sets):
    o = run_json("modes", path, *sets)
    g = o.get("gyroscopic", {})
    return o, g, [(m["kind"], m["omega"], m["growth"]) for m in g.get("modes", [])]


trap = os.path.join(data, "magnetic_trap.scene")
for k, B in ((3.0, 2.0), (-0.5, 2.0), (0.0, 1.0)):
    o, g, ms = gyro(trap, "--set", "k=%r" % k, "--set", "B=%r" % B)
    check("trap keys", set(o) == {"equilibrium", "modes", "gyroscopic"} and
          set(g) == {"max_abs_G", "modes"}, json.dumps(o))
    check("trap max |G| = B", abs(g.get("max_abs_G", 0) - B) < 1e-15, json.dumps(g))
    r = math.sqrt(k + B * B / 4)
    exact = sorted([abs(r - B / 2), r + B / 2])
    if k == 0.0:  # r - B/2 = 0: a free drift (neutral) and the cyclotron motion
        check("trap k=0 kinds", [m[0] for m in ms] == ["neutral", "stable"], json.dumps(g))
        check("trap k=0 cyclotron omega", len(ms) == 2 and abs(ms[1][1] - B) < 1e-12 * B,
              json.dumps(g))
        continue
    check("trap k=%g kinds" % k, [m[0] for m in ms] == ["stable", "stable"], json.dumps(g))
    for (kind, w, gr), w_ex in zip(ms, exact):
        check("trap k=%g B=%g omega %g" % (k, B, w_ex), abs(w - w_ex) < 1e-12 * (1 + w_ex) and
              gr == 0, json.dumps(g))
    if k < 0:  # K alone says unstable: the field is what confines
        check("trap k<0: K-only modes unstable",
              [m["kind"] for m in o["modes"]] == ["unstable", "unstable"], json.dumps(o))
o, g, ms = gyro(trap, "--set", "k=-2", "--set", "B=2")  # k + B^2/4 = -1: growth 1, omega 1
check("trap unstable: one growing oscillation", len(ms) == 1 and ms[0][0] == "unstable" and
      abs(ms[0][1] - 1) < 1e-12 and abs(ms[0][2] - 1) < 1e-12, json.dumps(g))
r = run("modes", trap)
check("modes text: gyroscopic table", "with the gyroscopic terms" in r.stdout and
      "omega 1, period 6.28319" in r.stdout and "omega 3, period 2.0944" in r.stdout, r.stdout)

# Lagrange point L4: lambda^4 + lambda^2 + 27 mu (1 - mu) / 4 = 0; stable for mu < 0.0385.
l4 = os.path.join(data, "lagrange_l4.scene")
for mu in (0.01, 0.03, 0.05):
    o, g, ms = gyro(l4, "--set", "mu=%r" % mu)
    eq = o.get("equilibrium", {})
    check("L4 equilibrium mu=%g" % mu, abs(eq.get("x", 0) - (0.5 - mu)) < 1e-12 and
          abs(eq.get("y", 0) - math.sqrt(3) / 2) < 1e-12, json.dumps(eq))
    check("L4 K-only modes unstable (a potential maximum)",
          [m["kind"] for m in o.get("modes", [])] == ["unstable", "unstable"], json.dumps(o))
    d = 1 - 27 * mu * (1 - mu)
    if d > 0:
        exact = sorted(math.sqrt((1 + s * math.sqrt(d)) / 2) for s in (-1, 1))
        check("L4 mu=%g stable" % mu, [m[0] for m in ms] == ["stable", "stable"], json.dumps(g))
        for (kind, w, gr), w_ex in zip(ms, exact):
            check("L4 mu=%g omega %.6f" % (mu, w_ex), abs(w - w_ex) < 1e-10, json.dumps(g))
    else:
        lam = __import__("cmath").sqrt((-1 + __import__("cmath").sqrt(d)) / 2)
        lam = complex(abs(lam.real), abs(lam.imag))
        check("L4 mu=%g unstable" % mu, len(ms) == 1 and ms[0][0] == "unstable" and
              abs(ms[0][1] - lam.imag) < 1e-10 and abs(ms[0][2] - lam.real) < 1e-10,
              "%s vs %r" % (json.dumps(g), lam))

# Pointwise constraints (docs/theory.md (P-13)): modes on the constraints' tangent space, the
# multipliers as an addition to the contract. The Cartesian pendulum hangs at (0, -l) with
# lambda = -g/(2l) (tension -2 l lambda = m g) and omega^2 = g/l; the Cartesian double
# pendulum has the angle form's omega^2 = (g/l)(2 -+ sqrt 2) and tensions 2mg and mg.
o = run_json("modes", os.path.join(problems, "pendulum_cartesian.scene"))
check("Cartesian pendulum keys", set(o) == {"equilibrium", "modes", "multipliers"}, sorted(o))
ms = o.get("modes", [])
check("Cartesian pendulum: one mode, omega2 = g/l", len(ms) == 1 and
      abs(ms[0]["omega2"] - 9.81) < 1e-12 * 9.81 and ms[0]["kind"] == "stable", json.dumps(o))
check("Cartesian pendulum: tension m g", abs(-2 * o.get("multipliers", {}).get("rod", 0) - 9.81)
      < 1e-12 * 9.81, json.dumps(o))
dpc = os.path.join(data, "double_pendulum_cartesian.scene")
for sets, l, g in (((), 1.0, 9.81), (("--set", "l=0.7", "--set", "g=3.25"), 0.7, 3.25)):
    o = run_json("modes", dpc, *sets)
    ms = o.get("modes", [])
    check("Cartesian double pendulum: 2 modes", len(ms) == 2, json.dumps(o))
    for k, md in enumerate(ms[:2]):
        w2 = g / l * (2 - math.sqrt(2) if k == 0 else 2 + math.sqrt(2))
        check("Cartesian double pendulum omega2[%d] l=%g" % (k, l),
              abs(md["omega2"] - w2) <= 1e-12 * w2, "%r vs %r" % (md["omega2"], w2))
        v = md["shape"]
        vmv = sum(v[c] ** 2 for c in ("x1", "y1", "x2", "y2"))  # M = I
        check("Cartesian double pendulum unit M-norm", abs(vmv - 1) < 1e-13, repr(vmv))
        # the angle form's shape (a, b) = (x1 / l, (x2 - x1) / l) up to scale: b/a = +-sqrt 2
        a, b = v["x1"] / l, (v["x2"] - v["x1"]) / l
        check("Cartesian double pendulum shape ratio", abs(b / a - (math.sqrt(2) if k == 0
              else -math.sqrt(2))) < 1e-10, json.dumps(v))
    mu = o.get("multipliers", {})
    check("Cartesian double pendulum tensions 2mg, mg",
          abs(-2 * l * mu.get("rod1", 0) - 2 * g) < 1e-12 * g and
          abs(-2 * l * mu.get("rod2", 0) - g) < 1e-12 * g, json.dumps(mu))
r = run("modes", dpc)
check("modes text: constrained", "2 modes on the constraints' tangent space" in r.stdout and
      "lambda_rod1 = -9.81" in r.stdout, r.stdout)

# Bad inputs: clear messages.
r = run("modes", os.path.join(problems, "graded_index_ray.scene"), expect_rc=2)
check("modes explicit variable message", "graded_index_ray.scene:8: the integrand depends "
      "explicitly on x" in r.stderr, r.stderr)
r = run("modes", os.path.join(data, "no_kinetic.scene"), expect_rc=1)
check("modes M singular message", "not positive definite" in r.stderr, r.stderr)
r = run("modes", os.path.join(problems, "catenary.scene"), expect_rc=1)
check("modes no equilibrium message", "no equilibrium" in r.stderr, r.stderr)
r = run("modes", os.path.join(problems, "hanging_chain.scene"), expect_rc=2)
check("modes integral constraints message", "does not handle integral constraints" in r.stderr,
      r.stderr)
run("modes", os.path.join(problems, "double_pendulum.scene"), "--elements", "3", expect_rc=2)
run("equations", os.path.join(problems, "double_pendulum.scene"), "--csv", "-", expect_rc=2)
run("equations", os.path.join(data, "missing.scene"), expect_rc=2)
run("equations", expect_rc=2)

# check: degrees of freedom, derivative needs, the finite-difference check.
r = run("check", os.path.join(problems, "pendulum_cartesian.scene"))
check("check freedom", "2 unknown functions - 1 pointwise constraint = 1 degree of freedom"
      in r.stdout, r.stdout)
check("check derivatives", "agree with finite differences" in r.stdout, r.stdout)
check("check needs", "second partials" in r.stdout, r.stdout)

print("%d checks, %d failures" % (checks, failures))
sys.exit(1 if failures else 0)

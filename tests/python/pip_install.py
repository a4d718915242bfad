#!/usr/bin/env python3
"""tests/python/pip_install.py — `pip install .` into a fresh virtual environment, offline,
then the three-line catenary there; and, when python3-build is present, the wheel of
`python -m build --wheel --no-isolation` installed into a second environment.

usage: pip_install.py SOURCE_DIR [wheel]
The commands are those of docs/python.md ("Installing"): a venv with
--system-site-packages (numpy and meson-python from Debian; PyPI is not reachable) and
pip's --no-build-isolation. The environment of the test (CALCVAR_LIB, PYTHONPATH,
LD_PRELOAD of a sanitized build) is removed, so the module and the library must come
from the venv. Exit 77 (skipped) without meson-python or python3-build.
SPDX-License-Identifier: MIT
"""
import glob
import os
import subprocess
import sys
import tempfile

CATENARY = r'''
import calcvar
p = calcvar.Problem("y*sqrt(1 + y'^2)", (-1, 1), {"y": ("2*cosh(1/2)", "2*cosh(1/2)")})
sol = p.solve(elements=16, degree=4)
print(sol.status, sol.action)
import math, os, sys
exact = 2 + 2 * math.sinh(1)   # c (1 + (c/2) sinh(2/c)), c = 2
assert sol.status == "converged" and abs(sol.action - exact) < 1e-9, (sol.action, exact)
assert abs(sol(0.5)[0] - 2 * math.cosh(0.25)) < 1e-9
assert sol.curve_error["curve"] < 1e-8          # a module imported on first use
lib = calcvar._lib.lib._name
assert lib.startswith(sys.prefix), "the library %s is not the environment's" % lib
from importlib import metadata
assert metadata.version("calcvar") == calcvar.__version__, metadata.version("calcvar")
print("calcvar", calcvar.__version__, "from", os.path.dirname(calcvar.__file__), "library", lib)
'''


def run(cmd, **kw):
    print("+", " ".join(cmd), flush=True)
    r = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if r.returncode != 0:
        print(r.stdout[-4000:], r.stderr[-4000:])
        sys.exit("FAIL: %s exited %d" % (cmd[0], r.returncode))
    return r.stdout


def venv(tmp, name, env):
    d = os.path.join(tmp, name)
    run([sys.executable, "-m", "venv", "--system-site-packages", d], env=env)
    return os.path.join(d, "bin", "python")


def check(python, env, tmp, src):
    out = run([python, "-c", CATENARY], env=env, cwd=tmp)  # not the source tree
    # every file of the source package is installed (python/meson.build lists them)
    pkg = run([python, "-c", "import calcvar, os; print(os.path.dirname(calcvar.__file__))"],
              env=env, cwd=tmp).strip()
    want = {f for f in os.listdir(os.path.join(src, "python", "calcvar"))
            if not f.endswith(".in") and f != "__pycache__"}
    missing = want - set(os.listdir(pkg))
    assert not missing, "not installed: %s" % sorted(missing)
    print(out, end="")
    exe = os.path.join(os.path.dirname(python), "calcvar")
    print(run([exe, "--version"], env=env).splitlines()[0])


def main():
    src = os.path.abspath(sys.argv[1])
    wheel = len(sys.argv) > 2 and sys.argv[2] == "wheel"
    need = "build" if wheel else "mesonpy"
    if subprocess.run([sys.executable, "-c", "import mesonpy, " + need]).returncode != 0:
        print("SKIP: python3-mesonpy%s not installed (scripts/deps.sh)"
              % (" or python3-build" if wheel else ""))
        return 77
    env = {k: v for k, v in os.environ.items()
           if k not in ("CALCVAR_LIB", "PYTHONPATH", "LD_PRELOAD", "ASAN_OPTIONS",
                        "UBSAN_OPTIONS", "VIRTUAL_ENV", "PYTHONHOME")}
    env["PIP_NO_INDEX"] = "1"  # offline: nothing may come from PyPI
    with tempfile.TemporaryDirectory(prefix="calcvar-pip-") as tmp:
        py = venv(tmp, "env", env)
        if not wheel:
            run([py, "-m", "pip", "install", "--no-cache-dir", "--no-build-isolation",
                 "--config-settings=compile-args=-j2", src], env=env, cwd=tmp)
        else:
            dist = os.path.join(tmp, "dist")
            run([sys.executable, "-m", "build", "--wheel", "--no-isolation",
                 "--skip-dependency-check", "--config-setting=compile-args=-j2",
                 "--outdir", dist, src], env=env, cwd=tmp)
            whl = glob.glob(os.path.join(dist, "calcvar-*.whl"))
            assert len(whl) == 1, whl
            print("wheel:", os.path.basename(whl[0]))
            run([py, "-m", "pip", "install", "--no-cache-dir", "--no-deps", whl[0]], env=env,
                cwd=tmp)
        check(py, env, tmp, src)
    print("PASS")
    return 0


if __name__ == "__main__":
    sys.exit(main())

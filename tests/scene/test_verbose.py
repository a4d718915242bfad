#!/usr/bin/env python3
"""tests/scene/test_verbose.py — `solve --verbose` / `-v`, `-V`/`--version`, `-h`.

usage: test_verbose.py CALCVAR SCENES_DIR
--verbose: exactly one stderr line per Newton iteration (the JSON's `iterations`), numbered
1..k, the residual of the last below the first; with --adapt one `round` line per round,
the last estimate at most the target. -V: the linked libraries by name.
SPDX-License-Identifier: MIT
"""
import json
import os
import re
import subprocess
import sys

exe, scenes = sys.argv[1], sys.argv[2]
failures = checks = 0


def check(what, ok, detail=""):
    global failures, checks
    checks += 1
    if not ok:
        failures += 1
        print("FAIL %s %s" % (what, detail))


cat = os.path.join(scenes, "catenary.scene")
for flag in ("--verbose", "-v"):
    r = subprocess.run([exe, "solve", cat, "--elements", "8", "--degree", "2", flag,
                        "--json", "-"], capture_output=True, text=True)
    check(flag + " exit 0", r.returncode == 0, r.stderr)
    its = json.loads(r.stdout)["iterations"] if r.returncode == 0 else -1
    lines = re.findall(r"iteration (\d+): residual ([0-9.e+-]+), step ([0-9.e+-]+), "
                       r"line search ([0-9.e+-]+)", r.stderr)
    check(flag + ": one line per iteration", [int(k) for k, *_ in lines] ==
          list(range(1, its + 1)), r.stderr)
    if lines:
        check(flag + ": residual falls", float(lines[-1][1]) < float(lines[0][1]), r.stderr)
        check(flag + ": last step within the tolerance", float(lines[-1][2]) <= 1, r.stderr)

r = subprocess.run([exe, "solve", cat, "--elements", "4", "--degree", "2", "--adapt", "1e-8",
                    "-v", "--quiet"], capture_output=True, text=True)
rounds = re.findall(r"round (\d+): (\d+) elements, estimated max nodal error ([0-9.e+-]+)",
                    r.stderr)
check("adapt: round lines", len(rounds) >= 2 and float(rounds[-1][2]) <= 1e-8, r.stderr)
check("adapt: elements grow", [int(e) for _, e, _ in rounds] ==
      sorted(int(e) for _, e, _ in rounds), r.stderr)

r = subprocess.run([exe, "solve", cat, "--quiet"], capture_output=True, text=True)
check("no --verbose, not a terminal: stderr silent", r.returncode == 0 and r.stderr == "",
      r.stderr)
r = subprocess.run([exe, "equations", cat, "-v"], capture_output=True, text=True)
check("equations refuses -v", r.returncode == 2, r.stderr)
r = subprocess.run([exe, "batch", cat, os.devnull, "-v", "--threads", "1"],
                   capture_output=True, text=True)
check("batch refuses -v with a sentence", r.returncode == 2 and "--verbose" in r.stderr,
      r.stderr)

for flag in ("-V", "--version"):
    r = subprocess.run([exe, flag], capture_output=True, text=True)
    check(flag, r.returncode == 0 and r.stdout.startswith("calcvar ") and
          all(w in r.stdout for w in ("CHOLMOD", "NLopt", "LAPACK", "jansson", "PLplot")),
          r.stdout)
r = subprocess.run([exe, "-h"], capture_output=True, text=True)
check("-h", r.returncode == 0 and "usage" in r.stdout, r.stdout)

print("%d passed, %d failed" % (checks - failures, failures))
sys.exit(1 if failures else 0)

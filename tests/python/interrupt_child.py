#!/usr/bin/env python3
"""tests/python/interrupt_child.py — a long solve for test_safety.py to interrupt.

usage: interrupt_child.py plain|progress|all
Bratu's problem beyond its fold (lambda = 4: no stationary path), 20000 elements of
degree 4: Newton fails, and continuation tries for about half a minute, one progress call
per Newton step. all: the search for every stationary path of the double pendulum on 3000
elements of degree 4 (about 15 s; the deflated steps and the polishing solves between
them must see the interrupt too). Prints "ready" when the solve starts; on Ctrl-C prints "interrupted T
LIVE STEPS" (T: time.time() when KeyboardInterrupt arrived, LIVE: handle triples not
freed, STEPS: Newton steps reported to the progress function, -1 without one).
SPDX-License-Identifier: MIT
"""
import gc
import os
import sys
import time

import calcvar
from calcvar._solution import Handles

BRATU4 = """[scene]
interval = 0, 1
unknowns = y
integrand = y'^2/2 - 4*exp(y)
[boundary]
y = 0, 0
"""
steps = []
progress = (lambda d: steps.append(d["iteration"])) if sys.argv[1] == "progress" else None
print("ready", flush=True)
try:
    if sys.argv[1] == "all":
        scenes = os.environ.get("CALCVAR_SCENES", os.path.join(os.path.dirname(
            os.path.abspath(__file__)), "..", "scene", "data"))
        sol = calcvar.solve(os.path.join(scenes, "double_pendulum.scene"), all=True,
                            work=1e4, max_paths=100, elements=3000, degree=4)
    else:
        sol = calcvar.solve(BRATU4, elements=20000, degree=4, max_iterations=100000,
                            progress=progress)
    print("not interrupted:", getattr(sol, "status", len(sol)), flush=True)
    sys.exit(3)
except KeyboardInterrupt:
    t = time.time()
    gc.collect()
    print("interrupted %.6f %d %d" % (t, Handles.live(), len(steps) if progress else -1),
          flush=True)

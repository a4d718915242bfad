#!/usr/bin/env python3
"""bench/bench_python.py — what calcvar.solve adds to the same C calls (target <= 20 us).

usage: CALCVAR_LIB=build/libcalcvar.so PYTHONPATH=python \\
       flock /tmp/calcvar-build.lock /usr/bin/python3 bench/bench_python.py \\
       build/bench/bench_scene_api [SCENE]
Both sides solve the same scene on the same small mesh (so that the overhead is not
hidden in a long solve) and copy nodes and values out; each side is the best of 5 rounds,
the C baseline (bench_scene_api) measured in the same run. Timings on a shared machine
are noisy: compare the difference, run it twice.
SPDX-License-Identifier: MIT
"""
import os
import subprocess
import sys
import time

import calcvar

exe = sys.argv[1]
root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
scene = sys.argv[2] if len(sys.argv) > 2 else os.path.join(root, "tests", "scene", "data",
                                                           "catenary.scene")
for elements, degree in [(4, 1), (32, 4)]:
    reps = 2000
    line = subprocess.run([exe, scene, str(elements), str(degree), str(reps)], check=True,
                          capture_output=True, text=True).stdout
    c_us = float(line.split()[1])
    best = 1e30
    for _ in range(5):
        t0 = time.perf_counter()
        for _ in range(reps):
            sol = calcvar.solve(scene, elements=elements, degree=degree)
        best = min(best, (time.perf_counter() - t0) / reps)
    assert sol.success
    py_us = 1e6 * best
    print("%3d elements of degree %d: C %.2f us, calcvar.solve %.2f us, overhead %.2f us "
          "per call (x%.2f) %s" % (elements, degree, c_us, py_us, py_us - c_us, py_us / c_us,
                                   "<= 20 us" if py_us - c_us <= 20 else "ABOVE 20 us"))

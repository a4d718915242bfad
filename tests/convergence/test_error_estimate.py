#!/usr/bin/env python3
# tests/convergence/test_error_estimate.py — `error_estimate` (a scene without [exact])
# within a factor 3 of the true max nodal error, on catenary, fisheye_ray, harmonic_saddle,
# boundary_layer (eps = 1e-2) and sphere_geodesic, three meshes per degree 1, 2, 4 (issue 6).
# SPDX-License-Identifier: MIT
#
# usage: test_error_estimate.py CALCVAR EXACT_DIR NOEXACT_DIR
# The true error is the report's error.max_nodal for the same scene with its [exact]
# (tests/scene/data); the estimate comes from the copy without it (tests/convergence/data).
# A true error below 1e-12 is round-off, where no estimate can be within a factor: skipped
# (none of the meshes below comes that close except where printed).
import json
import os
import subprocess
import sys

calcvar, exact_dir, noexact_dir = [os.path.abspath(a) for a in sys.argv[1:4]]
failures = checked = 0
MESHES = {1: [8, 32, 128], 2: [4, 16, 64], 4: [2, 4, 8]}


def fail(what, expected, actual):
    global failures
    failures += 1
    print("FAIL %s\n  expected: %s\n  actual:   %s" % (what, expected, actual))


def solve(scene, E, p):
    r = subprocess.run([calcvar, "solve", scene, "--elements", str(E), "--degree", str(p),
                        "--json", "-"], capture_output=True, text=True, timeout=120)
    if r.returncode != 0:
        fail("%s E=%d p=%d exit" % (scene, E, p), 0, "%d: %s" % (r.returncode, r.stderr))
        return None
    return json.loads(r.stdout)


for name in ["catenary", "fisheye_ray", "harmonic_saddle", "boundary_layer",
             "sphere_geodesic"]:
    for p, meshes in MESHES.items():
        for E in meshes:
            a = solve(os.path.join(exact_dir, name + ".scene"), E, p)
            b = solve(os.path.join(noexact_dir, name + "_noexact.scene"), E, p)
            if a is None or b is None:
                continue
            if "error_estimate" in a:
                fail("%s E=%d p=%d: with [exact]" % (name, E, p), "no error_estimate",
                     a["error_estimate"])
            if "error" in b:
                fail("%s E=%d p=%d: without [exact]" % (name, E, p), "no error", b["error"])
            true, est = a["error"]["max_nodal"], b.get("error_estimate")
            print("%-16s p=%d E=%4d  true %.3e  estimate %s  ratio %s" %
                  (name, p, E, true, "%.3e" % est if est else None,
                   "%.3f" % (est / true) if est and true > 0 else "-"))
            if true < 1e-12:
                print("  (round-off: not judged)")
                continue
            checked += 1
            if est is None or not (true / 3 <= est <= 3 * true):
                fail("%s E=%d p=%d estimate" % (name, E, p), "within 3x of %.3e" % true, est)

print("%d estimates checked, %d failures" % (checked, failures))
sys.exit(1 if failures or checked < 40 else 0)

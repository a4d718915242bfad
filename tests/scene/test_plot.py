#!/usr/bin/env python3
"""tests/scene/test_plot.py — `solve --plot`: the path view and its layout, [plot] errors.

usage: test_plot.py CALCVAR EXAMPLE_SCENES_DIR
The picture's size (read from the PNG header) tells the layout: 1500 wide with the path
beside the components, 960 wide stacked; the file must be a sane PNG (20 kB .. 5 MB).
SPDX-License-Identifier: MIT
"""
import os
import struct
import subprocess
import sys
import tempfile

exe, scenes = sys.argv[1], sys.argv[2]
failures = checks = 0


def check(what, ok, detail=""):
    global failures, checks
    checks += 1
    if not ok:
        failures += 1
        print("FAIL %s %s" % (what, detail))


def png_size(path):
    with open(path, "rb") as f:
        head = f.read(24)
    if head[:8] != b"\x89PNG\r\n\x1a\n":
        return None
    return struct.unpack(">II", head[16:24])


with tempfile.TemporaryDirectory() as tmp:
    # name: (width, height) of the layout
    for name, size in [("kepler", (1500, 640)),          # path + components
                       ("sphere_geodesic", (1500, 920)),  # path + components + errors
                       ("brachistochrone", (960, 560)),   # the path replaces the graph
                       ("catenary", (960, 1020))]:        # graph + errors, no path
        out = os.path.join(tmp, name + ".png")
        r = subprocess.run([exe, "solve", os.path.join(scenes, name + ".scene"), "--quiet",
                            "--plot", out], capture_output=True, text=True)
        check(name + " exit 0", r.returncode == 0, r.stderr)
        ok = os.path.exists(out)
        check(name + " picture made", ok)
        if ok:
            n = os.path.getsize(out)
            check(name + " size sane", 20000 <= n <= 5000000, str(n))
            check(name + " layout", png_size(out) == size, "%s != %s" % (png_size(out), size))

    bad = os.path.join(tmp, "bad.scene")
    base = "[scene]\ninterval = 0, 1\nunknowns = y\nintegrand = y'^2\n[boundary]\ny = 0, 1\n"
    for plot, where, words in [("[plot]\npath = x, z\n", 8, "neither"),
                               ("[plot]\npath = y\n", 8, "two names"),
                               ("[plot]\npath = y, y\n", 8, "against itself"),
                               ("[plot]\ncolour = red\n", 8, "unknown key")]:
        with open(bad, "w") as f:
            f.write(base + plot)
        out = os.path.join(tmp, "bad.png")
        r = subprocess.run([exe, "solve", bad, "--quiet", "--plot", out],
                           capture_output=True, text=True)
        check(plot.split("\n")[1] + " refused", r.returncode == 2 and
              ("%s:%d:" % (bad, where)) in r.stderr and words in r.stderr, r.stderr)
        check(plot.split("\n")[1] + " nothing written", not os.path.exists(out))

print("%d passed, %d failed" % (checks - failures, failures))
sys.exit(1 if failures else 0)

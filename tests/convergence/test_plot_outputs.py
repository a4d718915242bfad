#!/usr/bin/env python3
# tests/convergence/test_plot_outputs.py — `converge --svg` and `solve --plot`: well-formed
# pictures with labelled axes and a legend; bad input to converge and --plot: exit 2, a
# sentence naming the problem, nothing written.
# SPDX-License-Identifier: MIT
#
# usage: test_plot_outputs.py CALCVAR DATA_DIR
import os
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

calcvar, data_dir = [os.path.abspath(a) for a in sys.argv[1:3]]
failures = checked = 0
SVG = "{http://www.w3.org/2000/svg}"


def fail(what, expected, actual):
    global failures
    failures += 1
    print("FAIL %s\n  expected: %s\n  actual:   %s" % (what, expected, actual))


def run(args, cwd):
    r = subprocess.run([calcvar] + args, cwd=cwd, capture_output=True, text=True, timeout=300)
    if "Sanitizer" in r.stderr or "runtime error:" in r.stderr:
        fail("calcvar " + " ".join(args) + " sanitizer", "no finding", r.stderr[:2000])
    return r


def svg_texts(path, what):
    """The text of every <text> element; fails unless the file is well-formed SVG."""
    with open(path, "rb") as f:
        head = f.read(64)
    if not (head.startswith(b"<?xml") or head.startswith(b"<svg")):
        fail(what + " header", "<?xml or <svg", head[:20])
        return []
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as e:
        fail(what + " well-formed", "parses as XML", str(e))
        return []
    if root.tag != SVG + "svg":
        fail(what + " root", "svg", root.tag)
    return ["".join(t.itertext()) for t in root.iter(SVG + "text")]


def expect_texts(texts, wanted, what):
    global checked
    for w in wanted:
        checked += 1
        if not any(w in t for t in texts):
            fail(what + " text", w, texts[:40])


cat = os.path.join(data_dir, "catenary.scene")
pend = os.path.join(data_dir, "pendulum_cartesian.scene")
with tempfile.TemporaryDirectory() as tmp:
    # converge --svg: axes, title, one legend entry per degree
    svg = os.path.join(tmp, "wp.svg")
    r = run(["converge", cat, "--elements", "2", "--levels", "3", "--degree", "1,2,4",
             "--svg", svg, "--quiet"], tmp)
    checked += 1
    if r.returncode != 0 or not os.path.getsize(svg):
        fail("converge --svg", "exit 0 and a file", "%d %s" % (r.returncode, r.stderr))
    else:
        expect_texts(svg_texts(svg, "converge --svg"),
                     ["run time", "max nodal error", "Catenary", "degree p = 1",
                      "degree p = 2", "degree p = 4"], "converge --svg")
    # solve --plot .svg: the unknown and the variable; with constraints, the multiplier
    for scene, wanted in [(cat, ["y(x)", "Catenary", "y exact"]),
                          (pend, ["x(t)", "y(t)", "lambda_rod(t)", "multiplier"])]:
        out = os.path.join(tmp, os.path.basename(scene) + ".svg")
        r = run(["solve", scene, "--plot", out, "--quiet"], tmp)
        checked += 1
        if r.returncode != 0 or not os.path.exists(out) or not os.path.getsize(out):
            fail("solve --plot " + scene, "exit 0 and a file", "%d %s" % (r.returncode,
                                                                         r.stderr))
            continue
        expect_texts(svg_texts(out, "solve --plot"), wanted, "solve --plot " + scene)
    # solve --plot .png: a PNG signature and more than a header
    png = os.path.join(tmp, "cat.png")
    r = run(["solve", cat, "--plot", png, "--quiet"], tmp)
    checked += 1
    if r.returncode != 0 or not os.path.exists(png):
        fail("solve --plot png", "exit 0 and a file", "%d %s" % (r.returncode, r.stderr))
    else:
        with open(png, "rb") as f:
            data = f.read()
        if not data.startswith(b"\x89PNG\r\n\x1a\n") or len(data) < 2000:
            fail("solve --plot png", "a PNG image", data[:16])
    leftovers = [f for f in os.listdir(tmp) if ".tmp." in f]
    if leftovers:
        fail("temporary files", "none left", leftovers)

    # bad input: exit 2, the reason on stderr, nothing written
    nodir = os.path.join(tmp, "no_dir")
    cases = [
        (["converge", cat, "--levels", "0"], "--levels"),
        (["converge", cat, "--levels", "25"], "--levels"),
        (["converge", cat, "--levels", "two"], "--levels"),
        (["converge", cat, "--levels"], "--levels needs a value"),
        (["converge", cat, "--degree", "1,9"], "--degree"),
        (["converge", cat, "--degree", "1,,2"], "--degree"),
        (["converge", cat, "--degree", "2,2"], "--degree"),
        (["converge", cat, "--degree", "0"], "--degree"),
        (["converge", cat, "--degree", ""], "--degree"),
        (["converge", cat, "--svg", os.path.join(nodir, "x.svg")], "cannot write"),
        (["converge", cat, "--svg", "x.png"], ".svg"),
        (["converge", cat, "--csv", "x.csv"], "not of converge"),
        (["converge", cat, "--plot", "x.png"], "not of converge"),
        (["converge", cat, "--elements", "1000000", "--levels", "24"], "too many"),
        (["converge"], "scene file is missing"),
        (["converge", cat, "--bogus"], "unknown option"),
        (["solve", cat, "--plot", os.path.join(nodir, "x.svg")], "cannot write"),
        (["solve", cat, "--plot", "x.pdf"], ".png or .svg"),
    ]
    for args, expect in cases:
        before = set(os.listdir(tmp))
        r = run(args, tmp)
        checked += 1
        what = "calcvar " + " ".join(a.replace(tmp, "TMP") for a in args)
        if r.returncode != 2:
            fail(what + " exit status", 2, "%d (stderr: %s)" % (r.returncode, r.stderr.strip()))
        elif expect not in r.stderr:
            fail(what + " message", "... " + expect + " ...", r.stderr.strip())
        if r.stdout:
            fail(what + " stdout", "(nothing)", r.stdout.strip()[:200])
        if set(os.listdir(tmp)) != before:
            fail(what + " files", "nothing written", sorted(set(os.listdir(tmp)) - before))

print("%d checks, %d failures" % (checked, failures))
sys.exit(1 if failures else 0)

#!/usr/bin/env python3
# examples/test_scenes.py — solve every examples/scenes/*.scene with `calcvar solve --json -`
# and check it converged and met the bounds its header states in `# expect:` lines.
# SPDX-License-Identifier: MIT
#
# usage: test_scenes.py CALCVAR SCENE_DIR
# An expect line is either  `# expect: PATH < BOUND`  (the JSON value at PATH, dotted keys,
# is below BOUND) or  `# expect: PATH = VALUE +- TOL`  (|value - VALUE| <= TOL).
# A scene with an [exact] section must state at least one bound on `error.*`.
import glob
import json
import os
import re
import subprocess
import sys

EXPECT = re.compile(r"^#\s*expect:\s*([\w.]+)\s*(?:<\s*(\S+)|=\s*(\S+)\s*\+-\s*(\S+))\s*$")


def lookup(report, path):
    node = report
    for key in path.split("."):
        if not isinstance(node, dict) or key not in node:
            return None
        node = node[key]
    return node


def check(calcvar, scene):
    text = open(scene).read()
    expects = [EXPECT.match(line) for line in text.splitlines() if "expect:" in line]
    if not expects or not all(expects):
        return ["malformed or missing '# expect:' lines"]
    if "\n[exact]" in text and not any(m.group(1).startswith("error.") for m in expects):
        return ["has [exact] but states no bound on error.*"]
    run = subprocess.run([calcvar, "solve", scene, "--json", "-"], capture_output=True,
                         text=True, timeout=120)
    if run.returncode != 0:
        return ["exit status %d, expected 0: %s" % (run.returncode, run.stderr.strip())]
    report = json.loads(run.stdout)
    fails = []
    if report.get("status") != "converged":
        fails.append("status %s, expected converged" % report.get("status"))
    for m in expects:
        path, bound, value, tol = m.groups()
        got = lookup(report, path)
        if not isinstance(got, (int, float)):
            fails.append("%s missing from the report" % path)
        elif bound is not None:
            ok = got < float(bound)
            print("  %-22s %-24.17g < %s %s" % (path, got, bound, "ok" if ok else "FAIL"))
            if not ok:
                fails.append("%s = %.17g, expected < %s" % (path, got, bound))
        else:
            ok = abs(got - float(value)) <= float(tol)
            print("  %-22s %-24.17g = %s +- %s %s" % (path, got, value, tol,
                                                    "ok" if ok else "FAIL"))
            if not ok:
                fails.append("%s = %.17g, expected %s +- %s" % (path, got, value, tol))
    return fails


def main():
    calcvar, folder = sys.argv[1], sys.argv[2]
    scenes = sorted(glob.glob(os.path.join(folder, "*.scene")))
    if len(scenes) < 8:
        print("FAIL: %d scenes in %s, expected at least 8" % (len(scenes), folder))
        return 1
    failed = 0
    for scene in scenes:
        print(os.path.basename(scene))
        fails = check(calcvar, scene)
        for f in fails:
            print("FAIL %s: %s" % (os.path.basename(scene), f))
        failed += bool(fails)
    print("%d scenes, %d failed" % (len(scenes), failed))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())

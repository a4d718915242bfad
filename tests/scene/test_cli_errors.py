#!/usr/bin/env python3
# tests/scene/test_cli_errors.py — malformed scenes and bad flags: exit 2, "FILE:LINE:" on
# stderr pointing at the right line, no crash, and no output file left behind.
# SPDX-License-Identifier: MIT
#
# usage: test_cli_errors.py CALCVAR BAD_DIR DATA_DIR
# Each BAD_DIR/*.scene starts with "# expect: SUBSTRING"; the line carrying the marker
# "# <-" is the line the message must name (comments are part of the format, so the marker
# does not change what the loader sees).
import os
import subprocess
import sys
import tempfile

calcvar, bad_dir, data_dir = [os.path.abspath(a) for a in sys.argv[1:4]]
failures = 0
checked = 0


def fail(what, expected, actual):
    global failures
    failures += 1
    print("FAIL %s\n  expected: %s\n  actual:   %s" % (what, expected, actual))


def run(args, cwd):
    r = subprocess.run([calcvar] + args, cwd=cwd, capture_output=True, text=True,
                       timeout=120)
    # Under -Db_sanitize=address,undefined a finding must fail the test, whatever the exit.
    if "Sanitizer" in r.stderr or "runtime error:" in r.stderr:
        fail("calcvar " + " ".join(args) + " sanitizer", "no finding", r.stderr[:2000])
    return r


with tempfile.TemporaryDirectory() as tmp:
    for name in sorted(os.listdir(bad_dir)):
        if not name.endswith(".scene"):
            continue
        path = os.path.join(bad_dir, name)
        with open(path) as f:
            lines = f.read().split("\n")
        expect = lines[0].split("# expect:", 1)[1].split("# <-")[0].strip()
        line = next(i + 1 for i, l in enumerate(lines) if "# <-" in l)
        out = os.path.join(tmp, name + ".json")
        csv = os.path.join(tmp, name + ".csv")
        r = run(["solve", path, "--json", out, "--csv", csv], tmp)
        checked += 1
        prefix = "%s:%d: " % (path, line)
        if r.returncode != 2:
            fail(name + " exit status", 2, "%d (stderr: %s)" % (r.returncode, r.stderr.strip()))
        elif not r.stderr.startswith(prefix):
            fail(name + " location", prefix + "...", r.stderr.strip())
        elif expect not in r.stderr:
            fail(name + " message", "... " + expect + " ...", r.stderr.strip())
        if r.stdout:
            fail(name + " stdout", "(nothing)", r.stdout.strip())
        left = [f for f in os.listdir(tmp) if f.startswith(name)]
        if left:
            fail(name + " output files", "none written", left)

    # Bad flags: exit 2, a sentence naming the problem, nothing written.
    cat = os.path.join(data_dir, "catenary.scene")
    flag_cases = [
        (["solve", cat, "--elements", "0"], "--elements"),
        (["solve", cat, "--elements", "abc"], "--elements"),
        (["solve", cat, "--elements=-3"], "--elements"),
        (["solve", cat, "--degree", "9"], "--degree"),
        (["solve", cat, "--degree"], "needs a value"),
        (["solve", cat, "--method", "gradient"], "unknown method"),
        (["solve", os.path.join(data_dir, "hanging_chain.scene"), "--method", "lbfgs"],
         "cannot impose constraints"),
        (["solve", cat, "--method", "lbfgs"], None),  # a valid engine: must not be exit 2
        (["solve", cat, "--tolerance", "0"], "--tolerance"),
        (["solve", cat, "--tolerance", "nan"], "--tolerance"),
        (["solve", cat, "--max-iterations", "-1"], "--max-iterations"),
        (["solve", cat, "--set", "c"], "--set needs name=value"),
        (["solve", cat, "--set", "nosuch=1"], "not a parameter"),
        (["solve", cat, "--set", "c=abc"], "unknown name 'abc'"),
        (["solve", cat, "--set", "c=1/0"], "not a finite number"),
        (["solve", cat, "--set", "c=0.1"], None),  # a valid override: must not be exit 2
        (["solve", cat, "--adapt", "1e-8"], None),  # valid: must not be exit 2
        (["solve", cat, "--adapt", "1e-8", "--continue", "c=1.6:2"], "cannot be combined"),
        (["solve", cat, "--continue", "nosuch=1:2"], "not a parameter"),
        (["solve", cat, "--adapt", "-1"], "--adapt"),
        (["solve", cat, "--continue", "c=1.6:2"], None),  # valid: must not be exit 2
        (["solve", cat, "--continue", "c=1"], "name=from:to"),
        (["solve", cat, "--plot", os.path.join(tmp, "no_dir", "x.png")], "cannot write"),
        (["solve", cat, "--plot", "out.jpg"], ".png or .svg"),
        (["solve", cat, "--json", "-", "--csv", "-"], "stdout"),
        (["solve", cat, "--bogus"], "unknown option"),
        (["solve", cat, "--quiet=1"], "takes no value"),
        (["solve"], "scene file is missing"),
        (["solve", cat, cat], "one scene file only"),
        (["solve", os.path.join(tmp, "no_such.scene")], "cannot open"),
        (["solve", cat, "--json", os.path.join(tmp, "no_dir", "x.json")], "cannot write"),
        (["frobnicate"], "unknown command"),
        (["converge", cat, "--levels", "0"], "--levels"),
        (["equations", cat, "--csv", "-"], "only --set, --json and --quiet apply"),
        (["modes", cat, "--degree", "2"], "only --set, --json and --quiet apply"),
    ]
    for args, expect in flag_cases:
        before = set(os.listdir(tmp))
        r = run(args, tmp)
        checked += 1
        what = "calcvar " + " ".join(a.replace(tmp, "TMP") for a in args)
        if expect is None:
            # Not bad input (a valid override or engine). It must not be exit 2.
            if r.returncode == 2:
                fail(what, "exit 0 or 1 (a valid --set)", "2: " + r.stderr.strip())
            continue
        if r.returncode != 2:
            fail(what + " exit status", 2, "%d (stderr: %s)" % (r.returncode, r.stderr.strip()))
        elif expect not in r.stderr:
            fail(what + " message", "... " + expect + " ...", r.stderr.strip())
        if set(os.listdir(tmp)) != before:
            fail(what + " files", "nothing written", sorted(set(os.listdir(tmp)) - before))

print("%d cases checked, %d failures" % (checked, failures))
sys.exit(1 if failures else 0)

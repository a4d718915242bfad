#!/usr/bin/env python3
# tests/robust/test_cli_minor.py — the minor faults of issue 27: messages with a line and
# without internal words, a non-UTF-8 title, a 250-character output name, batch --help,
# and the catenary's exact action as a formula of c.
# SPDX-License-Identifier: MIT
#
# usage: test_cli_minor.py CALCVAR EXAMPLES_DIR
import json
import os
import subprocess
import sys
import tempfile

calcvar, examples = [os.path.abspath(a) for a in sys.argv[1:3]]
failures = 0
BASE = b"[scene]\ntitle = %s\ninterval = %s\nunknowns = %s\nintegrand = %s\n[boundary]\n%s\n"
FORBIDDEN = ("invalid argument", "no solve yet", "nan", "ex_integrand")


def fail(what, expected, actual):
    global failures
    failures += 1
    print("FAIL %s\n  expected: %s\n  actual:   %s" % (what, expected, actual))


def run(args, cwd):
    return subprocess.run([calcvar] + args, cwd=cwd, capture_output=True, timeout=120)


def bad_scene(tmp, what, text, line, words):
    with open(os.path.join(tmp, "bad.scene"), "wb") as f:
        f.write(text)
    r = run(["solve", "bad.scene", "--quiet"], tmp)
    err = r.stderr.decode(errors="replace")
    if r.returncode != 2 or not err.startswith("bad.scene:%d:" % line) or words not in err or \
            any(w in err for w in FORBIDDEN):
        fail(what, "exit 2, 'bad.scene:%d: ... %s ...'" % (line, words),
             "%d %s" % (r.returncode, err.strip()[:300]))


def check_messages(tmp):
    ok = BASE % (b"t", b"0, 1", b"y", b"y'^2", b"y = 0, 1")
    bad_scene(tmp, "grading = 30", ok + b"[mesh]\ngrading = 30\n", 9, "from 1 to 20")
    bad_scene(tmp, "grading = 25 (a variant)", ok + b"[mesh]\nelements = 4\ngrading = 25\n", 10,
              "from 1 to 20")
    bad_scene(tmp, "interval = -1e308, 1e308",
              BASE % (b"t", b"-1e308, 1e308", b"y", b"y'^2", b"y = 0, 1"), 3,
              "larger than the largest double")
    bad_scene(tmp, "interval = -1.7e308, 1.7e308 (a variant)",
              BASE % (b"t", b"-1.7e308, 1.7e308", b"y", b"y'^2", b"y = 0, 1"), 3,
              "larger than the largest double")
    for n in (1001, 1500):
        names = ", ".join("u%d" % i for i in range(n)).encode()
        bcs = "\n".join("u%d = 0, 1" % i for i in range(n)).encode()
        bad_scene(tmp, "%d unknowns" % n, BASE % (b"t", b"0, 1", names, b"u0'^2", bcs), 4,
                  "at most 1000 unknowns")
    bad_scene(tmp, "a Latin-1 title", BASE % (b"caf\xe9", b"0, 1", b"y", b"y'^2", b"y = 0, 1"),
              2, "not UTF-8")
    bad_scene(tmp, "a title cut inside a UTF-8 sequence (a variant)",
              BASE % (b"caf\xc3", b"0, 1", b"y", b"y'^2", b"y = 0, 1"), 2, "not UTF-8")
    with open(os.path.join(tmp, "u.scene"), "wb") as f:  # UTF-8 goes through to the JSON
        f.write(BASE % ("café ∫".encode(), b"0, 1", b"y", b"y'^2", b"y = 0, 1"))
    r = run(["solve", "u.scene", "--json", "-"], tmp)
    if r.returncode != 0 or json.loads(r.stdout).get("title") != "café ∫":
        fail("a UTF-8 title in the JSON", "café ∫", r.stdout[:200])


def check_long_name(tmp):
    """Output names of 250 and 255 characters: the temporary name is shortened."""
    with open(os.path.join(tmp, "ok.scene"), "wb") as f:
        f.write(BASE % (b"t", b"0, 1", b"y", b"y'^2", b"y = 0, 1"))
    for n in (250, 255):
        name = "a" * (n - 5) + ".json"
        r = run(["solve", "ok.scene", "--quiet", "--json", name], tmp)
        if r.returncode != 0 or not os.path.exists(os.path.join(tmp, name)):
            fail("an output name of %d characters" % n, "exit 0 and the file",
                 "%d %s" % (r.returncode, r.stderr.decode()[:200]))
        left = [f for f in os.listdir(tmp) if ".tmp." in f]
        if left:
            fail("an output name of %d characters: temporary files" % n, "none", left)


def check_batch_help_and_catenary(tmp):
    for h in ("--help", "-h"):
        r = run(["batch", h], tmp)
        if r.returncode != 0 or not r.stdout.startswith(b"usage: calcvar batch"):
            fail("batch " + h, "exit 0 and the usage", "%d %s" % (r.returncode, r.stderr))
    # the catenary's exact action follows c: --set c=3 is checked against its own
    for c in ("2", "3", "1.5"):
        r = run(["solve", os.path.join(examples, "catenary.scene"), "--set", "c=" + c,
                 "--json", "-"], tmp)
        j = json.loads(r.stdout) if r.returncode == 0 else {}
        err = j.get("error", {}).get("action")
        if err is None or err > 1e-10:
            fail("catenary --set c=%s: error in the action" % c, "< 1e-10", err)


def main():
    with tempfile.TemporaryDirectory() as tmp:
        check_messages(tmp)
        check_long_name(tmp)
        check_batch_help_and_catenary(tmp)
    print("%d failure(s)" % failures)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())

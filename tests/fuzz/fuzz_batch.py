#!/usr/bin/env python3
# tests/fuzz/fuzz_batch.py — mutated batch tables against the command (issue 27): random
# bytes, NULs, control characters, long lines, wrong counts, non-numbers, CRLF, blank
# lines, spliced into a valid table. Each run must end with exit 0, 1 or 2 (never a
# signal, a sanitizer report or a hang); exit 2 names TABLE:LINE; exit 0 or 1 writes one
# output row per input row.
# SPDX-License-Identifier: MIT
#
# usage: fuzz_batch.py CALCVAR SCENE SECONDS
import os
import random
import subprocess
import sys
import tempfile
import time

calcvar, scene, secs = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2]), \
    float(sys.argv[3])
PIECES = [b"\0", b"\x01", b"\x1b", b"\x7f", b"\xff", b"\r\n", b"\n\n", b",", b",,", b" ",
          b"nan", b"inf", b"1e999", b"-0", b"0x10", b"2.5", b"c", b"d", b"\"2\"", b"#",
          b"2" * 5000]


def mutate(rng, text):
    data = bytearray(text)
    for _ in range(rng.randint(1, 6)):
        at = rng.randint(0, len(data))
        op = rng.random()
        if op < 0.5:
            data[at:at] = rng.choice(PIECES)
        elif op < 0.75 and data:
            del data[at:at + rng.randint(1, 4)]
        else:
            data[at:at] = bytes(rng.randrange(256) for _ in range(rng.randint(1, 8)))
    return bytes(data)


def main():
    rng = random.Random(27)
    base = b"c\n" + b"".join(b"%.3f\n" % (2 + 0.01 * k) for k in range(6))
    bad = runs = 0
    t_end = time.monotonic() + secs
    with tempfile.TemporaryDirectory() as tmp:
        table = os.path.join(tmp, "t.csv")
        while time.monotonic() < t_end:
            data = mutate(rng, base)
            with open(table, "wb") as f:
                f.write(data)
            runs += 1
            try:
                r = subprocess.run([calcvar, "batch", scene, table, "--threads", "1"],
                                   capture_output=True, timeout=60)
            except subprocess.TimeoutExpired:
                print("HANG on %r" % data[:200])
                bad += 1
                continue
            err = r.stderr.decode(errors="replace")
            # the header is the first line that is not blank (blank lines are skipped)
            rows = [l for l in data.split(b"\n") if l.strip(b" \t\r")][1:]
            problem = None
            if r.returncode not in (0, 1, 2) or "Sanitizer" in err or "runtime error" in err:
                problem = "exit %d: %s" % (r.returncode, err[:300])
            elif r.returncode == 2 and not err.startswith(table + ":") and \
                    not err.startswith("calcvar"):
                problem = "exit 2 without TABLE:LINE: " + err[:300]
            elif r.returncode in (0, 1) and len(r.stdout.splitlines()) != len(rows) + 1:
                problem = "%d output lines for %d rows" % (len(r.stdout.splitlines()),
                                                           len(rows))
            if problem:
                bad += 1
                print("FINDING on %r: %s" % (data[:200], problem))
    print("fuzz_batch: %d tables, %d finding(s)" % (runs, bad))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())

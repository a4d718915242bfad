#!/usr/bin/env python3
# tests/batch/test_batch_mpi.py — `mpirun -np 2 calcvar batch` writes the same table as one
# process (apart from time_s), in input order, written once (by rank 0); a bad row found by
# the second rank is reported once, exit 2. Exit 77 (skipped)
# when the build has no MPI. Usage: test_batch_mpi.py CALCVAR DATA_DIR MPIRUN_OR_EMPTY
# SPDX-License-Identifier: MIT
import csv
import io
import os
import random
import subprocess
import sys
import tempfile

calcvar, data, mpirun = sys.argv[1], sys.argv[2], sys.argv[3]
if not mpirun:
    print("calcvar was built without MPI (meson -Dmpi): skipped")
    sys.exit(77)

rng = random.Random(7)
tmp = tempfile.mkdtemp(prefix="cvmpi")
table = os.path.join(tmp, "t.csv")
with open(table, "w") as f:
    f.write("A,B,L,c\n")
    # windows of 2 x 1024 rows with one thread per rank: both ranks get rows, and the last
    # window is partial
    for k in range(2800):
        f.write("%r,%r,%r,%r\n" % (round(rng.uniform(-2, 2), 3), round(rng.uniform(-2, 2), 3),
                                   round(rng.uniform(0.2, 3), 3), round(rng.uniform(-3, 3), 3)))
scene = os.path.join(data, "line.scene")


def strip_time(text):
    rows = list(csv.DictReader(io.StringIO(text)))
    for r in rows:
        r.pop("time_s", None)
    return rows


one = subprocess.run([calcvar, "batch", scene, table, "--threads", "1"], capture_output=True,
                     text=True, timeout=120)
cmd = [mpirun, "-np", "2", "--oversubscribe"]
if os.geteuid() == 0:
    cmd.append("--allow-run-as-root")
env = dict(os.environ, OMPI_MCA_rmaps_base_oversubscribe="1")
# Under AddressSanitizer, OpenMPI's own start-up allocations (libmpi, its dlopen'd plugins,
# some from unloaded modules LSan cannot name) are reported as leaks at exit: leak checking
# is off for the ranks only; the same code paths run leak-checked in the one-process runs
# (here and in cli_batch), and ASan's other checks stay on.
if "ASAN_OPTIONS" in env:
    env["ASAN_OPTIONS"] = env["ASAN_OPTIONS"] + ":detect_leaks=0"
else:
    env["ASAN_OPTIONS"] = "detect_leaks=0"
two = subprocess.run(cmd + [calcvar, "batch", scene, table, "--threads", "1"],
                     capture_output=True, text=True, timeout=240, env=env)
# A bad row in the second rank's block: exit 2, its FILE:LINE said once (by that rank).
bad = os.path.join(tmp, "bad.csv")
with open(bad, "w") as f:
    f.write("A,B\n" + "1,2\n" * 1200 + "3,x\n" + "1,2\n" * 40 + "4,y\n")
three = subprocess.run(cmd + [calcvar, "batch", scene, bad, "--threads", "1"],
                       capture_output=True, text=True, timeout=240, env=env)
msg = "%s:1202: column 'B': 'x' is not a finite number" % bad
failures = 0
for what, ok, detail in [
        ("bad row: exit 2", three.returncode == 2, three.returncode),
        ("bad row: said once", three.stderr.count(msg) == 1 and three.stderr.count(bad) == 1,
         three.stderr[:600]),
        ("bad row: nothing written", three.stdout == "", three.stdout[:200]),
        ("one process exit 0", one.returncode == 0, one.stderr[:300]),
        ("mpirun -np 2 exit 0", two.returncode == 0, two.stderr[:600]),
        ("2800 rows", len(strip_time(one.stdout)) == 2800, len(strip_time(one.stdout))),
        ("header once", two.stdout.count("status,action") == 1, two.stdout[:200]),
        ("same table as one process", strip_time(two.stdout) == strip_time(one.stdout),
         (two.stdout[:300], one.stdout[:300]))]:
    if not ok:
        failures += 1
        print("FAIL %s: %s" % (what, detail))
print("8 checks, %d failures" % failures)
sys.exit(1 if failures else 0)

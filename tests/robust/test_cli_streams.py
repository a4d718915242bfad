#!/usr/bin/env python3
# tests/robust/test_cli_streams.py — inputs, outputs and signals under attack (issue 27,
# items 3, 4, 7-13): tables that are FIFOs, devices or pipes; bad bytes in batch rows;
# closed standard output; outputs that are an input or each other; /dev/stdout appended to
# a log; full disks (/dev/full, and a 64 KiB tmpfs mounted here when root, else skipped
# with a message); closed pipes; SIGINT and SIGTERM; MPI ranks with a failing output.
# SPDX-License-Identifier: MIT
#
# usage: test_cli_streams.py CALCVAR SCENE_DIR
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time

calcvar, scene_dir = [os.path.abspath(a) for a in sys.argv[1:3]]
SCENE = os.path.join(scene_dir, "catenary.scene")  # [parameters] c = 2, exact action known
failures = 0
checked = 0


def fail(what, expected, actual):
    global failures
    failures += 1
    print("FAIL %s\n  expected: %s\n  actual:   %s" % (what, expected, actual))


def run(args, cwd, timeout=60, **kw):
    global checked
    checked += 1
    kw.setdefault("stdout", subprocess.PIPE)
    kw.setdefault("stderr", subprocess.PIPE)
    try:
        r = subprocess.run([calcvar] + args, cwd=cwd, timeout=timeout, **kw)
    except subprocess.TimeoutExpired:
        fail("calcvar " + " ".join(args), "an answer within %d s" % timeout, "timed out")
        return subprocess.CompletedProcess(args, -1, b"", b"")
    return r


def err_of(r):
    return (r.stderr or b"").decode(errors="replace")


def expect(what, r, code, msg=None):
    e = err_of(r)
    if "Sanitizer" in e or "runtime error:" in e:
        fail(what + " sanitizer", "no finding", e[:2000])
    if r.returncode != code:
        fail(what + " exit status", code, "%s (stderr: %s)" % (r.returncode, e.strip()[:500]))
    elif msg is not None and msg not in e:
        fail(what + " message", "... " + msg + " ...", e.strip()[:500])


def no_temp_left(what, d):
    left = [f for f in os.listdir(d) if ".tmp." in f or f.startswith("calcvar-")]
    if left:
        fail(what + ": temporary files", "none left", left)


def write(path, data):
    with open(path, "wb") as f:
        f.write(data)


def read(path):
    with open(path, "rb") as f:
        return f.read()


def table_rows(n):
    """A batch table of n rows of c around 2 (every row converges)."""
    return ("c\n" + "".join("%.6f\n" % (2 + 0.5 * (k % 100) / 100) for k in range(n))).encode()


def check_table_inputs(tmp):
    """Item 4: tables that are FIFOs or devices are refused at once (exit 2); a batch
    table from a pipe, '-' or /dev/stdin works; [tables] files follow the same rules."""
    small = table_rows(3)
    write(os.path.join(tmp, "t.csv"), small)
    ref = run(["batch", SCENE, "t.csv", "--threads", "1"], tmp)
    expect("batch from a file", ref, 0)
    fifo = os.path.join(tmp, "fifo.csv")
    os.mkfifo(fifo)
    expect("batch table that is a FIFO", run(["batch", SCENE, fifo], tmp, timeout=20), 2,
           "FIFO")
    for dev in ("/dev/zero", "/dev/urandom", "/dev/null"):
        if os.path.exists(dev):
            expect("batch table " + dev, run(["batch", SCENE, dev], tmp, timeout=20), 2,
                   "device")
    with open("/dev/zero", "rb") as z:
        expect("batch table '-' from /dev/zero", run(["batch", SCENE, "-"], tmp, timeout=20,
                                                      stdin=z), 2, "device")
    noise = bytes((k * 37 + 11) % 256 for k in range(200000))
    expect("batch table '-' from a pipe of binary bytes",
           run(["batch", SCENE, "-"], tmp, timeout=20, input=noise), 2, "not a text table")
    for name in ("-", "/dev/stdin"):
        r = run(["batch", SCENE, name, "--threads", "1"], tmp, input=small)
        expect("batch table %s from a pipe" % name, r, 0)
        got = [l.split(",")[:3] for l in r.stdout.decode().splitlines()]
        want = [l.split(",")[:3] for l in ref.stdout.decode().splitlines()]
        if got != want:
            fail("batch table %s from a pipe: rows" % name, want, got)
    with open(os.path.join(tmp, "t.csv"), "rb") as f:  # '-' on a regular file: rewound
        r = run(["batch", SCENE, "-", "--threads", "1"], tmp, stdin=f)
    expect("batch table '-' redirected from a file", r, 0)
    if r.returncode == 0 and len(r.stdout.splitlines()) != 4:
        fail("batch table '-' from a file: rows", 4, len(r.stdout.splitlines()))
    # [tables]: a FIFO and a device in place of the CSV
    src = os.path.join(scene_dir, "seismic_ray_table.scene")
    if os.path.exists(src):
        d = os.path.join(tmp, "tables")
        os.mkdir(d)
        shutil.copy(src, d)
        os.mkfifo(os.path.join(d, "velocity.csv"))
        expect("[tables] file that is a FIFO",
               run(["solve", "seismic_ray_table.scene", "--quiet"], d, timeout=20), 2, "FIFO")
        os.unlink(os.path.join(d, "velocity.csv"))
        os.symlink("/dev/zero", os.path.join(d, "velocity.csv"))
        expect("[tables] file that is /dev/zero",
               run(["solve", "seismic_ray_table.scene", "--quiet"], d, timeout=20), 2,
               "device")


def check_bad_bytes(tmp):
    """Item 10: a NUL or another control byte in a batch table is TABLE:LINE, exit 2."""
    cases = {"a row that starts with NUL": b"c\n\x002\n",
             "a NUL inside a number (4\\0junk)": b"c\n2\n4\x00junk\n",
             "a NUL in the header": b"c\x00\n2\n",
             "an escape byte": b"c\n2\x1b[1m\n"}
    lines = {"a row that starts with NUL": 2, "a NUL inside a number (4\\0junk)": 3,
             "a NUL in the header": 1, "an escape byte": 2}
    for what, data in cases.items():
        write(os.path.join(tmp, "bad.csv"), data)
        r = run(["batch", SCENE, "bad.csv"], tmp)
        expect("batch table with " + what, r, 2, "bad.csv:%d:" % lines[what])
        if r.stdout:
            fail("batch table with " + what + ": output", "none", r.stdout[:200])


def check_closed_stdout(tmp):
    """Item 7: with standard output closed, no output file takes descriptor 1."""
    r = run(["solve", SCENE, "--quiet", "--json", "q.json", "--csv", "q.csv"], tmp,
            stdout=subprocess.DEVNULL, pass_fds=(), close_fds=True,
            preexec_fn=lambda: os.close(1))
    expect("--quiet --json --csv with stdout closed", r, 0)
    import json
    try:
        j = json.loads(read(os.path.join(tmp, "q.json")))
        if abs(j["action"] - 4.350402387287603) > 1e-9:
            fail("closed stdout: the JSON's action", 4.350402387287603, j["action"])
    except (ValueError, OSError, KeyError) as e:
        fail("closed stdout: the JSON", "a report", repr(e))
    if not read(os.path.join(tmp, "q.csv")).startswith(b"x,y\n"):
        fail("closed stdout: the CSV", "the table", read(os.path.join(tmp, "q.csv"))[:80])
    r = run(["solve", SCENE, "--json", "s.json"], tmp, preexec_fn=lambda: os.close(1))
    expect("a summary for a closed stdout", r, 3, "closed")
    r = run(["batch", SCENE, "-"], tmp, input=b"c\n2\n", preexec_fn=lambda: os.close(1))
    expect("batch into a closed stdout", r, 3)
    no_temp_left("closed stdout", tmp)


def check_same_file(tmp):
    """Item 8: outputs that are an input, or one another, by any name."""
    write(os.path.join(tmp, "in.csv"), table_rows(2))
    before = read(os.path.join(tmp, "in.csv"))
    os.symlink("in.csv", os.path.join(tmp, "link.csv"))
    os.link(os.path.join(tmp, "in.csv"), os.path.join(tmp, "hard.csv"))
    for out in ("./in.csv", "link.csv", "hard.csv", os.path.join(tmp, "in.csv")):
        expect("batch --out %s (the table)" % out,
               run(["batch", SCENE, "in.csv", "--out", out], tmp), 2, "being read")
    with open(os.path.join(tmp, "in.csv"), "rb") as f:
        expect("batch - --out the file stdin reads",
               run(["batch", SCENE, "-", "--out", "in.csv"], tmp, stdin=f), 2, "being read")
    if read(os.path.join(tmp, "in.csv")) != before:
        fail("the batch table", "untouched", "changed")
    for a, b in (("X", "./X"), ("X", os.path.join(tmp, "X")), ("sub/../Y", "Y")):
        os.makedirs(os.path.join(tmp, "sub"), exist_ok=True)
        r = run(["solve", SCENE, "--json", a, "--csv", b], tmp)
        expect("--json %s --csv %s" % (a, b), r, 2, "same file")
        if os.path.exists(os.path.join(tmp, os.path.basename(b))):
            fail("--json %s --csv %s" % (a, b), "nothing written", "a file")
    write(os.path.join(tmp, "Z"), b"old\n")
    os.symlink("Z", os.path.join(tmp, "Zlink"))
    expect("--json Z --csv Zlink (existing)", run(["solve", SCENE, "--json", "Z", "--csv",
                                                   "Zlink"], tmp), 2, "same file")
    if read(os.path.join(tmp, "Z")) != b"old\n":
        fail("--json Z --csv Zlink", "Z untouched", read(os.path.join(tmp, "Z"))[:80])
    no_temp_left("same file", tmp)


def check_stdout_append(tmp):
    """Item 9: --json /dev/stdout >> log (and /dev/stderr, /dev/fd/1) appends to the log."""
    for name, fd in (("/dev/stdout", 1), ("/dev/fd/1", 1), ("/proc/self/fd/1", 1),
                     ("/dev/stderr", 2)):
        log = os.path.join(tmp, "log.txt")
        write(log, b"first line\n")
        with open(log, "ab") as f:
            kw = {"stdout": f} if fd == 1 else {"stderr": f}
            r = run(["solve", SCENE, "--quiet", "--json", name], tmp, **kw)
        if r.returncode != 0:
            fail("--json %s >> log: exit status" % name, 0, r.returncode)
        text = read(log)
        if not text.startswith(b"first line\n{") or b'"action"' not in text:
            fail("--json %s >> log" % name, "the log's line, then the report",
                 text[:80])
    os.symlink("/dev/stdout", os.path.join(tmp, "out-link"))
    write(os.path.join(tmp, "log2.txt"), b"kept\n")
    with open(os.path.join(tmp, "log2.txt"), "ab") as f:
        run(["solve", SCENE, "--quiet", "--json", "out-link"], tmp, stdout=f)
    if not read(os.path.join(tmp, "log2.txt")).startswith(b"kept\n{"):
        fail("--json LINK-TO-/dev/stdout >> log", "appended", read(os.path.join(tmp,
                                                                          "log2.txt"))[:80])
    no_temp_left("stdout append", tmp)


def check_full(tmp):
    """Item 12: a full output is exit 3 with a sentence, for batch as for solve."""
    if not os.path.exists("/dev/full"):
        print("skip: no /dev/full")
        return
    write(os.path.join(tmp, "t.csv"), table_rows(3))
    expect("batch --out /dev/full", run(["batch", SCENE, "t.csv", "--out", "/dev/full"], tmp),
           3, "No space left")
    with open("/dev/full", "wb") as f:
        expect("batch > /dev/full", run(["batch", SCENE, "t.csv"], tmp, stdout=f), 3,
               "No space left")
        expect("solve --csv - > /dev/full", run(["solve", SCENE, "--csv", "-"], tmp,
                                                stdout=f), 3, "No space left")


def check_tmpfs(tmp):
    """Items 6 and 12 on a disk that fills: a 64 KiB tmpfs (root only)."""
    if os.geteuid() != 0:
        print("skip: the full-disk cases mount a tmpfs and need root")
        return
    mnt = os.path.join(tmp, "small")
    os.mkdir(mnt)
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", mnt],
                      stderr=subprocess.DEVNULL).returncode != 0:
        print("skip: cannot mount a tmpfs here")
        return
    try:
        write(os.path.join(tmp, "big.csv"), table_rows(3000))  # ~400 KB of output
        out = os.path.join(mnt, "out.csv")
        write(out, b"old table\n")
        r = run(["batch", SCENE, "big.csv", "--out", out, "--threads", "2"], tmp)
        expect("batch --out on a disk that fills", r, 3, "No space left")
        if read(out) != b"old table\n":
            fail("batch on a full disk", "the old table kept", read(out)[:60])
        no_temp_left("batch on a full disk", mnt)
        for pic in ("p.png", "p.svg"):
            target = os.path.join(mnt, pic)
            write(target, b"old picture\n")
            filler = os.path.join(mnt, "filler")
            try:  # leave a few KiB: a picture needs more
                with open(filler, "wb") as f:
                    f.write(b"\0" * (60 * 1024 - 4096))
            except OSError:
                pass
            r = run(["solve", SCENE, "--quiet", "--plot", target], tmp)
            expect("--plot %s on a full disk" % pic, r, 3)
            if read(target) != b"old picture\n":
                fail("--plot %s on a full disk" % pic, "the old picture kept",
                     read(target)[:60])
            os.unlink(filler)
            no_temp_left("--plot on a full disk", mnt)
        target = os.path.join(mnt, "c.svg")
        write(target, b"old\n")
        try:
            with open(os.path.join(mnt, "filler"), "wb") as f:
                f.write(b"\0" * (60 * 1024 - 2048))
        except OSError:
            pass
        r = run(["converge", SCENE, "--svg", target, "--levels", "3"], tmp)
        expect("converge --svg on a full disk", r, 3)
        if read(target) != b"old\n":
            fail("converge --svg on a full disk", "the old picture kept", read(target)[:60])
        no_temp_left("converge --svg on a full disk", mnt)
    finally:
        subprocess.run(["umount", mnt])


def check_pipe_closed(tmp):
    """Item 13: a reader that goes away (| head) is exit 3 with a sentence, not SIGPIPE."""
    for what, args, data in (
            ("solve --csv - | head -1", ["solve", SCENE, "--csv", "-", "--elements", "20000"],
             None),
            ("batch | head -1", ["batch", SCENE, "-", "--threads", "1"], table_rows(40000))):
        p = subprocess.Popen([calcvar] + args, cwd=tmp, stdin=subprocess.PIPE,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        if data:
            p.stdin.write(data)
        p.stdin.close()
        p.stdout.readline()
        p.stdout.close()
        try:
            err = p.stderr.read().decode(errors="replace")
            p.wait(timeout=60)
        except subprocess.TimeoutExpired:
            p.kill()
            fail(what, "an end", "still running after the reader left")
            continue
        r = subprocess.CompletedProcess(args, p.returncode, b"", err.encode())
        expect(what, r, 3, "Broken pipe")


def check_signals(tmp):
    """Item 11: SIGINT and SIGTERM remove NAME.tmp.XXXXXX and keep the old output."""
    write(os.path.join(tmp, "long.csv"), table_rows(400000))
    for sig in (signal.SIGINT, signal.SIGTERM):
        out = os.path.join(tmp, "res.csv")
        write(out, b"previous results\n")
        p = subprocess.Popen([calcvar, "batch", SCENE, "long.csv", "--out", "res.csv",
                              "--threads", "1"], cwd=tmp, stderr=subprocess.PIPE)
        t0 = time.monotonic()
        while not [f for f in os.listdir(tmp) if f.startswith("res.csv.tmp.")]:
            if time.monotonic() - t0 > 30 or p.poll() is not None:
                break
            time.sleep(0.01)
        time.sleep(0.5)  # into the solving: the temporary file holds rows
        p.send_signal(sig)
        try:
            p.wait(timeout=30)
        except subprocess.TimeoutExpired:
            p.kill()
            fail("batch under %s" % sig.name, "an end", "still running")
        if p.returncode != -sig:
            fail("batch under %s: how it ended" % sig.name, "by the signal (%d)" % -sig,
                 p.returncode)
        no_temp_left("batch under %s" % sig.name, tmp)
        if read(out) != b"previous results\n":
            fail("batch under %s: the old output" % sig.name, "kept", read(out)[:60])


def check_plot_memory(tmp):
    """Item 1: --plot under a memory limit ends with exit 0 and a whole picture, or exit 3,
    a sentence and the old picture; never a crash, never a temporary file left."""
    import resource

    def limit(mb):
        return lambda: resource.setrlimit(resource.RLIMIT_AS, (mb << 20, mb << 20))
    probe = run(["--version"], tmp, preexec_fn=limit(400))
    if probe.returncode != 0:  # a sanitised build reserves terabytes of address space
        print("skip: calcvar does not start under a 400 MB address-space limit (sanitisers?)")
        return
    for pic in ("p.png", "p.svg"):
        for mb in (30, 45, 60, 80, 105, 400):
            target = os.path.join(tmp, pic)
            write(target, b"old picture\n")
            r = run(["solve", SCENE, "--quiet", "--plot", pic], tmp, preexec_fn=limit(mb),
                    env=dict(os.environ, TMPDIR=tmp))  # the drawing's scratch file too
            what = "--plot %s under %d MB" % (pic, mb)
            if r.returncode == 0:
                data = read(target)
                whole = data.rstrip().endswith(b"</svg>") if pic.endswith("svg") else \
                    data.startswith(b"\x89PNG") and data.endswith(b"IEND\xaeB`\x82")
                if not whole:
                    fail(what, "a whole picture with exit 0", data[:40])
            else:
                expect(what, r, 3, "the plotting library failed")
                if read(target) != b"old picture\n":
                    fail(what, "the old picture kept", read(target)[:40])
            no_temp_left(what, tmp)


def check_mpi(tmp):
    """Item 3: under MPI a failing output ends every rank, with exit 3."""
    mpirun = shutil.which("mpirun")
    if not mpirun:
        print("skip: no mpirun")
        return
    probe = subprocess.run([mpirun, "--version"], capture_output=True)
    if probe.returncode != 0:
        print("skip: mpirun does not run")
        return
    write(os.path.join(tmp, "t.csv"), table_rows(50))
    base = [mpirun, "-np", "2", "--oversubscribe", "--allow-run-as-root", calcvar, "batch",
            SCENE, "t.csv", "--threads", "1"]
    for what, extra, code in (("--out /dev/full", ["--out", "/dev/full"], 3),
                              ("--out into a directory that does not exist",
                               ["--out", "nodir/out.csv"], 2),
                              ("a table row that is bad", ["--out", "o.csv"], None)):
        if code is None:
            write(os.path.join(tmp, "t.csv"), table_rows(30) + b"x\n")
            code = 2
        # Open MPI's own allocations are reported as leaks at exit under LSan: leak
        # checking is off for the ranks only (as in tests/batch/test_batch_mpi.py)
        env = dict(os.environ)
        env["ASAN_OPTIONS"] = env.get("ASAN_OPTIONS", "") + ":detect_leaks=0"
        try:
            r = subprocess.run(base + extra, cwd=tmp, capture_output=True, timeout=60, env=env)
        except subprocess.TimeoutExpired:
            fail("mpirun -np 2 batch " + what, "an end", "hung (60 s)")
            continue
        if "not built with MPI" in r.stderr.decode(errors="replace"):
            print("skip: this calcvar has no MPI")
            return
        if r.returncode != code:
            fail("mpirun -np 2 batch " + what, code,
                 "%d: %s" % (r.returncode, r.stderr.decode(errors="replace")[:400]))


def main():
    with tempfile.TemporaryDirectory() as base:
        for check in (check_table_inputs, check_bad_bytes, check_closed_stdout,
                      check_same_file, check_stdout_append, check_full, check_tmpfs,
                      check_pipe_closed, check_signals, check_plot_memory, check_mpi):
            d = os.path.join(base, check.__name__)
            os.mkdir(d)
            n0 = failures
            check(d)
            print("%s %s" % ("ok  " if failures == n0 else "FAIL", check.__doc__.split(":")[0]))
    print("%d checks, %d failure(s)" % (checked, failures))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
# tests/fuzz/fuzz_outpath.py — random output paths for every command that writes: regular
# files (new, existing, read-only directory), symbolic links (chains, dangling, to a device,
# to the scene), FIFOs with and without a reader, device nodes, directories, the input scene
# by another name, standard input redirected from the scene. After each run: the scene is
# unchanged, no non-regular file was replaced, no temporary file is left, the exit status is
# 0..3 and says what happened (2 before any output, 3 on a write error), and a regular target
# written with exit 0 holds a complete report. Run by scripts/fuzz.sh.
# SPDX-License-Identifier: MIT
#
# usage: fuzz_outpath.py CALCVAR SCENE_DIR [SECONDS]
import os
import random
import stat
import subprocess
import sys
import tempfile
import threading
import time

calcvar, data = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
secs = float(sys.argv[3]) if len(sys.argv) > 3 else 20
root = os.geteuid() == 0
seed = int(os.environ.get("FUZZ_SEED", time.time()))
rng = random.Random(seed)
findings = 0
runs = 0


def finding(msg):
    global findings
    findings += 1
    print("FINDING (seed %d, run %d): %s" % (seed, runs, msg))


def kind(p):
    try:
        m = os.lstat(p).st_mode
    except FileNotFoundError:
        return "missing"
    return ("link" if stat.S_ISLNK(m) else "fifo" if stat.S_ISFIFO(m) else
            "chr" if stat.S_ISCHR(m) else "dir" if stat.S_ISDIR(m) else
            "reg" if stat.S_ISREG(m) else "other")


def drain(path, stop):
    # a reader for a FIFO: opens (unblocking the writer), reads to the end
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    except OSError:
        return
    while not stop.is_set():
        try:
            if not os.read(fd, 65536):
                time.sleep(0.01)
        except BlockingIOError:
            time.sleep(0.01)
    os.close(fd)


commands = [("solve", "catenary.scene", ["--json", "--csv", "--plot"]),
            ("converge", "catenary.scene", ["--json", "--svg"]),
            ("equations", "catenary.scene", ["--json"]),
            ("modes", "pendulum_angle.scene", ["--json"])]
t_end = time.time() + secs
while time.time() < t_end:
    runs += 1
    with tempfile.TemporaryDirectory() as tmp:
        cmd, src, opts = rng.choice(commands)
        scene = os.path.join(tmp, "in.scene")
        with open(os.path.join(data, src)) as f:
            text = f.read()
        with open(scene, "w") as f:
            f.write(text)
        opt = rng.choice(opts)
        ext = ".svg" if opt in ("--plot", "--svg") else rng.choice([".json", ".csv", ""])
        out = os.path.join(tmp, "out" + ext)
        sub = os.path.join(tmp, "d")
        os.mkdir(sub)
        readers = []
        choice = rng.randrange(12)
        if choice == 0:
            pass  # new file
        elif choice == 1:
            with open(out, "w") as f:
                f.write("old")
        elif choice == 2:
            os.symlink("t1" + ext, out)
            os.symlink("t2" + ext, os.path.join(tmp, "t1" + ext))  # chain, dangling end
        elif choice == 3:
            os.mkfifo(out)
            if rng.random() < 0.8:
                readers.append(out)
            else:
                out = os.path.join(tmp, "nope", "out" + ext)  # no reader: use a bad dir
        elif choice == 4 and root:
            os.mknod(out, 0o666 | stat.S_IFCHR, os.makedev(1, rng.choice([3, 7])))
        elif choice == 5:
            out = rng.choice([sub, sub + "/"])
        elif choice == 6:
            out = rng.choice([scene, os.path.join(sub, "..", "in.scene")])
        elif choice == 7:
            os.link(scene, out)
        elif choice == 8:
            os.symlink(scene, out)
        elif choice == 9 and root:
            dev = os.path.join(tmp, "null")
            os.mknod(dev, 0o666 | stat.S_IFCHR, os.makedev(1, 3))
            os.symlink(dev, out)
        elif choice == 10:
            out = os.path.join(tmp, "missing_dir", "out" + ext)
        else:
            out = "-" if opt != "--plot" and opt != "--svg" else out
        before = {f: kind(os.path.join(tmp, f)) for f in os.listdir(tmp)}
        stdin = None
        scene_arg = scene
        if rng.random() < 0.2:
            scene_arg = "-"
            stdin = open(scene, "rb")
        stop = threading.Event()
        threads = [threading.Thread(target=drain, args=(p, stop)) for p in readers]
        for t in threads:
            t.start()
        try:
            r = subprocess.run([calcvar, cmd, scene_arg, opt, out, "--quiet"], cwd=tmp,
                               stdin=stdin, capture_output=True, timeout=60)
            rc, err = r.returncode, r.stderr.decode(errors="replace")
        except subprocess.TimeoutExpired:
            rc, err = None, "timeout"
        stop.set()
        for t in threads:
            t.join(10)
        if stdin:
            stdin.close()
        what = "%s %s %s %s (case %d)" % (cmd, "-" if scene_arg == "-" else "SCENE", opt,
                                          os.path.relpath(out, tmp) if out != "-" else "-",
                                          choice)
        if rc not in (0, 1, 2, 3):
            finding("%s: exit %s: %s" % (what, rc, err[-500:]))
        if "Sanitizer" in err or "runtime error:" in err:
            finding("%s: sanitizer: %s" % (what, err[-2000:]))
        with open(scene) as f:
            if f.read() != text:
                finding("%s: the input scene was changed" % what)
        for f, k in before.items():
            now = kind(os.path.join(tmp, f))
            if k in ("fifo", "chr", "link", "dir") and now != k:
                finding("%s: %s was a %s, is now %s" % (what, f, k, now))
        left = [f for f in os.listdir(tmp) if ".tmp." in f] + \
               [f for f in os.listdir(sub) if ".tmp." in f]
        if left:
            finding("%s: temporary files left: %s" % (what, left))
        if choice in (5, 6, 7, 8, 10) and rc != 2:
            finding("%s: expected exit 2 (refused before the work), got %s: %s" % (what, rc, err))
        if choice in (0, 1, 2) and rc == 0 and opt in ("--json", "--csv"):
            target = os.path.realpath(out)
            with open(target) as f:
                body = f.read()
            ok = body.rstrip().endswith(("}", "]")) if opt == "--json" else body.count("\n") > 2
            if not ok:
                finding("%s: the report is incomplete" % what)
print("fuzz_outpath: %d runs in %.0f s (seed %d), %d findings" % (runs, secs, seed, findings))
sys.exit(1 if findings else 0)

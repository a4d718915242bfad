#!/usr/bin/env python3
# tests/robust/test_cli_io.py — where calcvar reads and writes (issue 14, items 4-6):
# output paths that are devices, FIFOs, symbolic links, directories or the input scene; a
# full disk or full standard output (exit 3); scene paths that are not regular files, too
# large, or "-" (standard input, "<stdin>" in messages); --set with a non-finite constant.
# SPDX-License-Identifier: MIT
#
# usage: test_cli_io.py CALCVAR DATA_DIR
import json
import os
import stat
import subprocess
import sys
import tempfile
import threading

calcvar, data_dir = [os.path.abspath(a) for a in sys.argv[1:3]]
CAT = os.path.join(data_dir, "catenary.scene")
PEND = os.path.join(data_dir, "pendulum_angle.scene")
failures = 0
checked = 0


def fail(what, expected, actual):
    global failures
    failures += 1
    print("FAIL %s\n  expected: %s\n  actual:   %s" % (what, expected, actual))


def run(args, cwd, stdin=None, stdout=subprocess.PIPE, input_bytes=None, timeout=60):
    global checked
    checked += 1
    try:
        r = subprocess.run([calcvar] + args, cwd=cwd, stdin=stdin, stdout=stdout,
                           stderr=subprocess.PIPE, input=input_bytes, timeout=timeout)
    except subprocess.TimeoutExpired:
        fail("calcvar " + " ".join(args), "an answer within %d s" % timeout, "timed out")
        r = subprocess.CompletedProcess(args, -1, b"", b"")
    r.err = r.stderr.decode(errors="replace")
    r.out = r.stdout.decode(errors="replace") if r.stdout is not None else ""
    if "Sanitizer" in r.err or "runtime error:" in r.err:
        fail("calcvar " + " ".join(args) + " sanitizer", "no finding", r.err[:2000])
    return r


def expect(what, r, code, msg=None):
    if r.returncode != code:
        fail(what + " exit status", code, "%d (stderr: %s)" % (r.returncode, r.err.strip()))
    elif msg is not None and msg not in r.err:
        fail(what + " message", "... " + msg + " ...", r.err.strip())


def is_char_device(p):
    return stat.S_ISCHR(os.stat(p).st_mode)


def no_temp_left(what, d):
    left = [f for f in os.listdir(d) if ".tmp." in f]
    if left:
        fail(what + " temporary files", "none left", left)


def strip_time(text):
    j = json.loads(text)
    j.pop("time_s", None)
    return j


def reader(path, sink):
    with open(path, "rb") as f:
        sink.append(f.read())


def devices(tmp):
    """The null and full devices to aim outputs at. As root, a calcvar with the bug this
    test looks for would replace /dev/null itself; private device nodes (same major and
    minor numbers) in the test's directory take the damage instead. Not root: /dev cannot
    be written, so the real nodes are safe."""
    if os.geteuid() != 0:
        return "/dev/null", "/dev/full" if os.path.exists("/dev/full") else None
    try:
        nodes = []
        for name, minor in (("null", 3), ("full", 7)):
            p = os.path.join(tmp, "dev_" + name)
            os.mknod(p, 0o666 | stat.S_IFCHR, os.makedev(1, minor))
            with open(p, "wb") as f:
                f.write(b"x") if name == "null" else None
            nodes.append(p)
        return nodes[0], nodes[1]
    except OSError as e:
        print("note: device cases skipped (no private device nodes as root: %s)" % e)
        return None, None


with tempfile.TemporaryDirectory() as tmp:
    DEVNULL, DEVFULL = devices(tmp)
    scene = os.path.join(tmp, "cat.scene")
    with open(CAT) as f:
        scene_text = f.read()
    with open(scene, "w") as f:
        f.write(scene_text)
    with open(PEND) as f:  # a copy: a buggy calcvar must not clobber the test data
        PEND = os.path.join(tmp, "pend.scene")
        with open(PEND, "w") as g:
            g.write(f.read())

    def scene_intact(what):
        with open(scene) as f:
            if f.read() != scene_text:
                fail(what + ": input scene", "unchanged", "overwritten")
                with open(scene, "w") as g:
                    g.write(scene_text)

    # --- item 4: devices --------------------------------------------------------------
    for opt in ["--json", "--csv"]:
        if DEVNULL:
            r = run(["solve", scene, "--quiet", opt, DEVNULL], tmp)
            expect("solve %s /dev/null" % opt, r, 0)
            if not is_char_device(DEVNULL):
                fail(opt + " /dev/null", "still a character device", "replaced")
        if DEVFULL:
            r = run(["solve", scene, "--quiet", opt, DEVFULL], tmp)
            expect("solve %s /dev/full" % opt, r, 3, "cannot write " + DEVFULL)
            if not is_char_device(DEVFULL):
                fail(opt + " /dev/full", "still a character device", "replaced")
    if DEVFULL:
        # a full standard output: the summary, a report on "-", and the other commands
        with open(DEVFULL, "wb") as full:
            for args in (["solve", scene], ["solve", scene, "--quiet", "--json", "-"],
                         ["solve", scene, "--quiet", "--csv", "-"], ["check", scene],
                         ["equations", scene], ["modes", PEND], ["converge", scene],
                         ["converge", scene, "--json", "-"]):
                r = run(args, tmp, stdout=full)
                expect(" ".join(["calcvar"] + args[:1] + ["SCENE"] + args[2:]) + " > /dev/full",
                       r, 3, "cannot write standard output")
                if r.err.count("cannot write standard output") != 1:
                    fail("stdout /dev/full " + " ".join(args[2:]), "one message", r.err.strip())
        for args in (["converge", scene, "--quiet", "--json", DEVFULL],
                     ["equations", scene, "--quiet", "--json", DEVFULL],
                     ["modes", PEND, "--quiet", "--json", DEVFULL]):
            r = run(args, tmp)
            expect(" ".join(args[:1] + args[2:]), r, 3, "cannot write " + DEVFULL)
            if not is_char_device(DEVFULL):
                fail(args[0] + " --json /dev/full", "still a character device", "replaced")
        ln = os.path.join(tmp, "full.svg")
        os.symlink(DEVFULL, ln)
        r = run(["solve", scene, "--quiet", "--plot", ln], tmp)
        expect("solve --plot link-to-/dev/full.svg", r, 3, "No space left")
        os.unlink(ln)

    # --- /dev/stdout: a pipe (a /proc "magic" link readlink cannot name) and a file ------
    if os.path.exists("/dev/stdout"):
        r = run(["solve", scene, "--quiet", "--json", "/dev/stdout"], tmp)
        expect("solve --json /dev/stdout (a pipe)", r, 0)
        try:
            json.loads(r.out)
        except ValueError:
            fail("--json /dev/stdout (a pipe)", "the JSON report on the pipe", r.out[:200])
        red = os.path.join(tmp, "redirected.json")
        with open(red, "wb") as f:
            r = run(["solve", scene, "--quiet", "--json", "/dev/stdout"], tmp, stdout=f)
        expect("solve --json /dev/stdout (a file)", r, 0)
        with open(red) as f:
            try:
                json.load(f)
            except ValueError:
                fail("--json /dev/stdout (a file)", "the JSON report in the file", "not JSON")
        os.unlink(red)

    # --- FIFOs: streamed into, never replaced -----------------------------------------
    for opt, name, head in [("--csv", "fifo.csv", b"x,"), ("--json", "fifo.json", b"{"),
                            ("--plot", "fifo.svg", b"<?xml")]:
        fifo = os.path.join(tmp, name)
        os.mkfifo(fifo)
        sink = []
        t = threading.Thread(target=reader, args=(fifo, sink))
        t.start()
        r = run(["solve", scene, "--quiet", opt, fifo], tmp)
        t.join(30)
        expect("solve %s FIFO" % opt, r, 0)
        if not stat.S_ISFIFO(os.stat(fifo).st_mode):
            fail(opt + " FIFO", "still a FIFO", "replaced by a regular file")
        if not sink or not sink[0].lstrip().startswith(head):
            fail(opt + " FIFO content", head, sink[0][:40] if sink else "nothing read")
        os.unlink(fifo)
    no_temp_left("FIFOs", tmp)

    # --- symbolic links: followed, the link stays ---------------------------------------
    target = os.path.join(tmp, "target.csv")
    link = os.path.join(tmp, "link.csv")
    with open(target, "w") as f:
        f.write("old\n")
    os.chmod(target, 0o640)
    os.symlink("target.csv", link)  # relative, resolved against the link's directory
    r = run(["solve", scene, "--quiet", "--csv", link], tmp)
    expect("solve --csv link", r, 0)
    if not os.path.islink(link):
        fail("--csv link", "still a link", "replaced")
    with open(target) as f:
        if not f.read().startswith("x,"):
            fail("--csv link target", "the CSV table", "not written")
    if stat.S_IMODE(os.stat(target).st_mode) != 0o640:
        fail("--csv link target mode", "0640 kept", oct(stat.S_IMODE(os.stat(target).st_mode)))
    dangling = os.path.join(tmp, "dangling.json")
    os.symlink(os.path.join(tmp, "sub_target.json"), dangling)
    r = run(["solve", scene, "--quiet", "--json", dangling], tmp)
    expect("solve --json dangling link", r, 0)
    if not os.path.islink(dangling) or not os.path.isfile(os.path.join(tmp, "sub_target.json")):
        fail("--json dangling link", "link kept, target created", os.listdir(tmp))
    nl = os.path.join(tmp, "null.svg")
    os.symlink(DEVNULL or "/dev/null", nl)
    for args in (["solve", scene, "--quiet", "--plot", nl], ["converge", scene, "--quiet",
                                                              "--svg", nl]):
        if not DEVNULL:
            break
        r = run(args, tmp)
        expect(args[0] + " picture to a link to /dev/null", r, 0)
        if not os.path.islink(nl) or not is_char_device(DEVNULL):
            fail(args[0] + " link to /dev/null", "link and device kept", "replaced")
    no_temp_left("links", tmp)

    # --- the input scene, by any path, is refused before solving ------------------------
    hard = os.path.join(tmp, "hard.scene")
    os.link(scene, hard)
    slink = os.path.join(tmp, "slink")
    os.symlink("cat.scene", slink)
    sub = os.path.join(tmp, "d")
    os.mkdir(sub)
    for cmd, opt in [("solve", "--csv"), ("solve", "--json"), ("converge", "--json"),
                     ("equations", "--json")]:
        for out in (scene, hard, slink, os.path.join(sub, "..", "cat.scene")):
            r = run([cmd, scene, "--quiet", opt, out], tmp)
            expect("%s %s (the input scene as %s)" % (cmd, opt, os.path.relpath(out, tmp)), r, 2,
                   "it is the scene being read")
            scene_intact(cmd + " " + opt)
    with open(scene, "rb") as f:  # "-" reading a redirected file: that file is the input
        r = run(["solve", "-", "--quiet", "--json", scene], tmp, stdin=f)
    expect("solve - < scene --json scene", r, 2, "it is the scene being read")
    scene_intact("solve - < scene")
    r = run(["modes", PEND, "--quiet", "--json", PEND], tmp)
    expect("modes --json the input scene", r, 2, "it is the scene being read")

    # --- directories: refused before solving (no work, nothing written) ---------------
    for out in (sub, sub + "/", os.path.join(tmp, "no_dir", "x.json")):
        for cmd in (["solve", scene], ["converge", scene], ["equations", scene],
                    ["modes", PEND]):
            r = run(cmd + ["--json", out], tmp)
            expect("%s --json %s" % (cmd[0], os.path.relpath(out, tmp)), r, 2, "cannot write")
            if r.out:
                fail(cmd[0] + " --json dir stdout", "nothing (refused before the work)", r.out)
    if os.listdir(sub):
        fail("--json dir", "nothing written into the directory", os.listdir(sub))
    no_temp_left("directories", tmp)

    # --- item 5: a non-finite --set -----------------------------------------------------
    for val, msg in (("0/0", "'0/0' is not a finite number (NaN)"),
                     ("1/0 - 1/0", "not a finite number"), ("sqrt(-1)*0", "(NaN)")):
        r = run(["solve", scene, "--set", "c=" + val, "--json", "out.json"], tmp)
        expect("--set c=" + val, r, 2, msg)
        if os.path.exists(os.path.join(tmp, "out.json")):
            fail("--set c=" + val, "no report written", "out.json")

    # --- item 6: scene paths ------------------------------------------------------------
    fifo = os.path.join(tmp, "in.fifo")
    os.mkfifo(fifo)
    # (not /dev/zero: a calcvar with the bug would eat the machine's memory before failing)
    for path, msg in (("/dev/null", "character device"),
                      (sub, "directory"), (fifo, "FIFO")):
        for cmd in ("solve", "check", "equations", "modes", "converge"):
            r = run([cmd, path], tmp, timeout=20)  # must not block on the FIFO
            expect("%s %s" % (cmd, os.path.relpath(path, tmp)), r, 2, msg)
    big = os.path.join(tmp, "big.scene")
    with open(big, "w") as f:
        f.write(scene_text)
        f.write("#" * (4 << 20))
    r = run(["solve", big], tmp)
    expect("solve a 4 MiB + scene", r, 2, "larger than 4194304 bytes")
    r = run(["solve", "-"], tmp, input_bytes=b"#" * ((4 << 20) + 1))
    expect("solve - (4 MiB + 1 bytes)", r, 2, "<stdin>: the scene is larger")
    under = ("#" * ((4 << 20) - len(scene_text) - 2) + "\n" + scene_text).encode()
    r = run(["solve", "-", "--quiet"], tmp, input_bytes=under)
    expect("solve - (just under 4 MiB)", r, 0)

    # standard input: the same answer as the file, for every command; messages say <stdin>
    for cmd, path in (("solve", scene), ("check", scene), ("equations", scene),
                      ("modes", PEND), ("converge", scene)):
        with open(path, "rb") as f:
            text = f.read()
        a = run([cmd, path, "--json", "-"] if cmd != "check" else [cmd, path], tmp)
        b = run([cmd, "-", "--json", "-"] if cmd != "check" else [cmd, "-"], tmp,
                input_bytes=text)
        expect(cmd + " -", b, a.returncode)
        if cmd in ("solve", "converge"):
            ja, jb = json.loads(a.out), json.loads(b.out)
            rows_a = ja if isinstance(ja, list) else ja.get("rows", [ja])
            rows_b = jb if isinstance(jb, list) else jb.get("rows", [jb])
            if isinstance(ja, dict) and "rows" not in ja:
                rows_a, rows_b = [ja], [jb]
            for x, y in zip(rows_a, rows_b):
                if isinstance(x, dict):
                    x.pop("time_s", None)
                    y.pop("time_s", None)
            if json.dumps(ja, sort_keys=True) != json.dumps(jb, sort_keys=True):
                fail(cmd + " - JSON", "the same as from the file (apart from time_s)",
                     "different")
        elif cmd != "check" and a.out != b.out:
            fail(cmd + " - output", "the same as from the file", b.out[:200])
    bad = scene_text.replace("c = 2", "c = 0/0")
    r = run(["solve", "-"], tmp, input_bytes=bad.encode())
    line = scene_text.split("\n").index("c = 2") + 1
    expect("solve - (bad scene)", r, 2, "<stdin>:%d: parameter 'c'" % line)
    r = run(["solve", "-", "--continue", "c=1.6:2", "--quiet"], tmp,
            input_bytes=scene_text.encode())
    expect("solve - --continue", r, 0)

print("%d cases checked, %d failures" % (checked, failures))
sys.exit(1 if failures else 0)

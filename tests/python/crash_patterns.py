#!/usr/bin/env python3
"""tests/python/crash_patterns.py — the ways of using Solutions that crashed the interpreter
before Solutions owned their data (issue: deepcopy then del, pickle round trips, process
pools returning Solutions, threads on the paths of one all=True solve). Each pattern also
checks its answers against the same Solution used plainly; run one pattern per process:

usage: crash_patterns.py PATTERN     (deepcopy, pickle, pool_spawn, pool_fork, threads_paths,
                                      threads_report, threads_solve); prints OK and exits 0,
                                      or fails.
SPDX-License-Identifier: MIT
"""
import concurrent.futures
import copy
import gc
import multiprocessing
import pickle
import sys
import threading

import numpy as np

import calcvar
from calcvar._solution import Handles

CATENARY = """[scene]
title = Catenary
interval = -1, 1
unknowns = y
integrand = y * sqrt(1 + y'^2)
[parameters]
c = 2
[boundary]
y = c*cosh(1/c), c*cosh(1/c)
"""
BRATU = """[scene]
title = Bratu
interval = 0, 1
unknowns = y
integrand = y'^2/2 - exp(y)
[boundary]
y = 0, 0
"""
XS = np.linspace(-1, 1, 41)


def catenary(c):
    """A Solution of the catenary with parameter c (in a worker: returned by pickling)."""
    return calcvar.solve(CATENARY, elements=8, degree=4, set={"c": c})


def deepcopy():
    s = catenary(2)
    want = s(XS), s.action, s.report["action"]
    d = copy.deepcopy(s)
    e = copy.copy(d)
    del s
    gc.collect()
    assert np.array_equal(d(XS), want[0]) and d.action == want[1]
    assert d.report["action"] == want[2]
    del d
    gc.collect()
    assert e.report["action"] == want[2] and np.array_equal(e(XS), want[0])


def pickle_():
    s = catenary(2)
    want = s(XS), s.action, s.morse_index
    p = pickle.loads(pickle.dumps(s))
    q = pickle.loads(pickle.dumps(p))  # a Solution without handles pickles too
    del s
    gc.collect()
    for r in (p, q):
        assert np.array_equal(r(XS), want[0]) and r.action == want[1]
        assert r.morse_index == want[2] and r.report["status"] == "converged"
    del p
    gc.collect()
    assert q["y"].shape == q.x.shape


def pool(method):
    cs = [1.5, 2.0, 2.5, 3.0]
    ctx = multiprocessing.get_context(method)
    with concurrent.futures.ProcessPoolExecutor(max_workers=2, mp_context=ctx) as ex:
        sols = list(ex.map(catenary, cs))
    for c, s in zip(cs, sols):
        here = catenary(c)
        assert s.success and abs(s.action - here.action) <= 1e-12 * here.action
        assert np.max(np.abs(s(XS) - here(XS))) <= 1e-12
        assert s.report["status"] == "converged"
    del sols
    gc.collect()


def threads_paths():
    sols = calcvar.solve(BRATU, elements=16, degree=6, all=True)
    assert len(sols) == 2, len(sols)
    xs = np.linspace(0, 1, 2001)
    want = [(s(xs), s.action, s.report["action"]) for s in sols]
    bad = []

    def work(k):
        for _ in range(50):
            s = sols[k]
            if not (np.array_equal(s(xs), want[k][0]) and s.action == want[k][1]
                    and s.report["action"] == want[k][2]):
                bad.append(k)

    ts = [threading.Thread(target=work, args=(k % 2,)) for k in range(4)]
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    assert not bad, bad
    assert want[0][1] < want[1][1]


def threads_report():
    s = catenary(2)
    copies = [s, copy.copy(s), copy.deepcopy(s)]
    out = []
    ts = [threading.Thread(target=lambda c=c: out.append((c.report["action"], c.action,
                                                          c.message)))
          for c in copies * 2]
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    assert len(out) == 6 and len(set(out)) == 1, out


def threads_solve():
    """Four threads solving at once (the GIL is released in the solve) get the answers of
    the same solves made one after the other, and bad input in one thread is its own."""
    cs = [1.5, 2.0, 2.5, 3.0] * 2
    want = {c: catenary(c).action for c in cs}
    got, errors = [], []

    def work(c):
        got.append((c, catenary(c).action))
        try:
            calcvar.solve(CATENARY, set={"c": "1/0"})
        except ValueError as e:
            errors.append(str(e))

    ts = [threading.Thread(target=work, args=(c,)) for c in cs]
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    assert sorted(got) == sorted((c, want[c]) for c in cs), got
    assert len(errors) == len(cs)


PATTERNS = {"deepcopy": deepcopy, "pickle": pickle_, "pool_spawn": lambda: pool("spawn"),
            "pool_fork": lambda: pool("fork"), "threads_paths": threads_paths,
            "threads_report": threads_report, "threads_solve": threads_solve}

if __name__ == "__main__":
    PATTERNS[sys.argv[1]]()
    gc.collect()
    assert Handles.live() == 0, "%d handle triples not freed" % Handles.live()
    print("OK")

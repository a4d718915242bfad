"""tests/python/test_docs.py — every ```python block of docs/python.md runs, in order, in
one namespace, from the repository's root (the tutorial's paths are relative to it); the
blocks check their own claims with assert. A block that needs scipy or sympy is skipped
(with the rest) when they are not installed.
SPDX-License-Identifier: MIT
"""
import contextlib
import io
import os
import re

import pytest

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
DOC = os.path.join(ROOT, "docs", "python.md")


def blocks():
    text = open(DOC, encoding="utf-8").read()
    out = []
    for m in re.finditer(r"^```python\n(.*?)^```", text, re.S | re.M):
        out.append((text.count("\n", 0, m.start()) + 2, m.group(1)))
    return out


def test_every_python_block_runs():
    found = blocks()
    assert len(found) >= 15, "docs/python.md has %d python blocks" % len(found)
    os.environ.setdefault("MPLBACKEND", "Agg")  # sol.plot() without a display
    ns = {"__name__": "__docs__"}
    here = os.getcwd()
    os.chdir(ROOT)
    try:
        for line, code in found:
            if ("scipy" in code and not _has("scipy")) or ("sympy" in code and not _has("sympy")):
                pytest.skip("docs/python.md:%d needs scipy or sympy" % line)
            with contextlib.redirect_stdout(io.StringIO()):
                try:
                    exec(compile(code, "docs/python.md:%d" % line, "exec"), ns)
                except Exception as e:
                    raise AssertionError("the block at docs/python.md:%d fails: %r"
                                         % (line, e)) from e
    finally:
        os.chdir(here)


def _has(module):
    try:
        __import__(module)
        return True
    except ImportError:
        return False

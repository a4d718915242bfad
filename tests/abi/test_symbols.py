#!/usr/bin/env python3
"""tests/abi/test_symbols.py — the shared library exports exactly the public API.

usage: test_symbols.py LIBCALCVAR.SO CALCVAR.H [SANITIZE]

Every name in `nm -D --defined-only` must be a function declared CVAR_API in calcvar.h,
and every CVAR_API declaration must be exported. When the build is instrumented
(SANITIZE not 'none'), names the sanitizer runtime adds (starting with '__') are ignored.
SPDX-License-Identifier: MIT
"""
import re
import subprocess
import sys


def main():
    lib, header = sys.argv[1], sys.argv[2]
    sanitized = len(sys.argv) > 3 and sys.argv[3] not in ("", "none")
    out = subprocess.run(["nm", "-D", "--defined-only", lib], check=True,
                         capture_output=True, text=True).stdout
    exported = set()
    for line in out.splitlines():
        parts = line.split()
        if len(parts) < 3:
            continue
        name = parts[2].split("@")[0]
        if sanitized and name.startswith("__"):
            continue
        exported.add(name)
    text = open(header, encoding="utf-8").read()
    declared = set(re.findall(r"^CVAR_API [^;]*?\b(cv_\w+)\(", text, re.M))
    bad = sorted(n for n in exported if not n.startswith("cv_") or n not in declared)
    missing = sorted(declared - exported)
    print(f"{len(exported)} exported, {len(declared)} declared CVAR_API in calcvar.h")
    for n in bad:
        print(f"FAIL: exported but not public: {n}")
    for n in missing:
        print(f"FAIL: declared public but not exported: {n}")
    if not declared or bad or missing:
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())

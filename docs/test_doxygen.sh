#!/bin/sh
# docs/test_doxygen.sh — run Doxygen on the public header; fail on any warning.
# usage: test_doxygen.sh DOXYFILE      exit 77 (skipped) when doxygen is not installed.
# SPDX-License-Identifier: MIT
set -eu
command -v doxygen >/dev/null 2>&1 || { echo "doxygen not installed: skipped"; exit 77; }
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
# The configured file, with the output redirected to a scratch folder.
{ cat "$1"; echo "OUTPUT_DIRECTORY = $out"; } | doxygen - >"$out/log" 2>&1 || {
  cat "$out/log"; echo "FAIL: doxygen exited with an error"; exit 1; }
if [ -s "$out/log" ]; then
  cat "$out/log"; echo "FAIL: doxygen printed warnings"; exit 1
fi
[ -f "$out/html/calcvar_8h.html" ] || { echo "FAIL: no page for calcvar.h"; exit 1; }
echo "doxygen $(doxygen --version): no warnings; $(find "$out/html" -type f | wc -l) files"

#!/bin/sh
# docs/test_man.sh — render the man page calcvar(1); fail on any roff warning.
# usage: test_man.sh PAGE       exit 77 (skipped) when groff is not installed.
# SPDX-License-Identifier: MIT
set -eu
command -v groff >/dev/null 2>&1 || { echo "groff not installed: skipped"; exit 77; }
warnings=$(groff -man -Tutf8 -ww -z "$1" 2>&1)
[ -z "$warnings" ] || { echo "$warnings"; echo "FAIL: groff warnings"; exit 1; }
text=$(groff -man -Tutf8 -P-cbou "$1" 2>/dev/null)
for word in NAME SYNOPSIS DESCRIPTION OPTIONS "EXIT STATUS" "calcvar solve" "calcvar batch" SIGNALS; do
  printf '%s' "$text" | grep -q "$word" || { echo "FAIL: '$word' missing"; exit 1; }
done
echo "$1 renders: $(printf '%s\n' "$text" | wc -l) lines"

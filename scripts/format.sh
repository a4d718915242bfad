#!/usr/bin/env bash
# scripts/format.sh — one format for the whole tree (.clang-format).
#   scripts/format.sh          reformat every C source and header in place
#   scripts/format.sh --check  list the files that differ from the format; exit 1 if any
# SPDX-License-Identifier: MIT
set -euo pipefail
cd "$(dirname "$0")/.."
command -v clang-format >/dev/null || { echo "format.sh: clang-format is not installed" >&2; exit 2; }
mapfile -t files < <(git ls-files '*.c' '*.h' '*.cpp')
if [ "${1:-}" = "--check" ]; then
  bad=0
  for f in "${files[@]}"; do
    if ! clang-format "$f" | cmp -s - "$f"; then echo "format.sh: $f differs from .clang-format"; bad=1; fi
  done
  exit $bad
fi
clang-format -i "${files[@]}"

#!/usr/bin/env bash
# scripts/build.sh — configure (once) and build calcvar in ./build (or $1).
set -euo pipefail
cd "$(dirname "$0")/.."
dir="${1:-build}"
[ -f "$dir/build.ninja" ] || meson setup "$dir" --buildtype=debugoptimized -Dwerror=true >/dev/null  # warnings are errors in development and CI
ninja -C "$dir"

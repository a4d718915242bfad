#!/usr/bin/env bash
# scripts/build.sh — configure (once) and build calcvar in ./build (or $1).
set -euo pipefail
cd "$(dirname "$0")/.."
dir="${1:-build}"
[ -f "$dir/build.ninja" ] || meson setup "$dir" --buildtype=debugoptimized >/dev/null
ninja -C "$dir"

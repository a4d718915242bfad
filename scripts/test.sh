#!/usr/bin/env bash
# scripts/test.sh — install dependencies, build, and run every test (meson test).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/deps.sh
scripts/build.sh build
meson test -C build --print-errorlogs "$@"

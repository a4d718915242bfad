#!/usr/bin/env bash
# scripts/gallery.sh — the main job: install dependencies, build, run the demo gallery.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/deps.sh
scripts/build.sh build
exec build/src/cli/calcvar

#!/usr/bin/env bash
# scripts/gallery-pictures.sh — draw the picture of every example scene for docs/gallery.md:
# calcvar solve examples/scenes/NAME.scene --plot docs/gallery/NAME.png
# usage: scripts/gallery-pictures.sh [BUILD_DIR]   (default build; builds it if needed)
# SPDX-License-Identifier: MIT
set -euo pipefail
cd "$(dirname "$0")/.."
dir="${1:-build}"
[ -x "$dir/src/cli/calcvar" ] || scripts/build.sh "$dir"
mkdir -p docs/gallery
for scene in examples/scenes/*.scene; do
  name=$(basename "$scene" .scene)
  "$dir/src/cli/calcvar" solve "$scene" --quiet --plot "docs/gallery/$name.png"
  echo "docs/gallery/$name.png"
done

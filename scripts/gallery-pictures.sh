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
  extra=()
  # the mirage's page shows every ray (docs/mirage.md), not the one a plain solve finds
  [ "$name" = mirage ] && extra=(--all)
  "$dir/src/cli/calcvar" solve "$scene" --quiet "${extra[@]}" --plot "docs/gallery/$name.png"
  echo "docs/gallery/$name.png"
done

#!/bin/sh
# scripts/snapshot.sh — record every output of calcvar for a set of scenes, so that a
# refactoring can be checked to change none of it.
#   scripts/snapshot.sh CALCVAR OUTDIR SCENE...
# For each scene: `solve --json -`, `equations --json -`, `modes --json -` and `check`
# (stdout, stderr and exit status), `solve --csv -` and the text summary of `solve`; and the demo gallery (calcvar without arguments).
# The key time_s is removed from JSON, and run times from the text summary and the
# gallery's last column, since those change from run to run. Compare two snapshots with `diff -r OLD NEW`.
set -u
exe=$1
out=$2
shift 2
mkdir -p "$out"
strip_json() { jq -S 'walk(if type == "object" then del(.time_s) else . end)' 2>/dev/null; }
for scene in "$@"; do
  name=$(basename "$scene" .scene)
  dir=$(basename "$(dirname "$scene")")
  base="$out/$dir.$name"
  for cmd in solve equations modes; do
    "$exe" "$cmd" "$scene" --json - 2>"$base.$cmd.err" >"$base.$cmd.raw"
    echo "exit $?" >"$base.$cmd.rc"
    if strip_json <"$base.$cmd.raw" >"$base.$cmd.json"; then rm -f "$base.$cmd.raw"; else rm -f "$base.$cmd.json"; fi
  done
  "$exe" solve "$scene" --csv - >"$base.solve.csv" 2>/dev/null
  "$exe" solve "$scene" 2>&1 | sed 's/iterations*, [0-9.e+-]* s$/iterations, (time) s/' >"$base.solve.txt"
  "$exe" check "$scene" >"$base.check.out" 2>"$base.check.err"
  echo "exit $?" >"$base.check.rc"
done
"$exe" 2>&1 | sed 's/ *[0-9.]*$//' >"$out/gallery.out"

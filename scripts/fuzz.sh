#!/bin/sh
# scripts/fuzz.sh — build the scene-loader and [tables] fuzzers with clang (libFuzzer +
# ASan + UBSan) and run them for N seconds (default 60) and N/3 seconds, on the reference
# and malformed scenes and the example tables as seed corpus; then fuzz the command's
# output paths (tests/fuzz/fuzz_outpath.py) and batch tables (tests/fuzz/fuzz_batch.py)
# for N/3 seconds each.
# usage: scripts/fuzz.sh [SECONDS]      exit status: 0 clean, nonzero on a finding.
# SPDX-License-Identifier: MIT
set -eu
secs=${1:-60}
root=$(cd "$(dirname "$0")/.." && pwd)
out=${FUZZ_DIR:-$root/build-fuzz}
mkdir -p "$out/corpus"
cc=${CLANG:-clang}
# The library sources exactly as meson lists them (a file not in meson.build is not built).
srcs=""
for d in core expr mech scene; do
  for f in $(sed -n "s/^ *'\([A-Za-z0-9_]*\.c\)',\{0,1\}.*/\1/p" "$root/src/$d/meson.build"); do
    srcs="$srcs $root/src/$d/$f"
  done
done
# shellcheck disable=SC2086
"$cc" -std=c11 -D_POSIX_C_SOURCE=200809L -g -O1 -fno-omit-frame-pointer \
  -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined \
  -I"$root/include" -I"$root/src" -I/usr/include/suitesparse \
  "$root/tests/fuzz/fuzz_scene.c" $srcs \
  -linih -ljansson -lcholmod -lnlopt -llapack -lm -pthread -o "$out/fuzz_scene"
# shellcheck disable=SC2086
"$cc" -std=c11 -D_POSIX_C_SOURCE=200809L -g -O1 -fno-omit-frame-pointer \
  -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined \
  -I"$root/include" -I"$root/src" -I/usr/include/suitesparse \
  "$root/tests/fuzz/fuzz_table.c" $srcs \
  -linih -ljansson -lcholmod -lnlopt -llapack -lm -pthread -o "$out/fuzz_table"
cp "$root"/tests/scene/data/*.scene "$root"/tests/scene/bad/*.scene "$out/corpus/" 2>/dev/null || true
mkdir -p "$out/corpus_table"
cp "$root"/examples/scenes/*.csv "$out/corpus_table/" 2>/dev/null || true
cd "$out"
rc=0
./fuzz_scene -max_total_time="$secs" -timeout=10 -rss_limit_mb=2048 \
  -dict="$root/tests/fuzz/scene.dict" corpus || rc=1
./fuzz_table -max_total_time=$((secs / 3 + 1)) -timeout=10 -rss_limit_mb=2048 corpus_table || rc=1
# Output paths (devices, FIFOs, links, directories, the input scene) against the built
# command, for a third of the time: needs build/ (scripts/build.sh) or CALCVAR.
calcvar=${CALCVAR:-$root/build/src/cli/calcvar}
if [ -x "$calcvar" ]; then
  python3 "$root/tests/fuzz/fuzz_outpath.py" "$calcvar" "$root/tests/scene/data" \
    $((secs / 3 + 1)) || rc=1
  python3 "$root/tests/fuzz/fuzz_batch.py" "$calcvar" "$root/examples/scenes/catenary.scene" \
    $((secs / 3 + 1)) || rc=1
else
  echo "fuzz.sh: $calcvar not built: output-path fuzzing skipped"
fi
exit $rc

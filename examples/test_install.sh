#!/bin/sh
# examples/test_install.sh — `meson install` into a scratch DESTDIR, then build examples out
# of tree against the installed library through pkg-config, shared and static, and run them.
# SPDX-License-Identifier: MIT
#
# usage: test_install.sh BUILD_DIR SOURCE_DIR [EXTRA_CFLAGS]
# EXTRA_CFLAGS carries -fsanitize=... when the build is instrumented (the installed library
# then needs the sanitizer runtime in the program too).
set -eu
build=$1 src=$2 extra=${3:-}
cc=${CC:-cc}
dest=$(mktemp -d)
trap 'rm -rf "$dest"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

meson install -C "$build" --no-rebuild --destdir "$dest" >"$dest/install.log" 2>&1 ||
  { cat "$dest/install.log"; fail "meson install"; }

pc=$(find "$dest" -name calcvar.pc | head -n 1)
[ -n "$pc" ] || fail "no calcvar.pc installed"
hdr=$(find "$dest" -name calcvar.h | head -n 1)
exe=$(find "$dest" -path '*/bin/calcvar' | head -n 1)
man=$(find "$dest" -path '*/man1/calcvar.1*' | head -n 1)
shared=$(find "$dest" -name 'libcalcvar.so*' | head -n 1)
static=$(find "$dest" -name libcalcvar.a | head -n 1)
for f in "$hdr" "$exe" "$man" "$shared" "$static"; do [ -n "$f" ] || fail "missing file"; done
echo "installed: ${pc#"$dest"} ${hdr#"$dest"} ${exe#"$dest"} ${man#"$dest"}"
libdir=${shared%/*}
echo "           ${libdir#"$dest"}/libcalcvar.so, libcalcvar.a (DESTDIR $dest)"

# pkg-config sees the staged tree as the system root: -I and -L point into $dest.
export PKG_CONFIG_PATH="${pc%/*}" PKG_CONFIG_SYSROOT_DIR="$dest"
version=$(pkg-config --modversion calcvar) || fail "pkg-config cannot read calcvar.pc"
cflags=$(pkg-config --cflags calcvar)
libs=$(pkg-config --libs calcvar)
libs_static=$(pkg-config --static --libs calcvar)
echo "pkg-config: calcvar $version"
echo "  --cflags:        $cflags"
echo "  --libs:          $libs"
echo "  --static --libs: $libs_static"

for ex in ball catenary hanging_chain; do
  # Shared: the library found at run time through LD_LIBRARY_PATH (it is not installed).
  # shellcheck disable=SC2086
  $cc -std=c11 $extra -o "$dest/${ex}_shared" "$src/examples/$ex.c" $cflags $libs -lm ||
    fail "compiling $ex.c against the shared library"
  readelf -d "$dest/${ex}_shared" | grep -q 'NEEDED.*libcalcvar\.so' ||
    fail "${ex}_shared does not use libcalcvar.so"
  LD_LIBRARY_PATH="$libdir" "$dest/${ex}_shared" >"$dest/out" 2>&1 ||
    { cat "$dest/out"; fail "${ex}_shared did not check its answer"; }
  echo "shared  $ex: $(head -n 1 "$dest/out")"

  # Static libcalcvar.a: Libs.private must name everything it needs (CHOLMOD has no .pc
  # file on Debian 12, so -lcholmod comes from there). Its dependencies stay shared.
  static_libs=$(echo "$libs_static" | sed "s|-lcalcvar|$libdir/libcalcvar.a|")
  # shellcheck disable=SC2086
  $cc -std=c11 $extra -o "$dest/${ex}_static" "$src/examples/$ex.c" $cflags $static_libs -lm ||
    fail "compiling $ex.c against the static library with pkg-config --static"
  if readelf -d "$dest/${ex}_static" | grep -q 'NEEDED.*libcalcvar'; then
    fail "${ex}_static needs libcalcvar.so"
  fi
  "$dest/${ex}_static" >"$dest/out" 2>&1 ||
    { cat "$dest/out"; fail "${ex}_static did not check its answer"; }
  echo "static  $ex: $(head -n 1 "$dest/out")"
done

"$exe" --version >"$dest/out" 2>&1 || fail "installed calcvar --version"
"$exe" solve "$src/examples/scenes/catenary.scene" --quiet || fail "installed calcvar solve"
echo "installed command: $(cat "$dest/out"); solves examples/scenes/catenary.scene"

# The Python module: installed into site-packages (when meson found a Python with numpy),
# importable from the staged tree with the staged library, and solving.
pymod=$(find "$dest" -path '*/calcvar/__init__.py' | head -n 1)
py=""
for p in python3 /usr/bin/python3; do
  if command -v "$p" >/dev/null 2>&1 && "$p" -c 'import numpy' 2>/dev/null; then py=$p; fi
done
if [ -n "$py" ]; then
  [ -n "$pymod" ] || fail "the Python module was not installed"
  [ -f "${pymod%/*}/_config.py" ] || fail "the Python module's _config.py was not installed"
  if [ -z "$extra" ]; then  # an instrumented library cannot load into a plain interpreter
    PYTHONPATH="${pymod%/calcvar/*}" CALCVAR_LIB="$shared" "$py" -c '
import sys, calcvar
s = calcvar.solve(sys.argv[1])
assert s.success and s.report["error"]["max_nodal"] < 1e-10, s.message
print("python  calcvar %s from %s: %s" % (calcvar.version(), calcvar.__file__, s.status))
' "$src/examples/scenes/catenary.scene" || fail "the installed Python module"
  fi
  echo "python module: ${pymod#"$dest"}"
fi

#!/usr/bin/env bash
# ctest api_install_embed: install into a temporary prefix, build examples/embed against it with
# CMake (find_package(plumb)) and with pkg-config (plumb.pc), run both.
# Usage: install_embed_test.sh CMAKE BUILD_DIR EXAMPLE_DIR WORK_DIR CXX
set -euo pipefail
cmake_bin="$1"; build="$2"; example="$3"; work="$4"; cxx="$5"
rm -rf "$work"
mkdir -p "$work"
prefix="$work/prefix"
"$cmake_bin" --install "$build" --prefix "$prefix" > "$work/install.log"
for f in include/plumb/odometry.h lib/cmake/plumb/plumbConfig.cmake lib/pkgconfig/plumb.pc lib/libplumb_api.a; do
  found=$(cd "$prefix" && ls $f 2>/dev/null || ls ${f/lib\//lib/*/} 2>/dev/null || true)
  [ -n "$found" ] || { echo "FAILED: $f not installed under $prefix"; exit 1; }
done
launcher=()
if command -v ccache >/dev/null 2>&1; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
"$cmake_bin" -S "$example" -B "$work/build" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_CXX_COMPILER="$cxx" \
  "${launcher[@]}" > "$work/configure.log"
"$cmake_bin" --build "$work/build" -j2 > "$work/build.log"
echo "== examples/embed built with find_package(plumb):"
"$work/build/plumb_embed"
if command -v pkg-config >/dev/null 2>&1; then
  pcdir=$(dirname "$(find "$prefix" -name plumb.pc | head -1)")
  flags=$(PKG_CONFIG_PATH="$pcdir" pkg-config --cflags --libs plumb)
  # shellcheck disable=SC2086
  "$cxx" -O1 "$example/main.cpp" -o "$work/plumb_embed_pc" $flags
  echo "== examples/embed built with pkg-config plumb:"
  "$work/plumb_embed_pc"
fi

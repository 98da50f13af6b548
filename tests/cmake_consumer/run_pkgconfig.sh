#!/usr/bin/env bash
# ctest: build the consumer programs with plain compiler commands and
# `pkg-config --cflags --libs curvetet` against the installed PREFIX; run them.
# usage: run_pkgconfig.sh PREFIX LIBDIR SOURCE_DIR DATA_DIR WORK CC CXX VERSION
set -euo pipefail
prefix=$1 libdir=$2 src=$3 data=$4 work=$5 cc=$6 cxx=$7 version=$8
rm -rf "$work" && mkdir -p "$work"
export PKG_CONFIG_PATH="$prefix/$libdir/pkgconfig"
unset PKG_CONFIG_LIBDIR PKG_CONFIG_SYSROOT_DIR

got=$(pkg-config --modversion curvetet)
[ "$got" = "$version" ] || { echo "pkg-config version $got, expected $version" >&2; exit 1; }
pkg-config --exists --print-errors "curvetet >= $version"

flags=$(pkg-config --cflags --libs curvetet)
rpath="-Wl,-rpath,$(pkg-config --variable=libdir curvetet)"
echo "pkg-config --cflags --libs curvetet: $flags"
# shellcheck disable=SC2086
"$cc" -std=c11 -Wall -Wextra -Werror "$src/mesh_surface.c" -o "$work/mesh_surface" $flags "$rpath"
# shellcheck disable=SC2086
"$cxx" -std=c++17 -Wall -Wextra -Werror "$src/mesh_arrays.cpp" -o "$work/mesh_arrays" $flags "$rpath"

# Static: the archive plus Libs.private (pkg-config --static).
private=$(pkg-config --libs-only-l --static curvetet | sed 's/-lcurvetet\b//')
echo "static link with: $private"
# shellcheck disable=SC2086
"$cc" -std=c11 "$src/mesh_surface.c" -o "$work/mesh_surface_static" \
  $(pkg-config --cflags curvetet) "$(pkg-config --variable=libdir curvetet)/libcurvetet.a" $private

"$work/mesh_surface" "$data/sphere_p2.msh" "$work/a.msh"
"$work/mesh_surface_static" "$data/sphere_p2.msh" "$work/b.mesh"
"$work/mesh_arrays" "$data/sphere_p2.msh"
test -s "$work/a.msh" && test -s "$work/b.mesh"
echo "pkg-config consumer: OK"

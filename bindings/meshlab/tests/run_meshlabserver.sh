#!/usr/bin/env bash
# The MeshLab plugin's tests: a private copy of meshlabserver (so MeshLab's plugin folder,
# <exe dir>/../lib/<multiarch>/meshlab/plugins, can hold our plugin without writing to
# /usr) runs under xvfb-run (meshlabserver needs an X display for its GL context).
#
#   run_meshlabserver.sh dump WORK            meshlabserver -d lists the filter
#   run_meshlabserver.sh mesh WORK IN_LIN.OFF an .mlx script meshes the surface
#   run_meshlabserver.sh open WORK CLOSED.OFF an open surface (one facet dropped) fails cleanly
#   run_meshlabserver.sh smooth WORK RAW.OFF  smoothIterations 10 meshes a marching-cubes surface
#   run_meshlabserver.sh readme WORK IN.OFF   docs/meshlab.md's .mlx example ($README) runs
#
# Environment (set by CMakeLists.txt): MESHLABSERVER, XVFB_RUN, PLUGIN, CURVETET_CLI, PYTHON,
# TESTS_DIR, LIBCURVETET (the shared library);
# MESHLAB_LIBDIR (default: the folder of MeshLab's libmeshlab-common.so).
set -euo pipefail
mode=$1 work=$2 input=${3:-}
fail() { echo "FAIL: $*" >&2; exit 1; }

rm -rf "$work"
mkdir -p "$work"
work=$(cd "$work" && pwd)

# The private MeshLab: a copy of meshlabserver, symlinks to MeshLab's library and plugins
# and ours. meshlabserver's RUNPATH ($ORIGIN/../lib/<multiarch>/meshlab) finds the library.
libdir=${MESHLAB_LIBDIR:-$(dirname "$(ldd "$MESHLABSERVER" | awk '/libmeshlab-common/ {print $3}')")}
[ -f "$libdir/libmeshlab-common.so" ] || fail "no libmeshlab-common.so in '$libdir'"
libdir=$(readlink -f "$libdir") # ldd says /usr/bin/../lib/...
rel=${libdir#/usr/}
root=$work/meshlab
mkdir -p "$root/bin" "$root/$rel/plugins"
cp "$MESHLABSERVER" "$root/bin/meshlabserver"
ln -s "$libdir/libmeshlab-common.so" "$root/$rel/"
for p in "$libdir"/plugins/*.so; do
  ln -s "$p" "$root/$rel/plugins/"
done
ln -s "$PLUGIN" "$root/$rel/plugins/"
# The X authority file lives in $work: without -f, xvfb-run makes a temporary folder of its
# own and, when removing it fails, ends with its exit code 5 instead of meshlabserver's
# (seen once in CI, on the open-surface case).
server() {
  : >"$work/Xauthority"
  "$XVFB_RUN" -a -f "$work/Xauthority" -e "$work/xvfb.log" "$root/bin/meshlabserver" "$@"
}

filter='Tetrahedralize: curved quadratic (curvetet)'
write_mlx() { # write_mlx FILE OUTPUT...: the filter once per output file
  local file=$1
  shift
  {
    echo '<!DOCTYPE FilterScript>'
    echo '<FilterScript>'
    for out in "$@"; do
      cat <<MLX
 <filter name="$filter">
  <Param type="RichFloat" name="alpha" value="1.5" description="Search radius factor"/>
  <Param type="RichFloat" name="featureAngle" value="40" description="Feature angle (degrees)"/>
  <Param type="RichInt" name="smoothIterations" value="${SMOOTH:-0}" description="Smoothing iterations"/>
  <Param type="RichBool" name="optimize" value="true" description="Optimize"/>
  <Param type="RichBool" name="thorough" value="false" description="Thorough"/>
  <Param type="RichSaveFile" name="outputFile" value="$out" ext=".msh" description="Output file (.msh or .vtu)"/>
 </filter>
MLX
    done
    echo '</FilterScript>'
  } >"$file"
}

case "$mode" in
dump)
  server -d "$work/dump.txt" >"$work/log.txt" 2>&1 || { cat "$work/log.txt" >&2; fail "meshlabserver -d"; }
  grep -F "$filter" "$work/dump.txt" || fail "the filter is not listed by meshlabserver -d"
  # Its section (up to the next filter's) lists the six parameters: type and label.
  sed -n "/\\\\section f[0-9]* $filter/,/^\\\\section/p" "$work/dump.txt" >"$work/section.txt"
  for row in "Float .*Search radius factor" "Float .*Feature angle (degrees)" \
             "Int .*Smoothing iterations" "Bool .*Optimize" "Bool .*Thorough" \
             "FileName .*Output file (.msh or .vtu)"; do
    grep -q "$row" "$work/section.txt" || fail "parameter '$row' not listed"
  done
  echo "meshlabserver -d lists '$filter' with its parameters"
  ;;
mesh)
  outs=("$work/out.msh")
  if [ "$(basename "$input")" = torus_lin.off ]; then outs+=("$work/out.vtu"); fi
  write_mlx "$work/script.mlx" "${outs[@]}"
  # The C ABI alone (capi_reference.py, ctypes) on the very surface the filter gets
  # (MeshLab's single-precision copy of the vertices, written exactly): the filter must do
  # what it does.
  "$PYTHON" "$TESTS_DIR/check_output.py" --layer-off "$input" "$work/layer.off"
  ref_rc=0
  "$PYTHON" "$TESTS_DIR/capi_reference.py" "$LIBCURVETET" "$work/layer.off" >"$work/ref.txt" 2>&1 ||
    ref_rc=$?
  start=$(date +%s)
  rc=0
  # -o ... -l x: save the last layer, the (last) cut view; the input stays the current layer.
  server -i "$input" -o "$work/cut.ply" -l x -s "$work/script.mlx" >"$work/log.txt" 2>&1 || rc=$?
  cat "$work/log.txt"
  echo "meshlabserver: exit code $rc, $(($(date +%s) - start)) s; the C ABI alone: $(head -n 1 "$work/ref.txt")"
  [ "$rc" = 0 ] || fail "meshlabserver exited with $rc"
  [ "$ref_rc" = 0 ] || { cat "$work/ref.txt"; fail "the C ABI failed where the filter succeeded"; }
  grep -q "quadratic tets" "$work/log.txt" || fail "no tet count in the log"
  grep -q "min scaled Jacobian" "$work/log.txt" || fail "no quality summary in the log"
  grep -q "max skewness" "$work/log.txt" || fail "no skewness in the log"
  for out in "${outs[@]}"; do
    [ -s "$out" ] || fail "$out not written"
    "$CURVETET_CLI" check --json "$out" >"$out.check.json" || fail "curvetet check $out"
  done
  "$PYTHON" "$TESTS_DIR/check_output.py" "$input" "$work/cut.ply" "${outs[@]}"
  ;;
open)
  # The closed surface less its last facet: an open surface.
  "$PYTHON" - "$input" "$work/open.off" <<'PY'
import sys
lines = [l for l in open(sys.argv[1]).read().split("\n") if l.strip() and not l.startswith("#")]
nv, nf = map(int, lines[1].split()[:2])
body = lines[2:2 + nv + nf - 1]
open(sys.argv[2], "w").write("OFF\n%d %d 0\n%s\n" % (nv, nf - 1, "\n".join(body)))
PY
  write_mlx "$work/script.mlx" "$work/out.msh"
  rc=0
  server -i "$work/open.off" -o "$work/cut.ply" -s "$work/script.mlx" >"$work/log.txt" 2>&1 || rc=$?
  cat "$work/log.txt"
  [ "$rc" != 0 ] || fail "meshlabserver succeeded on an open surface"
  # meshlabserver ends a failed script with exit(-1); a crash would be 128 + signal.
  [ "$rc" = 255 ] || fail "meshlabserver did not end with the failed script's exit code 255 but $rc"
  grep -q "curvetet: CURVETET_ERR_INVALID_SURFACE\|curvetet: .*INVALID_SURFACE" "$work/log.txt" ||
    fail "curvetet's error is not in the log"
  grep -q "(not-closed).*hole" "$work/log.txt" || fail "the message does not say the surface is open"
  grep -q "Problem with filter: $filter" "$work/log.txt" || fail "meshlabserver did not report the filter's failure"
  [ ! -e "$work/out.msh" ] || fail "an output file was written for a failed run"
  [ ! -e "$work/cut.ply" ] || fail "a layer was saved after a failed run"
  echo "open surface: the filter failed cleanly (meshlabserver exit code $rc)"
  ;;
smooth)
  # A raw marching-cubes surface (tests/data/mc_blob.off: 101 of its 2,316 triangles have
  # an aspect ratio above 10) with smoothIterations 10: it meshes, the log says it was
  # smoothed, and the volume mesh passes curvetet check.
  SMOOTH=10 write_mlx "$work/script.mlx" "$work/out.msh"
  rc=0
  server -i "$input" -o "$work/cut.ply" -l x -s "$work/script.mlx" >"$work/log.txt" 2>&1 || rc=$?
  cat "$work/log.txt"
  [ "$rc" = 0 ] || fail "meshlabserver exited with $rc"
  grep -q "10 Taubin smoothing iterations" "$work/log.txt" || fail "the log does not say it smoothed"
  grep -q "quadratic tets" "$work/log.txt" || fail "no tet count in the log"
  [ -s "$work/out.msh" ] || fail "out.msh not written"
  "$CURVETET_CLI" check "$work/out.msh" || fail "curvetet check out.msh"
  echo "raw marching-cubes surface: smoothed (10 iterations) and meshed"
  ;;
readme)
  # docs/meshlab.md's filter script, as printed there, on a surface: runs, and its volume mesh
  # passes curvetet check.
  "$PYTHON" - "$README" "$work/curvetet.mlx" <<'PY'
import sys
section = open(sys.argv[1]).read()  # docs/meshlab.md
open(sys.argv[2], "w").write(section.split("```xml\n", 1)[1].split("```", 1)[0])
PY
  rc=0
  (cd "$work" && server -i "$input" -o cut.ply -l x -s curvetet.mlx >log.txt 2>&1) || rc=$?
  cat "$work/log.txt"
  [ "$rc" = 0 ] || fail "meshlabserver with the README's script: exit code $rc"
  [ -s "$work/volume.msh" ] || fail "the README's script wrote no volume.msh"
  "$CURVETET_CLI" check "$work/volume.msh" || fail "curvetet check volume.msh"
  [ -s "$work/cut.ply" ] || fail "no cut layer saved"
  echo "the README's filter script meshes $(basename "$input")"
  ;;
*) fail "unknown mode $mode" ;;
esac

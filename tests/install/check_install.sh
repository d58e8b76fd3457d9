#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Installs the build into a fresh prefix and checks that the command, its data and the scenes land where
# a user expects them, and that the installed command runs from there.
set -euo pipefail
build_dir=$1
prefix=$(mktemp -d)
trap 'rm -rf "$prefix"' EXIT

cmake --install "$build_dir" --prefix "$prefix" > /dev/null
fail() { echo "install: $*" >&2; exit 1; }
[ -x "$prefix/bin/chromatrace" ] || fail "bin/chromatrace missing"
[ -x "$prefix/libexec/chromatrace/chromatrace-full" ] || fail "libexec/chromatrace/chromatrace-full missing"
[ -f "$prefix/share/chromatrace/data/cie1931_2deg_1nm.csv" ] || fail "share/chromatrace/data missing"
[ -f "$prefix/share/chromatrace/data/README.md" ] || fail "data README (sources, licences) missing"
[ -f "$prefix/share/chromatrace/scenes/paper/box.json" ] || fail "scenes missing"
[ -f "$prefix/share/doc/chromatrace/README.md" ] || fail "docs missing"
"$prefix/bin/chromatrace" --version | grep -q '^chromatrace ' || fail "installed command does not run"
# --help starts without the image libraries; a command handed to the full program finds it and loads them.
oiio_loaded() { LD_DEBUG=files "$prefix/bin/chromatrace" "$@" 2>&1 >/dev/null | grep 'libOpenImageIO.*link map' >/dev/null; }
! oiio_loaded --help || fail "installed chromatrace --help loads OpenImageIO"
oiio_loaded render --help || fail "installed chromatrace render --help does not reach the full program"
"$prefix/bin/chromatrace" check-scene --quiet "$prefix/share/chromatrace/scenes/paper/box.json" \
  || fail "installed scene does not validate"
# `paper` runs the series installed with the command, not one in a source tree.
"$prefix/bin/chromatrace" paper -o "$prefix/paper" --variant 2-object-spectra --resolution 8x8 --spp 1 --quiet > /dev/null \
  || fail "installed paper command does not run"
grep -q "\"source\": \"$prefix/share/chromatrace/scenes/paper/series.json\"" "$prefix/paper/series.json" \
  || fail "installed paper command does not use the installed series"
addon="$prefix/share/chromatrace/blender_addon"
[ -f "$addon/chromatrace/__init__.py" ] && [ -f "$addon/batch.py" ] || fail "Blender add-on missing"
[ ! -d "$addon/chromatrace/__pycache__" ] || fail "Blender add-on installed with __pycache__"
( cd / && env -u CHROMATRACE_EXE PATH=/usr/bin:/bin python3 -c "import sys; sys.path.insert(0, '$addon'); \
  from chromatrace import spectra, tool; assert tool.find_executable() == '$prefix/bin/chromatrace', tool.find_executable(); \
  assert 'cornell_box.csv:red' in spectra.library_entries()" ) || fail "installed add-on does not find bin/chromatrace or the spectra"
# The Python module, where it was built: the package beside its extension, importable from the prefix.
if [ -n "${CHROMATRACE_PYTHON:-}" ]; then
  module=$(find "$prefix/lib" -path '*-packages/chromatrace/__init__.py' | head -1)
  [ -n "$module" ] && ls "$(dirname "$module")"/_chromatrace*.so > /dev/null || fail "Python module chromatrace missing"
  ( cd / && PYTHONPATH="$(dirname "$(dirname "$module")")" PYTHONDONTWRITEBYTECODE=1 "$CHROMATRACE_PYTHON" -c "import chromatrace, numpy;     a = chromatrace.analyze(numpy.full((8, 8, 3), 0.5, numpy.float32)); assert a.regions[0]['pixels'] == 64" )     || fail "installed Python module does not import or run"
fi
echo "install: ok"

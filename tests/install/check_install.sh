#!/usr/bin/env bash
# Installs the build into a fresh prefix and checks that the command, its data and the scenes land where
# a user expects them, and that the installed command runs from there.
set -euo pipefail
build_dir=$1
prefix=$(mktemp -d)
trap 'rm -rf "$prefix"' EXIT

cmake --install "$build_dir" --prefix "$prefix" > /dev/null
fail() { echo "install: $*" >&2; exit 1; }
[ -x "$prefix/bin/chromatrace" ] || fail "bin/chromatrace missing"
[ -f "$prefix/share/chromatrace/data/cie1931_2deg_1nm.csv" ] || fail "share/chromatrace/data missing"
[ -f "$prefix/share/chromatrace/data/README.md" ] || fail "data README (sources, licences) missing"
[ -f "$prefix/share/chromatrace/scenes/paper/box.json" ] || fail "scenes missing"
[ -f "$prefix/share/doc/chromatrace/README.md" ] || fail "docs missing"
"$prefix/bin/chromatrace" --version | grep -q '^chromatrace ' || fail "installed command does not run"
"$prefix/bin/chromatrace" check-scene --quiet "$prefix/share/chromatrace/scenes/paper/box.json" \
  || fail "installed scene does not validate"
echo "install: ok"

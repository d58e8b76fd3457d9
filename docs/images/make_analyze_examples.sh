#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Makes the pictures of docs/analyze.md: one plot per histogram class from the synthetic test images
# (tests/analyzer/synthetic.h), plots of the synthetic scene coloured by density and by component, and a
# screenshot of report.html in headless Chromium (through the browser test, tests/browser).
# Usage: docs/images/make_analyze_examples.sh [build-dir]
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$root/build}
images=$root/docs/images
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$build/tests/analyzer_synthetic_images" "$tmp"
for class in linear L skewed-T P curved clipped gamma thickened fork thickened-line; do
  "$build/cli/chromatrace" analyze "$tmp/$class.exr" -o "$tmp/$class" --no-report --quiet
  cp "$tmp/$class/plots/region-00.png" "$images/analyze_$class.png"
done
for class in superposed mixed; do  # object 1 of a file with light-group layers, or with object ids
  "$build/cli/chromatrace" analyze "$tmp/$class.exr" -o "$tmp/$class" --no-report --quiet
  cp "$tmp/$class/plots/region-01.png" "$images/analyze_$class.png"
done
"$build/cli/chromatrace" analyze "$tmp/scene.exr" -o "$tmp/scene" --no-report --quiet
cp "$tmp/scene/plots/region-01-components.png" "$images/analyze_scene_components.png"
cp "$tmp/scene/plots/region-04-density.png" "$images/analyze_scene_density.png"
CHROMATRACE_EXE="$build/cli/chromatrace" CHROMATRACE_SYNTHETIC_IMAGES="$build/tests/analyzer_synthetic_images" \
  CHROMATRACE_SCREENSHOT="$images/analyze_report.png" node --test "$root/tests/browser/report.test.mjs" > /dev/null

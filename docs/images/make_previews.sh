#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Renders the preview images of docs/render.md: the paper box and the Cornell box at 256×256.
# Usage: docs/images/make_previews.sh [build-dir]   (needs oiiotool from openimageio-tools)
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$root/build}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
preview() {  # scene, output png, scale of the linear RGB preview before sRGB encoding
  "$build/cli/chromatrace" render "$root/$1" -o "$tmp/render.exr" --spp 256 --components none --quiet
  oiiotool "$tmp/render.exr" --ch R,G,B --mulc "$3" --colorconvert linear sRGB -d uint8 -o "$root/docs/images/$2"
}
preview scenes/paper/box.json paper_box.png 0.04
preview scenes/cornell_box/cornell_box.json cornell_box.png 0.02

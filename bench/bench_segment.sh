#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# analyze --segment on a 24-megapixel photograph: wall time, peak memory (max RSS) and output size, beside a
# baseline run in the same script on the same image: OpenCV's mean-shift filtering (build/bench/bench_meanshift),
# the core of the analyzer's former segmentation. Figures and their reading: bench/README.md.
#
#   bench/bench_segment.sh [BUILD_DIR] [PHOTO]
#
# The photograph: Blender's interior.exr (package blender-data, CC0) scaled to 6928 × 3464 (24.0 Mpixel) and
# saved as an 8-bit sRGB JPEG by oiiotool (openimageio-tools), the way a camera or phone stores a picture.
set -euo pipefail
build=${1:-build}
photo=${2:-/usr/share/blender/datafiles/studiolights/world/interior.exr}
exe="$build/cli/chromatrace"
[ -x "$exe" ] || { echo "bench_segment.sh: $exe not built" >&2; exit 2; }
[ -f "$photo" ] || { echo "bench_segment.sh: $photo: no such file (install blender-data or name a photo)" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# Exposure: the room at mid-grey, the window and lamps clipped, as a camera would have it.
oiiotool "$photo" --resize 6928x3464 --mulc 0.12 --colorconvert linear sRGB -d uint8 -o "$work/photo.jpg"
echo "image: $(oiiotool --info "$work/photo.jpg" | sed 's/^[^:]*: *//'), $(stat -c %s "$work/photo.jpg") bytes"
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | sed 's/.*: //'), load $(cut -d' ' -f1-3 /proc/loadavg)"

measure() {  # label, command…: prints seconds and peak memory of the whole process
  local label=$1
  shift
  /usr/bin/time -f "%e %M" -o "$work/time" "$@" > "$work/out.txt" 2>&1 || { cat "$work/out.txt" >&2; exit 1; }
  read -r seconds kb < "$work/time"
  printf '%-44s %8.1f s %8.0f MB\n' "$label" "$seconds" "$((kb / 1024))"
}

measure "analyze --segment (2 threads, all outputs)" "$exe" analyze "$work/photo.jpg" -o "$work/analysis" --segment --threads 2 -q
echo "  output: $(du -sb "$work/analysis" | cut -f1) bytes in $(find "$work/analysis" -type f | wc -l) files;" \
     "$(python3 -c "import json,sys; a=json.load(open(sys.argv[1])); s=a['segmentation']; print(sum(r['source']=='segment' for r in a['regions']), 'segments,', '%.1f %% unassigned' % (100*s['unassigned_fraction']))" "$work/analysis/analysis.json" 2>/dev/null || echo '')"
measure "analyze --segment --no-plots --no-report" "$exe" analyze "$work/photo.jpg" -o "$work/bare" --segment --threads 2 --no-plots --no-report
grep -o 'segmentation: .*' "$work/out.txt" | sed 's/^/  /'
measure "analyze, no --segment (the rest of the work)" "$exe" analyze "$work/photo.jpg" -o "$work/plain" --threads 2 -q
measure "baseline: pyrMeanShiftFiltering alone" "$build/bench/bench_meanshift" "$work/photo.jpg"
cat "$work/out.txt"

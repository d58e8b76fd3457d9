#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Makes docs/images/analyze_stilllife.png, the report of docs/analyze.md on the cut of ILM's StillLife photograph
# (tests/data/photos/StillLife-table.exr): analysed on its segments and the glazed bagel's mask (its outline in
# tests/data/photos/masks.json: an ellipse less the napkin over its lower edge), with the napkin's mean colour as the
# known light, the bagel's region picked, in headless Chromium.
# Usage: docs/images/make_stilllife_report.sh [build-dir]   (needs oiiotool from openimageio-tools, and chromium)
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$root/build}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# The bagel's mask: pixels whose centre lies in the ellipse (250, 163; 70, 43) and outside the napkin's band
# [170, 330] × [200, 210].
awk 'BEGIN {
  print "P2"; print "500 400"; print "255"
  for (y = 0; y < 400; ++y) {
    line = ""
    for (x = 0; x < 500; ++x) {
      cx = x + 0.5; cy = y + 0.5
      inside = ((cx - 250) / 70) ^ 2 + ((cy - 163) / 43) ^ 2 <= 1 && !(cx >= 170 && cx <= 330 && cy >= 200 && cy <= 210)
      line = line (x ? " " : "") (inside ? 255 : 0)
    }
    print line
  }
}' > "$tmp/bagel.pgm"
oiiotool "$tmp/bagel.pgm" -d uint8 -o "$tmp/bagel.png"
"$build/cli/chromatrace" analyze "$root/tests/data/photos/StillLife-table.exr" -o "$tmp/still" --segment \
  --mask "$tmp/bagel.png" --illuminant 0.4196,0.2404,0.0716 --quiet
cat > "$tmp/shot.mjs" <<JS
import { openOffline } from '$root/tests/browser/offline_page.mjs';
const problems = [];
const { context, page } = await openOffline('$tmp', { width: 1400, height: 900 }, problems);
await page.goto('file://$tmp/still/report.html');
await page.waitForFunction(() => document.body.dataset.ready === '1', null, { timeout: 30000 });
await page.click('#region-list button:has-text("mask bagel.png")');
await page.waitForTimeout(500);
await page.screenshot({ path: '$root/docs/images/analyze_stilllife.png', fullPage: true });
await context.close();
if (problems.length) { console.error(problems.join('\n')); process.exit(1); }
JS
(cd "$root" && node "$tmp/shot.mjs")

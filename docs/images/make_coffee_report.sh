#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Makes docs/images/analyze_coffee.png, the report of docs/analyze.md on skimage's coffee.png (Debian's
# python3-skimage; Rachel Michetti, CC0): analysed on its segments, the white cup's segment picked (the segment that
# holds the cup's body, pixel (300, 200)), in headless Chromium.
# Usage: docs/images/make_coffee_report.sh [build-dir]   (needs chromium and the npm packages of ./setup.sh)
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$root/build}
photo=/usr/lib/python3/dist-packages/skimage/data/coffee.png
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$build/cli/chromatrace" analyze "$photo" -o "$tmp/coffee" --segment --quiet
# The cup's segment: the label at (300, 200) in labels.png, read by oiiotool.
label=$(oiiotool "$tmp/coffee/labels.png" --cut 1x1+300+200 -d uint16 --printstats 2>/dev/null |
        sed -n 's/.*Max: *\([0-9.]*\).*/\1/p' | head -1)
label=$(python3 -c "print(round(float('$label') * 65535))")
cat > "$tmp/shot.mjs" <<JS
import { openOffline } from '$root/tests/browser/offline_page.mjs';
const problems = [];
const { context, page } = await openOffline('$tmp', { width: 1400, height: 900 }, problems);
await page.goto('file://$tmp/coffee/report.html');
await page.waitForFunction(() => document.body.dataset.ready === '1', null, { timeout: 30000 });
await page.click('#region-list button:text-matches("^segment $label —")');
await page.waitForTimeout(500);
await page.screenshot({ path: '$root/docs/images/analyze_coffee.png', fullPage: true });
console.log(await page.locator('#details').innerText());
await context.close();
if (problems.length) { console.error(problems.join('\n')); process.exit(1); }
JS
(cd "$root" && node "$tmp/shot.mjs")

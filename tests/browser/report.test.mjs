// SPDX-License-Identifier: Apache-2.0
// report.html in a real browser: Debian's Chromium, headless, driven by playwright-core.
//
// The test makes its own input (the synthetic scene of tests/analyzer/synthetic.h, written by
// analyzer_synthetic_images), runs `chromatrace analyze`, opens the report from file:// and checks that it
// loads without console errors, draws the histogram, switches regions on a click in the image, and
// highlights pixels for points selected in the histogram.
// Environment: CHROMATRACE_EXE, CHROMATRACE_SYNTHETIC_IMAGES (the two executables); optional
// CHROMATRACE_SCREENSHOT (where to save a screenshot, e.g. docs/images/analyze_report.png).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { openOffline } from './offline_page.mjs';

const work = fs.mkdtempSync(path.join(os.tmpdir(), 'chromatrace-report-'));
let context;
let page;
const problems = []; // console errors and uncaught exceptions

before(async () => {
  execFileSync(process.env.CHROMATRACE_SYNTHETIC_IMAGES, [work]);
  execFileSync(process.env.CHROMATRACE_EXE, ['analyze', path.join(work, 'scene.exr'), '-o', path.join(work, 'out'), '--quiet']);
  ({ context, page } = await openOffline(work, { width: 1280, height: 900 }, problems));
  await page.goto('file://' + path.join(work, 'out', 'report.html'));
  await page.waitForFunction(() => document.body.dataset.ready === '1', null, { timeout: 30000 });
});

after(async () => {
  await context?.close();
  fs.rmSync(work, { recursive: true, force: true });
});

const drawn = () => page.evaluate(() => Number(document.getElementById('histogram').dataset.pointsDrawn));
const shown = () => page.evaluate(() => Number(document.getElementById('histogram').dataset.region));

test('loads without console errors', () => {
  assert.deepEqual(problems, []);
});

test('draws the histogram', async () => {
  assert.ok((await drawn()) > 1000);
  // The WebGL canvas shows more than its background: count pixels that differ from it.
  const lit = await page.evaluate(() => {
    const source = document.querySelector('#histogram canvas');
    const copy = document.createElement('canvas');
    copy.width = source.width;
    copy.height = source.height;
    const c = copy.getContext('2d');
    c.drawImage(source, 0, 0);
    const pixels = c.getImageData(0, 0, copy.width, copy.height).data;
    let count = 0;
    for (let i = 0; i < pixels.length; i += 4) if (Math.abs(pixels[i] - 0x1c) + Math.abs(pixels[i + 1] - 0x1c) + Math.abs(pixels[i + 2] - 0x1c) > 30) ++count;
    return count;
  });
  assert.ok(lit > 500, `only ${lit} pixels drawn`);
});

test('selecting a region changes the points drawn', async () => {
  const before = await drawn();
  await page.click('#region-list button[data-region="0"]'); // the whole image
  assert.equal(await shown(), 0);
  assert.notEqual(await drawn(), before);
  // A click on the lower-right sphere (object 4) in the image selects it.
  const box = await page.locator('#overlay').boundingBox();
  await page.mouse.click(box.x + box.width * 0.75, box.y + box.height * 0.75);
  assert.equal(await shown(), 4);
  assert.ok((await drawn()) < before * 2);
});

test('selecting points in the histogram highlights their pixels', async () => {
  const box = await page.locator('#histogram canvas').boundingBox();
  await page.keyboard.down('Shift');
  const select = async (x0, x1) => {
    await page.mouse.move(box.x + box.width * x0, box.y + 2);
    await page.mouse.down();
    await page.mouse.move(box.x + box.width * x1, box.y + box.height - 2, { steps: 4 });
    await page.mouse.up();
    return page.evaluate(() => Number(document.getElementById('image-wrap').dataset.selectedPixels));
  };
  await page.keyboard.down('Shift');
  const all = await select(0.005, 0.995);
  const bright = await select(0.7, 0.995); // the right of the view: the bright end of the cluster
  await page.keyboard.up('Shift');
  assert.equal(all, await drawn()); // a rectangle over the whole view holds every point
  assert.ok(bright > 0 && bright < all, `${bright} of ${all} points selected`);
  if (process.env.CHROMATRACE_SCREENSHOT) await page.screenshot({ path: process.env.CHROMATRACE_SCREENSHOT });
  assert.deepEqual(problems, []);
});

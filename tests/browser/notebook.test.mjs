// SPDX-License-Identifier: Apache-2.0
// The Python module's notebook display in a real browser: docs/notebooks/chromatrace.ipynb executed and converted
// to HTML by Jupyter's nbconvert (its basic template: the outputs as a notebook front end shows them, with no page
// scripts of Jupyter's own), opened offline in Debian's Chromium. The analysis's output, analyze's report in a
// sandboxed frame, must load without console errors or network requests and draw its 3D histogram.
// Environment: CHROMATRACE_EXE, CHROMATRACE_PYTHON (with the module on PYTHONPATH); optional CHROMATRACE_SCREENSHOT
// (where to save a screenshot of the report's frame).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { openOffline } from './offline_page.mjs';

const source = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
const work = fs.mkdtempSync(path.join(os.tmpdir(), 'chromatrace-notebook-'));
let context;
let page;
let report;
const problems = [];

before(async () => {
  execFileSync(process.env.CHROMATRACE_PYTHON, ['-m', 'nbconvert', '--to', 'html', '--template', 'basic', '--execute',
    '--ExecutePreprocessor.timeout=600', '--output-dir', work, path.join(source, 'docs/notebooks/chromatrace.ipynb')],
  { stdio: ['ignore', 'ignore', 'pipe'], cwd: path.join(source, 'docs/notebooks') });
  ({ context, page } = await openOffline(work, { width: 1100, height: 900 }, problems));
  await page.goto('file://' + path.join(work, 'chromatrace.html'));
  const frame = await page.waitForSelector('iframe[srcdoc]');
  report = await frame.contentFrame();
  await report.waitForFunction(() => document.body.dataset.ready === '1', null, { timeout: 30000 });
});

after(async () => {
  await context?.close();
  fs.rmSync(work, { recursive: true, force: true });
});

test('the report loads in its frame, offline, without console errors', () => {
  assert.deepEqual(problems, []);
});

test('the report in the notebook draws the histogram and lists the segments', async () => {
  const drawn = await report.evaluate(() => Number(document.getElementById('histogram').dataset.pointsDrawn));
  assert.ok(drawn > 1000, `${drawn} points drawn`);
  const text = await report.evaluate(() => document.body.innerText);
  assert.match(text, /coffee\.png/);
  assert.match(text, /segment 1/);
  if (process.env.CHROMATRACE_SCREENSHOT) await (await page.$('iframe[srcdoc]')).screenshot({ path: process.env.CHROMATRACE_SCREENSHOT });
});

test('the plots the notebook draws are there', async () => {
  const images = await page.evaluate(() => [...document.querySelectorAll('img')].filter((i) => i.naturalWidth > 100).length);
  assert.ok(images >= 3, `${images} images`);  // the segment map, the camera's picture, the object's histogram plot
});

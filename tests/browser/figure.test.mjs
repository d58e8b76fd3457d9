// SPDX-License-Identifier: Apache-2.0
// The figure page of `chromatrace paper` (index.html) in a real browser: Debian's Chromium, headless, driven by
// playwright-core.
//
// The test runs the paper's series small (48 × 48 pixels, 8 paths per pixel), opens DIR/index.html from
// file:// and checks that it loads offline without console errors or network requests, that it holds the
// paper's eight panels (Figures 3 and 4, a–d) and the banana beyond the paper beside 3d (3e), each with its camera
// image and its two histogram plots loaded,
// that every link to a variant's report.html leads to a file that exists, and that figure3.png and
// figure4.png were written.
// Environment: CHROMATRACE_EXE (the executable); optional CHROMATRACE_SCREENSHOT (where to save a full-page
// screenshot, e.g. docs/images/series_figure.png) and CHROMATRACE_FIGURE_ARGS (extra arguments for
// `chromatrace paper`, e.g. "--resolution 128x128 --spp 64" for the documentation's screenshot).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { openOffline } from './offline_page.mjs';

const work = fs.mkdtempSync(path.join(os.tmpdir(), 'chromatrace-figure-'));
const out = path.join(work, 'paper');
let context;
let page;
const problems = []; // console errors and uncaught exceptions
const requests = []; // anything the page asked for beyond the file itself

before(async () => {
  const extra = (process.env.CHROMATRACE_FIGURE_ARGS ?? '--resolution 48x48 --spp 8').split(/\s+/).filter(Boolean);
  // Exit status 1 means some variant failed; the page must show that too, so it is not fatal here.
  try {
    execFileSync(process.env.CHROMATRACE_EXE, ['paper', '-o', out, ...extra, '--quiet'], { stdio: ['ignore', 'ignore', 'inherit'] });
  } catch (e) {
    if (e.status !== 1) throw e;
  }
  ({ context, page } = await openOffline(work, { width: 1900, height: 1200 }, problems));
  const index = 'file://' + path.join(out, 'index.html');
  page.on('request', (r) => r.url() !== index && !r.url().startsWith('data:') && requests.push(r.url()));
  await page.goto(index);
  await page.waitForLoadState('load');
});

after(async () => {
  await context?.close();
  fs.rmSync(work, { recursive: true, force: true });
});

test('loads offline without console errors or requests', () => {
  assert.deepEqual(problems, []);
  assert.deepEqual(requests, []);
});

test('holds the paper\'s eight panels and the banana beside 3d, each with its image and plots', async () => {
  const panels = await page.evaluate(() =>
    [...document.querySelectorAll('section.panel[data-panel]')].map((p) => ({
      panel: p.dataset.panel,
      variant: p.dataset.variant,
      caption: p.querySelector('h3.caption')?.textContent ?? '',
      camera: [...p.querySelectorAll('img.camera')].map((i) => i.complete && i.naturalWidth),
      plots: [...p.querySelectorAll('img.plot')].map((i) => i.complete && i.naturalWidth),
      findings: p.querySelectorAll('tr.finding').length,
      external: [...p.querySelectorAll('img')].filter((i) => !i.src.startsWith('data:image/png;base64,')).length,
    })));
  assert.deepEqual(panels.map((p) => p.panel), ['3a', '3b', '3c', '3d', '3e', '4a', '4b', '4c', '4d']);
  for (const p of panels) {
    assert.equal(p.camera.length, 1, `${p.panel}: one camera image`);
    assert.ok(p.camera[0] > 0, `${p.panel}: the camera image did not load`);
    assert.equal(p.plots.length, 2, `${p.panel}: an oblique view and a projection`);
    for (const w of p.plots) assert.ok(w > 0, `${p.panel}: a plot did not load`);
    assert.equal(p.external, 0, `${p.panel}: images must be data: URIs`);
    assert.ok(p.findings > 0, `${p.panel}: no expected vs found rows`);
    assert.match(p.caption, p.panel === '3e' ? /^\(e\) Beyond the paper: / : /^\([a-d]\) /);
  }
  // The paper's own captions, and 3-specular in both 3b and 4a.
  assert.equal(panels[0].caption, '(a) Diffusely reflecting surfaces under direct illumination');
  assert.equal(panels[8].caption, '(d) With clipping effect by over exposure');
  assert.equal(panels[1].variant, panels[5].variant);
});

test('links to every variant\'s report.html lead to files that exist', async () => {
  const links = await page.evaluate(() => [...document.querySelectorAll('a.report')].map((a) => a.href));
  const series = JSON.parse(fs.readFileSync(path.join(out, 'series.json'), 'utf8'));
  const ok = series.variants.filter((v) => v.ok);
  // One in each of the nine panels and one per successful variant in the table.
  assert.equal(links.length, 9 + ok.length);
  for (const link of links) {
    assert.ok(link.startsWith('file://'), link);
    assert.match(link, /\/analysis\/report\.html$/);
    assert.ok(fs.existsSync(fileURLToPath(link)), `${link} does not exist`);
  }
  const rows = await page.evaluate(() => new Set([...document.querySelectorAll('table.variants tr[data-variant]')].map((r) => r.dataset.variant)).size);
  assert.equal(rows, series.variants.length, 'the table lists every variant');
});

test('writes figure3.png and figure4.png', () => {
  for (const name of ['figure3.png', 'figure4.png']) {
    const bytes = fs.readFileSync(path.join(out, name));
    assert.equal(bytes.subarray(1, 4).toString(), 'PNG');
    assert.ok(bytes.readUInt32BE(16) > 1500, `${name} is too narrow for four panels`);
  }
  assert.deepEqual(fs.readdirSync(out).filter((f) => f.includes('.tmp')), [], 'no temporary files left');
});

test('screenshot', async () => {
  if (process.env.CHROMATRACE_SCREENSHOT) await page.screenshot({ path: process.env.CHROMATRACE_SCREENSHOT, fullPage: true });
  assert.deepEqual(problems, []);
});

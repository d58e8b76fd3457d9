// SPDX-License-Identifier: Apache-2.0
// Hostile names in report.html, in a real browser (Debian's Chromium, headless, playwright-core).
//
// Region names come from the file's header (chromatrace.objects), and the file's name from whoever sent it: a
// spectral EXR whose objects are named as HTML that runs script, under a file name that does too. The report must
// show every name as the text it is: no dialog opens, no element the names spelled is made, and each region's
// details show its name exactly as analysis.json has it, for every region clicked. ("<!--<script>" in the data would
// put the HTML parser in a state where the data's end is not seen, and the viewer would not load.)
//
// The same for the series figure page and the compare page (a scene whose objects, material, light and variant are
// named and described as HTML that runs script, a camera's curves under a folder so named), the study page (such a
// scene, under a file name so named), and the calibration datasheet (a monochrome camera's frames whose channel and
// EXIF date are so named).
// Environment: CHROMATRACE_EXE, CHROMATRACE_SYNTHETIC_IMAGES (the two executables).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { openOffline } from './offline_page.mjs';

const work = fs.mkdtempSync(path.join(os.tmpdir(), 'chromatrace-hostile-'));
const names = {
  1: 'floor<img src=x onerror=alert(1)>',
  2: '<script>alert(2)</script>',
  3: '"><svg onload=alert(3)>',
  4: "x' onmouseover='alert(4)' &amp; &lt;b&gt; <!--<script>",
};
const file = path.join(work, 'scene<img src=y onerror=alert(5)>.exr');
let context;
let page;
const problems = [];
let dialogs = 0;
let analysis;

before(async () => {
  execFileSync(process.env.CHROMATRACE_SYNTHETIC_IMAGES, [work]);
  execFileSync('oiiotool', ['--evaloff', path.join(work, 'scene.exr'), '--attrib:type=string', 'chromatrace.objects', JSON.stringify(names), '-o', file]);
  execFileSync(process.env.CHROMATRACE_EXE, ['analyze', file, '-o', path.join(work, 'out'), '--quiet']);
  analysis = JSON.parse(fs.readFileSync(path.join(work, 'out', 'analysis.json'), 'utf8'));
  ({ context, page } = await openOffline(work, { width: 1280, height: 900 }, problems));
  page.on('dialog', async (d) => {
    ++dialogs;
    await d.dismiss();
  });
  await page.goto('file://' + path.join(work, 'out', 'report.html'));
  await page.waitForFunction(() => document.body.dataset.ready === '1', null, { timeout: 30000 });
});

after(async () => {
  await context?.close();
  fs.rmSync(work, { recursive: true, force: true });
});

// No element that a hostile name spells: no script, svg or img but the report's own, nothing with an event handler.
const spelled = () =>
  page.evaluate(() => ({
    handlers: [...document.querySelectorAll('*')].filter((e) => [...e.attributes].some((a) => a.name.startsWith('on'))).length,
    // The analysis's data is JSON in a script element of type application/json, which never runs.
    scripts: [...document.querySelectorAll('script')].filter((s) => s.type !== 'application/json' && s.textContent.includes('alert(')).length,
    svgs: document.querySelectorAll('#details svg, #region-list svg').length,
    images: document.querySelectorAll('#details img, #region-list img, header img').length,
  }));

test('every hostile name reaches the analysis', () => {
  const regionNames = analysis.regions.map((r) => r.name).join('\n');
  for (const n of Object.values(names)) assert.ok(regionNames.includes(n), `${n} is not a region's name`);
});

test('every region shows its name as text, and no script runs', async () => {
  const buttons = await page.locator('#region-list button').count();
  assert.ok(buttons >= 5);
  for (let i = 0; i < buttons; ++i) {
    const button = page.locator('#region-list button').nth(i);
    const index = Number(await button.getAttribute('data-region'));
    await button.click();
    await button.hover();
    const heading = await page.locator('#details h2').textContent();
    assert.equal(heading, analysis.regions[index].name);
  }
  await page.locator('#details').hover();
  assert.deepEqual(await spelled(), { handlers: 0, scripts: 0, svgs: 0, images: 0 });
  assert.equal(dialogs, 0);
  // The file's name, shown as written.
  assert.ok((await page.locator('body').innerText()).includes('scene<img src=y onerror=alert(5)>.exr'));
  assert.deepEqual(problems, []);
});

// ---- the series figure page and the compare page ----------------------------------------------------------------
const hostile = {
  floor: 'floor<img src=x onerror=alert(11)>',
  ball: '<script>alert(12)</script>',
  lamp: 'lamp"><svg onload=alert(13)>',
  material: "wall'><img src=x onerror=alert(14)>",
  variant: 'v<b onmouseover=alert(15)>1',
  description: '<img src=y onerror=alert(16)> &amp;',
  folder: 'cam<img src=z onerror=alert(17)>',
};

async function openPage(file) {
  const pageProblems = [];
  const { context: c, page: p } = await openOffline(fs.mkdtempSync(path.join(work, 'profile-')), { width: 1280, height: 900 }, pageProblems);
  let opened = 0;
  p.on('dialog', async (d) => {
    ++opened;
    await d.dismiss();
  });
  await p.goto('file://' + file);
  await p.mouse.move(200, 200);
  await p.mouse.move(600, 500);
  const found = await p.evaluate(() => ({
    handlers: [...document.querySelectorAll('*')].filter((e) => [...e.attributes].some((a) => a.name.startsWith('on'))).length,
    scripts: [...document.querySelectorAll('script')].filter((s) => s.type !== 'application/json' && s.textContent.includes('alert(')).length,
    text: document.body.innerText,
  }));
  await c.close();
  return { found, opened, pageProblems };
}

test('the series figure page and the compare page show hostile names as text', async () => {
  const minimal = new URL('../data/scenes/minimal.json', import.meta.url);
  const scene = JSON.parse(fs.readFileSync(minimal, 'utf8'));
  scene.materials = { [hostile.material]: scene.materials.wall, plastic: scene.materials.plastic };
  scene.objects[0].name = hostile.floor;
  scene.objects[0].material = hostile.material;
  scene.objects[1].name = hostile.ball;
  scene.lights[0].name = hostile.lamp;
  scene.lights[0].group = 'lamp'; // a component's name is a plain word; the light's own name may be anything
  const sceneFile = path.join(work, 'hostile-scene.json');
  fs.writeFileSync(sceneFile, JSON.stringify(scene));
  const seriesFile = path.join(work, 'hostile-series.json');
  fs.writeFileSync(seriesFile, JSON.stringify({
    format: 'chromatrace-series/1', base: sceneFile,
    variants: [{ name: hostile.variant, description: hostile.description, patch: { render: { samples: 4 } } }],
  }));
  const exe = process.env.CHROMATRACE_EXE;
  execFileSync(exe, ['series', seriesFile, '-o', path.join(work, 'series'), '--resolution', '32x24', '--quiet']);
  execFileSync(exe, ['render', sceneFile, '-o', path.join(work, 'a.exr'), '--spp', '4', '--resolution', '32x24', '--quiet']);
  const folder = path.join(work, hostile.folder);
  fs.mkdirSync(folder);
  fs.writeFileSync(path.join(folder, 'c.csv'), 'wavelength_nm,r,g,b\n300,1,0.5,0.2\n900,1,0.5,0.2\n');
  execFileSync(exe, ['compare', path.join(work, 'a.exr'), path.join(work, 'a.exr'), '-o', path.join(work, 'compare'), '--camera',
    path.join(folder, 'c.csv')]);

  const series = await openPage(path.join(work, 'series', 'index.html'));
  assert.deepEqual([series.found.handlers, series.found.scripts, series.opened], [0, 0, 0]);
  for (const text of [hostile.variant, hostile.description]) assert.ok(series.found.text.includes(text), `${text} not shown`);
  assert.deepEqual(series.pageProblems, []);

  const compare = await openPage(path.join(work, 'compare', 'compare.html'));
  assert.deepEqual([compare.found.handlers, compare.found.scripts, compare.opened], [0, 0, 0]);
  for (const text of [hostile.floor, hostile.ball, hostile.folder]) assert.ok(compare.found.text.includes(text), `${text} not shown`);
  assert.deepEqual(compare.pageProblems, []);
});

test('the study page and the calibration datasheet show hostile names as text', async () => {
  const exe = process.env.CHROMATRACE_EXE;
  const scene = JSON.parse(fs.readFileSync(new URL('../data/scenes/minimal.json', import.meta.url), 'utf8'));
  scene.objects[0].name = hostile.floor;
  scene.objects[1].name = hostile.ball;
  const sceneFile = path.join(work, 'scene<img src=w onerror=alert(18)>.json');
  fs.writeFileSync(sceneFile, JSON.stringify(scene));
  execFileSync(exe, ['study', sceneFile, '-o', path.join(work, 'study'), '--resolution', '32x24', '--bands', '3', '--fitted', '1', '--samples', '4',
    '--bounces', '1', '--no-plan', '--reference-spp', '16', '--quiet']);
  const study = await openPage(path.join(work, 'study', 'index.html'));
  assert.deepEqual([study.found.handlers, study.found.scripts, study.opened], [0, 0, 0]);
  assert.ok(study.found.text.includes('scene<img src=w onerror=alert(18)>.json'));
  assert.deepEqual(study.pageProblems, []);

  // A photon-transfer series of a monochrome camera (the sensor simulator's green plane, as
  // docs/images/make_calibrate_report.sh makes the colour one), its channel and date named as HTML.
  const frames = path.join(work, 'frames');
  fs.mkdirSync(frames);
  execFileSync('oiiotool', ['--create', '64x64', '1', '--chnames', 'S0.550nm', '-d', 'float', '-o', path.join(frames, 'dark.exr')]);
  execFileSync('oiiotool', ['--create', '64x64', '1', '--chnames', 'S0.550nm', '-d', 'float', '--addc', '0.0098', '-o', path.join(frames, 'flat.exr')]);
  fs.writeFileSync(path.join(frames, 'camera.csv'), 'wavelength_nm,r,g,b\n300,1,1,1\n900,1,1,1\n');
  const channel = '<img src=v onerror=alert(19)>';
  const args = { flat: [], dark: [] };
  let seed = 1;
  for (const share of [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.94, 0.97, 1.0, 1.03, 1.3]) {
    for (const kind of ['flat', 'dark']) {
      for (const k of [0, 1]) {
        const config = path.join(frames, 'camera.json');
        fs.writeFileSync(config, JSON.stringify({
          optics: { f_number: 4, cos4: false }, exposure: { time_s: share }, pixel: { pitch_um: 5 },
          spectral_response: { camera: path.join(frames, 'camera.csv'), basis: 'photon', peak_qe: 0.6 },
          noise: { enabled: true, dark_current_e_per_s: 100, read_e: 5, seed: seed++ },
          full_well: { enabled: true, electrons: 20000 }, adc: { enabled: true, gain_dn_per_e: 0.25, black_level_dn: 100, bits: 16 },
          display: { enabled: false },
        }));
        const rgb = path.join(frames, `${share}-${kind}-${k}-rgb.exr`), mono = path.join(frames, `${share}-${kind}-${k}.exr`);
        execFileSync(exe, ['sensor', path.join(frames, `${kind}.exr`), '-o', rgb, '--config', config, '--quiet']);
        execFileSync('oiiotool', ['--evaloff', rgb, '--ch', 'G', '--chnames', channel, '--attrib:type=string', 'DateTime',
          '2026:11:29 <svg onload=alert(20)>', '-o', mono]);
        args[kind].push(mono);
      }
    }
  }
  execFileSync(exe, ['calibrate', '--flat', ...args.flat, '--dark', ...args.dark, '-o', path.join(work, 'settings.json'), '--report',
    path.join(work, 'datasheet'), '--photons-per-s', '33298', '--quiet']);
  const datasheet = await openPage(path.join(work, 'datasheet', 'index.html'));
  assert.deepEqual([datasheet.found.handlers, datasheet.found.scripts, datasheet.opened], [0, 0, 0]);
  for (const text of [channel, '2026:11:29 <svg onload=alert(20)>']) assert.ok(datasheet.found.text.includes(text), `${text} not shown`);
  assert.deepEqual(datasheet.pageProblems, []);
});

// SPDX-License-Identifier: Apache-2.0
// The report's viewer: the analysed image beside a rotatable 3D colour histogram, linked both ways.
//
// report.html (analyzer/report.cpp) holds the data as JSON in <script id="analysis-data"> and this file,
// bundled with three.js into one IIFE by esbuild at build time. Clicking a region in the image (or in the
// list) shows its histogram; shift-dragging a rectangle over the histogram highlights the pixels of the
// points inside it. State is mirrored in data-* attributes so that tests can read it:
//   body[data-ready]                  "1" once the first frame is drawn
//   #histogram[data-points-drawn]     points in the current histogram
//   #histogram[data-region]           index of the region shown
//   #image-wrap[data-selected-pixels] pixels highlighted by the last selection
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';

const data = JSON.parse(document.getElementById('analysis-data').textContent);

function decodeUint16(base64) {
  const bytes = Uint8Array.from(atob(base64), (c) => c.charCodeAt(0));
  return new Uint16Array(bytes.buffer);
}

function decodeUint8(base64) {
  return Uint8Array.from(atob(base64), (c) => c.charCodeAt(0));
}

const srgb = (v) => (v <= 0.0031308 ? 12.92 * v : 1.055 * Math.pow(v, 1 / 2.4) - 0.055);

// Per region: positions in the unit cube, pixel coordinates in the displayed image, optional component.
const regions = data.regions.map((r) => {
  const rgb = decodeUint16(r.points.rgb);
  const pix = decodeUint16(r.points.pixels);
  const component = r.points.component ? decodeUint8(r.points.component) : null;
  return { ...r, rgb, pix, component, count: pix.length / 2 };
});
const labels = decodeUint16(data.labels);

// ---- image pane ----------------------------------------------------------------------------------
const image = document.getElementById('image');
const overlay = document.getElementById('overlay');
const imageWrap = document.getElementById('image-wrap');
overlay.width = data.display.width;
overlay.height = data.display.height;
const overlayContext = overlay.getContext('2d');

function drawRegionOutline(index) {
  overlayContext.clearRect(0, 0, overlay.width, overlay.height);
  if (index === 0) return; // the whole image needs no outline
  const shade = overlayContext.createImageData(overlay.width, overlay.height);
  for (let p = 0; p < labels.length; ++p) {
    if (labels[p] !== index) continue;
    shade.data[p * 4 + 0] = 255;
    shade.data[p * 4 + 1] = 255;
    shade.data[p * 4 + 2] = 255;
    shade.data[p * 4 + 3] = 70;
  }
  overlayContext.putImageData(shade, 0, 0);
}

function highlightPixels(points) {
  drawRegionOutline(current);
  overlayContext.fillStyle = 'rgba(255, 0, 255, 0.9)';
  const region = regions[current];
  for (const i of points) overlayContext.fillRect(region.pix[2 * i] - 1, region.pix[2 * i + 1] - 1, 3, 3);
  imageWrap.dataset.selectedPixels = String(points.length);
}

overlay.addEventListener('click', (event) => {
  const box = overlay.getBoundingClientRect();
  const x = Math.floor(((event.clientX - box.left) / box.width) * overlay.width);
  const y = Math.floor(((event.clientY - box.top) / box.height) * overlay.height);
  if (x < 0 || y < 0 || x >= overlay.width || y >= overlay.height) return;
  showRegion(labels[y * overlay.width + x]);
});

// ---- region list and details ---------------------------------------------------------------------
const list = document.getElementById('region-list');
// Largest first, with pixel counts (ties keep the analysis order).
const bySize = regions.map((r, index) => [r, index]).sort((a, b) => (b[0].pixels ?? 0) - (a[0].pixels ?? 0) || a[1] - b[1]);
bySize.forEach(([r, index]) => {
  const button = document.createElement('button');
  button.textContent = `${r.name} — ${r.class} (${(r.pixels ?? 0).toLocaleString('en')} px)`;
  button.dataset.region = String(index);
  button.addEventListener('click', () => showRegion(index));
  list.appendChild(button);
});

const details = document.getElementById('details');
// Every text is the analysis's (region names come from the file, and may be anyone's): set as text, never as HTML.
function element(tag, text, className) {
  const e = document.createElement(tag);
  if (text !== undefined) e.textContent = text;
  if (className) e.className = className;
  return e;
}
function showDetails(r) {
  const ranges = r.ranges.map((lh, c) => `${'RGB'[c]} ${lh[0].toPrecision(4)} to ${lh[1].toPrecision(4)}`).join(', ');
  const table = element('table');
  for (const [k, v] of [['cube shown', `${ranges} (${data.unit})`], ...r.summary]) {
    const row = table.insertRow();
    row.appendChild(element('th', String(k)));
    row.appendChild(element('td', String(v)));
  }
  const light = r.class_as_stored ? ' in linear light' : '';
  const parts = [element('h2', r.name), element('p', `${r.class}${light}`, 'class')];
  if (r.class_as_stored) parts.push(element('p', `As stored (the file's curve not undone): ${r.class_as_stored}`));
  parts.push(element('p', r.reason), element('p', r.explanation ?? '', 'explanation'), table);
  details.replaceChildren(...parts);
}

// ---- histogram pane ------------------------------------------------------------------------------
const histogram = document.getElementById('histogram');
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(1);
histogram.appendChild(renderer.domElement);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0x1c1c1c);
const camera = new THREE.PerspectiveCamera(35, 1, 0.01, 100);
camera.up.set(0, 0, 1); // blue up: the cube stands on its red-green face
camera.position.set(3.02, -2.02, 1.82); // far enough back that the axes' names at the edges' ends stay in view
const controls = new OrbitControls(camera, renderer.domElement);
controls.target.set(0.5, 0.5, 0.5);
controls.update(); // aims the camera at the target
controls.addEventListener('change', render);

function segments(pairs, colour) {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.Float32BufferAttribute(pairs.flat(2), 3));
  return new THREE.LineSegments(geometry, new THREE.LineBasicMaterial({ color: colour }));
}

// The cube: edges from black in their channel's colour, the rest grey.
const corners = [...Array(8).keys()].map((b) => [b & 1, (b >> 1) & 1, (b >> 2) & 1]);
const edges = { grey: [], r: [], g: [], b: [] };
for (let a = 0; a < 8; ++a)
  for (let bit = 0; bit < 3; ++bit) {
    const b = a | (1 << bit);
    if (b !== a) (a === 0 ? edges['rgb'[bit]] : edges.grey).push([corners[a], corners[b]]);
  }
scene.add(segments(edges.grey, 0x5a5a5a), segments(edges.r, 0xff4040), segments(edges.g, 0x40e040), segments(edges.b, 0x4080ff));

// A text label facing the camera, `height` high in cube units.
function label(text, position, colour, height = 0.045) {
  const canvas = document.createElement('canvas');
  const context = canvas.getContext('2d');
  const font = '32px sans-serif';
  context.font = font;
  canvas.width = Math.ceil(context.measureText(text).width) + 8;
  canvas.height = 40;
  context.font = font;
  context.fillStyle = colour;
  context.textBaseline = 'middle';
  context.fillText(text, 4, 20);
  const material = new THREE.SpriteMaterial({ map: new THREE.CanvasTexture(canvas), depthTest: false, transparent: true });
  const sprite = new THREE.Sprite(material);
  sprite.scale.set((height * canvas.width) / canvas.height, height, 1);
  sprite.position.set(...position);
  return sprite;
}

// Tick values along each channel's edge from black (computed with the plots' ticks, analyzer/plots.h), and the
// channels' names with the unit of the values.
function axisLabels(r) {
  const group = new THREE.Group();
  const colours = ['#ff8080', '#80e080', '#80a0ff'];
  const away = [[0, -0.07, -0.04], [-0.07, 0, -0.04], [-0.07, -0.07, 0]];
  r.ticks.forEach((ticks, c) => {
    for (const [at, text] of ticks) {
      if (c > 0 && at < 0.08) continue; // black's own value is written once, on the red edge
      const position = away[c].slice();
      position[c] = at;
      group.add(label(text, position, '#bbbbbb'));
    }
    const end = away[c].map((v) => 2 * v);
    end[c] = 1.12;
    group.add(label(`${'RGB'[c]} (${data.unit})`, end, colours[c], 0.055));
  });
  return group;
}

let points = null;
let fits = null;
let axes = null;
let current = -1;
const colourMode = document.getElementById('colour-mode');
if (!regions.some((r) => r.component)) colourMode.querySelector('option[value=component]').remove();
colourMode.addEventListener('change', () => showRegion(current, true));

function componentColour(k) {
  const [b, g, r] = data.componentColours[k] || [128, 128, 128];
  return [r / 255, g / 255, b / 255];
}

function showRegion(index, force = false) {
  if (index === current && !force) return;
  current = index;
  const r = regions[index];
  if (points) scene.remove(points);
  if (fits) scene.remove(fits);
  if (axes) {
    scene.remove(axes);
    axes.traverse((o) => o.material && (o.material.map.dispose(), o.material.dispose()));
  }
  axes = axisLabels(r);
  scene.add(axes);
  const positions = new Float32Array(r.count * 3);
  const colours = new Float32Array(r.count * 3);
  for (let i = 0; i < r.count; ++i) {
    for (let c = 0; c < 3; ++c) positions[i * 3 + c] = r.rgb[i * 3 + c] / 65535;
    const colour =
      colourMode.value === 'component' && r.component
        ? componentColour(r.component[i])
        : [0, 1, 2].map((c) => (data.encodeSrgb ? srgb(positions[i * 3 + c]) : positions[i * 3 + c]));
    colours.set(colour, i * 3);
  }
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(positions, 3));
  geometry.setAttribute('color', new THREE.BufferAttribute(colours, 3));
  points = new THREE.Points(geometry, new THREE.PointsMaterial({ size: 2.5, sizeAttenuation: false, vertexColors: true }));
  scene.add(points);

  fits = new THREE.Group();
  for (const line of r.fits.lines) fits.add(segments([[line.from, line.to]], line.kind === 'highlight' ? 0xffdc00 : 0xffffff));
  if (r.fits.curve.length > 1) {
    const pairs = r.fits.curve.slice(1).map((p, i) => [r.fits.curve[i], p]);
    fits.add(segments(pairs, 0x00ffff));
  }
  if (r.fits.plane.length === 4) {
    const [a, b, c, d] = r.fits.plane;
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.Float32BufferAttribute([a, b, c, a, c, d].flat(), 3));
    fits.add(new THREE.Mesh(geometry, new THREE.MeshBasicMaterial({ color: 0xff00ff, transparent: true, opacity: 0.15, side: THREE.DoubleSide, depthWrite: false })));
  }
  scene.add(fits);

  histogram.dataset.pointsDrawn = String(r.count);
  histogram.dataset.region = String(index);
  for (const button of list.children) button.classList.toggle('current', Number(button.dataset.region) === index);
  imageWrap.dataset.selectedPixels = '0';
  drawRegionOutline(index);
  showDetails(r);
  render();
}

function resize() {
  const width = histogram.clientWidth;
  const height = histogram.clientHeight;
  renderer.setSize(width, height, false);
  renderer.domElement.style.width = `${width}px`;
  renderer.domElement.style.height = `${height}px`;
  camera.aspect = width / height;
  camera.updateProjectionMatrix();
  render();
}

function render() {
  renderer.render(scene, camera);
}

// ---- selecting points: shift-drag a rectangle over the histogram --------------------------------
const band = document.getElementById('selection');
let dragStart = null;
renderer.domElement.addEventListener('pointerdown', (event) => {
  if (!event.shiftKey) return;
  controls.enabled = false;
  dragStart = [event.offsetX, event.offsetY];
  Object.assign(band.style, { display: 'block', left: `${event.offsetX}px`, top: `${event.offsetY}px`, width: '0px', height: '0px' });
});
renderer.domElement.addEventListener('pointermove', (event) => {
  if (!dragStart) return;
  const [x0, y0] = dragStart;
  Object.assign(band.style, {
    left: `${Math.min(x0, event.offsetX)}px`,
    top: `${Math.min(y0, event.offsetY)}px`,
    width: `${Math.abs(event.offsetX - x0)}px`,
    height: `${Math.abs(event.offsetY - y0)}px`,
  });
});
window.addEventListener('pointerup', (event) => {
  if (!dragStart) return;
  const box = renderer.domElement.getBoundingClientRect();
  const [x0, y0] = dragStart;
  const x1 = event.clientX - box.left;
  const y1 = event.clientY - box.top;
  dragStart = null;
  controls.enabled = true;
  band.style.display = 'none';
  selectInRectangle(Math.min(x0, x1), Math.min(y0, y1), Math.max(x0, x1), Math.max(y0, y1), box.width, box.height);
});

function selectInRectangle(left, top, right, bottom, width, height) {
  const r = regions[current];
  const v = new THREE.Vector3();
  const chosen = [];
  for (let i = 0; i < r.count; ++i) {
    v.set(r.rgb[i * 3] / 65535, r.rgb[i * 3 + 1] / 65535, r.rgb[i * 3 + 2] / 65535).project(camera);
    const x = ((v.x + 1) / 2) * width;
    const y = ((1 - v.y) / 2) * height;
    if (x >= left && x <= right && y >= top && y <= bottom) chosen.push(i);
  }
  highlightPixels(chosen);
}

// ---- start ---------------------------------------------------------------------------------------
function start() {
  resize();
  showRegion(regions.length > 1 ? 1 : 0);
  window.addEventListener('resize', resize);
  document.body.dataset.ready = '1';
}
if (image.complete) start();
else image.addEventListener('load', start);

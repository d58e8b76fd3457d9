// SPDX-License-Identifier: Apache-2.0
// A page of ours in Debian's Chromium, headless, driven by playwright-core, that must work offline: console
// errors and uncaught exceptions are collected into `problems`, and any request other than file: and data:
// URLs is refused and counted as one.
import path from 'node:path';
import { chromium } from 'playwright-core';

// Returns { context, page }; the caller closes the context.
export async function openOffline(profileDir, viewport, problems) {
  const context = await chromium.launchPersistentContext(path.join(profileDir, 'profile'), {
    executablePath: '/usr/bin/chromium',
    headless: true,
    viewport,
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
      '--disable-component-update', '--disable-sync'],
  });
  const page = await context.newPage();
  page.on('console', (m) => m.type() === 'error' && problems.push(m.text()));
  page.on('pageerror', (e) => problems.push(e.message));
  await page.route(/^(?!file:|data:)/, (route) => {
    problems.push(`network request: ${route.request().url()}`);
    route.abort();
  });
  return { context, page };
}

// Writes a screenshot of a replay page at a given time (the README's
// picture: node screenshot.mjs out/match.html docs/replay.png 62.4 "corner SE").
// Usage: node screenshot.mjs PAGE.html OUT.png [SECONDS] [CAMERA]
import { resolve } from 'node:path';
import { pathToFileURL } from 'node:url';

import { launchChromium } from './chromium.mjs';

const [pagePath, out, seconds = '60', camera = 'corner SW'] = process.argv.slice(2);
const browser = await launchChromium();
const page = await browser.newPage({ viewport: { width: 1400, height: 940 } });
await page.goto(pathToFileURL(resolve(pagePath)).href);
await page.waitForFunction(() => window.simbotViewer && window.simbotViewer.ready === true);
await page.evaluate(([t, c]) => { window.simbotViewer.setCamera(c); window.simbotViewer.seek(t); },
  [Math.round(Number(seconds) * 9216000), camera]);
await page.screenshot({ path: out });
await browser.close();

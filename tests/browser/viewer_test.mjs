// The replay viewer in real Chromium (Debian's /usr/bin/chromium, driven by
// playwright-core): the page of a 180-s ICEMAN vs fig92 match must open
// without console errors, draw the robots where the trace puts them at
// three seek positions, advance time when playing, highlight the source
// line the trace gives, render every camera preset, and show the report of
// `simbot explain` in its Explain panel, have a legend listing every symbol
// the timeline draws, draw a trail per robot that its toggle hides and
// shows, and place the miss labels so that no two overlap. It measures and
// prints (never asserts) how long the page took to be ready: from
// navigation start to the page's 'simbot-ready' performance mark. It writes
// screenshots of the 2-D view, the 3-D view and the timeline.
//
// Usage: node viewer_test.mjs SIMBOT ICEMAN FIG92 OUTDIR
import { execFileSync } from 'node:child_process';
import { mkdirSync, readFileSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { pathToFileURL } from 'node:url';

import { launchChromium, watchConsole } from './chromium.mjs';


const [simbot, iceman, fig92, outArg] = process.argv.slice(2);
const out = resolve(outArg);
mkdirSync(out, { recursive: true });
const failures = [];
function check(ok, message) {
  if (!ok) {
    failures.push(message);
    console.log('FAIL: ' + message);
  }
}

// ---- the match, its trace and its page (seed 15, under the default
// profile's variation)
const tracePath = join(out, 'm180.jsonl');
const pagePath = join(out, 'm180.html');
execFileSync(simbot, ['match', iceman, fig92, '--seconds', '180', '--seed', '15', '--trace', tracePath,
  '--replay', pagePath], { stdio: ['ignore', 'ignore', 'inherit'] });
const samples = { A: [], B: [] };
for (const line of readFileSync(tracePath, 'utf8').split('\n')) {
  if (!line.includes('"type":"sample"')) continue;
  const r = JSON.parse(line);
  samples[r.robot].push(r);
}
check(samples.A.length === 3601 && samples.B.length === 3601, 'a sample every 50 ms for 180 s');
// The latest sample of a robot at or before tick t.
function sampleAt(robot, t) {
  let lo = 0, hi = samples[robot].length - 1;
  while (lo < hi) {
    const mid = (lo + hi + 1) >> 1;
    if (samples[robot][mid].t <= t) lo = mid; else hi = mid - 1;
  }
  return samples[robot][lo];
}

// ---- the browser: no network, software WebGL
const browser = await launchChromium();
const page = await browser.newPage({ viewport: { width: 1400, height: 1000 } });
const consoleProblems = [];
// Chromium's software GL reports a "GPU stall due to ReadPixels" when the
// test reads the 3-D canvas back (view3dStats): the test's doing, not the page's.
const readPixelsNote = /GL Driver Message \(OpenGL, Performance.*ReadPixels/;
watchConsole(page, consoleProblems, (type, text) => type === 'warning' && readPixelsNote.test(text));
const requests = [];
page.on('request', (r) => { if (!r.url().startsWith('file:') && !r.url().startsWith('data:')) requests.push(r.url()); });

const started = Date.now();
await page.goto(pathToFileURL(pagePath).href);
await page.waitForFunction(() => window.simbotViewer && window.simbotViewer.ready === true, null,
  { timeout: 60000 });
const openMs = Date.now() - started;
const readyMark = await page.evaluate(() => {
  const m = performance.getEntriesByName('simbot-ready');
  return m.length ? m[0].startTime : null;
});
check(readyMark !== null, "the page sets its 'simbot-ready' mark");
console.log(`viewer: the 180-s page (${(readFileSync(pagePath).length / 1e6).toFixed(1)} MB) ` +
  `was ready ${Math.round(readyMark)} ms after navigation start ('simbot-ready' mark; ` +
  `${openMs} ms as the test saw it)`);

// ---- robots where the trace puts them, at three seek positions (sample ticks)
const TPS = 9216000;
for (const seconds of [30, 95.05, 170]) {
  const tick = Math.round(seconds * TPS);
  await page.evaluate((t) => window.simbotViewer.seek(t), tick);
  check(await page.evaluate(() => window.simbotViewer.time()) === tick, `seek to ${seconds} s`);
  for (const robot of ['A', 'B']) {
    const want = sampleAt(robot, tick);
    check(want.t === tick, `a sample of ${robot} at ${seconds} s`);
    const drawn = await page.evaluate((r) => window.simbotViewer.pose(r), robot);
    const close = (a, b) => Math.abs(a - b) <= 1e-9;
    check(close(drawn.x_ft, want.x_ft) && close(drawn.y_ft, want.y_ft) &&
          close(drawn.heading_deg, want.heading_deg),
    `${robot} at ${seconds} s drawn at ${JSON.stringify(drawn)}, the trace says ` +
          `(${want.x_ft}, ${want.y_ft}, ${want.heading_deg})`);
  }
}

// ---- the highlighted source line of A is the line the trace gives
for (const seconds of [1.234, 42.5, 97.07, 150.01]) {
  const tick = Math.round(seconds * TPS);
  await page.evaluate((t) => window.simbotViewer.seek(t), tick);
  const want = sampleAt('A', tick).line;
  const shown = await page.evaluate(() => {
    const el = document.querySelector('#source-A .current');
    return el ? Number(el.getAttribute('data-line')) : null;
  });
  check(shown === want, `A's highlighted line at ${seconds} s is ${shown}, the trace says ${want}`);
  check(await page.evaluate(() => window.simbotViewer.currentLine('A')) === want,
    `currentLine('A') at ${seconds} s`);
}

// ---- play advances time
await page.evaluate((t) => window.simbotViewer.seek(t), 10 * TPS);
await page.evaluate(() => { window.simbotViewer.setSpeed(1); window.simbotViewer.play(); });
await page.waitForTimeout(700);
const played = await page.evaluate(() => {
  const v = window.simbotViewer;
  const playing = v.playing();
  v.pause();
  return { playing, t: v.time() };
});
check(played.playing, 'playing after play()');
check(played.t > 10 * TPS + 0.2 * TPS && played.t < 10 * TPS + 5 * TPS,
  `0.7 s of playback at 1x moved the cursor from 10 s to ${played.t / TPS} s`);

// ---- the Explain panel: the report of `simbot explain` on this trace, line for
// line, and a click on the longest stall seeks to where it starts
const explained = execFileSync(simbot, ['explain', tracePath], { encoding: 'utf8' });
const panelText = await page.evaluate(() =>
  [...document.querySelectorAll('#explain-body div')].map((d) => d.textContent.replace(/\u00a0/g, '')).join('\n') + '\n');
check(panelText === explained, 'the Explain panel shows what simbot explain prints');
check(/Stalls: the program running and seeing/.test(panelText), 'the Explain panel lists the stalls');
const longest = page.locator('#explain-body div.seek', { hasText: 'longest:' });
const stallStart = Number(/longest: A ([0-9.]+) s/.exec(panelText)[1]);
await longest.click();
const seekTo = await page.evaluate(() => window.simbotViewer.time());
check(Math.abs(seekTo / TPS - stallStart) < 0.001,
  `clicking the longest stall seeks to ${stallStart} s (cursor at ${seekTo / TPS} s)`);

// ---- the legend lists every symbol the timeline draws (whole match in view)
await page.evaluate((end) => { window.simbotViewer.setWindow(0, end); window.simbotViewer.seek(95 * 9216000); },
  180 * TPS);
const drawnSymbols = await page.evaluate(() => window.simbotViewer.timelineSymbols());
const legendSymbols = await page.evaluate(() =>
  [...document.querySelectorAll('#legend .legend-item')].filter((e) => e.getBoundingClientRect().width > 0)
    .map((e) => e.dataset.symbol));
check(drawnSymbols.length >= 8, `the timeline drew ${drawnSymbols.join(', ')}`);
for (const s of drawnSymbols) check(legendSymbols.includes(s), `the legend lists "${s}", which the timeline draws`);
await page.evaluate(() => window.simbotViewer.setWindow(85 * 9216000, 100 * 9216000));
const zoomed = await page.evaluate(() => window.simbotViewer.timelineSymbols());
for (const s of zoomed) check(legendSymbols.includes(s), `the legend lists "${s}" (zoomed in)`);

// ---- trails: a path per robot, hidden and shown again by the toggle
const trailsOn = await page.evaluate(() => window.simbotViewer.trails());
const fieldOn = await page.evaluate(() => document.getElementById('field2d').toDataURL());
check(trailsOn.length === 2 && trailsOn.every((t) => t.points > 1000),
  `a trail per robot at 95 s: ${JSON.stringify(trailsOn)}`);
await page.locator('#trails').uncheck();
const trailsOff = await page.evaluate(() => window.simbotViewer.trails());
const fieldOff = await page.evaluate(() => document.getElementById('field2d').toDataURL());
check(trailsOff.length === 0 && fieldOff !== fieldOn, 'the trails toggle hides the trails');
await page.locator('#trails').check();
check((await page.evaluate(() => window.simbotViewer.trails())).length === 2, 'the trails toggle shows them again');

// ---- no two miss labels overlap, wherever misses are on the field
const missTicks = [];
for (const line of readFileSync(tracePath, 'utf8').split('\n'))
  if (line.includes('"type":"ball_miss"')) missTicks.push(JSON.parse(line).t);
check(missTicks.length > 1, `misses to label (${missTicks.length})`);
let mostShown = 0;
for (const t of missTicks) {
  for (const at of [t, t + 1 * TPS, t + 3 * TPS]) {
    await page.evaluate((x) => window.simbotViewer.seek(x), at);
    const boxes = await page.evaluate(() => [...document.querySelectorAll('#field-labels .mark-label.miss')]
      .filter((e) => e.style.display !== 'none').map((e) => {
        const r = e.getBoundingClientRect();
        return { l: r.left, r: r.right, t: r.top, b: r.bottom, text: e.textContent };
      }));
    mostShown = Math.max(mostShown, boxes.length);
    for (let i = 0; i < boxes.length; ++i)
      for (let j = i + 1; j < boxes.length; ++j) {
        const a = boxes[i], b = boxes[j];
        check(!(a.l < b.r && b.l < a.r && a.t < b.b && b.t < a.b),
          `miss labels "${a.text}" and "${b.text}" overlap at ${at / TPS} s`);
      }
  }
}
check(mostShown >= 2, `at some time several miss labels are shown (at most ${mostShown})`);

// ---- every camera preset renders something; screenshots
await page.evaluate((t) => window.simbotViewer.seek(t), 95 * TPS);
const cameras = await page.evaluate(() => window.simbotViewer.cameras());
for (const name of ['overhead', 'corner SW', 'corner SE', 'corner NE', 'corner NW', 'A eye', 'B eye'])
  check(cameras.includes(name), `camera preset "${name}"`);
for (const name of cameras) {
  const stats = await page.evaluate((n) => { window.simbotViewer.setCamera(n); return window.simbotViewer.view3dStats(); }, name);
  check(stats.nonBackground > 0.01 * stats.width * stats.height,
    `camera "${name}" renders a non-empty view (${stats.nonBackground} of ${stats.width}x${stats.height} pixels)`);
  if (name === 'corner SW') await page.locator('#view3d').screenshot({ path: join(out, 'viewer-3d.png') });
}
await page.locator('#field2d').screenshot({ path: join(out, 'viewer-2d.png') });
await page.locator('#timeline').screenshot({ path: join(out, 'viewer-timeline.png') });
await page.screenshot({ path: join(out, 'viewer.png'), fullPage: true });

check(consoleProblems.length === 0, `console: ${consoleProblems.join(' | ')}`);
const caught = await page.evaluate(() => window.simbotViewer.errors);
check(caught.length === 0, `the viewer caught errors: ${caught.join(' | ')}`);
check(requests.length === 0, `the page made network requests: ${requests.join(' ')}`);
await browser.close();

console.log(`screenshots: ${join(out, 'viewer-2d.png')}, viewer-3d.png, viewer-timeline.png, viewer.png`);
if (failures.length) {
  console.log(`${failures.length} check(s) failed`);
  process.exit(1);
}
console.log('viewer_test: all checks passed');

// The replay page draws what the wider competition puts on the field
// (reports/viewer/js/course.js), in real Chromium: for ICEMAN vs fig92
// among scenarios/mines.toml's obstacles under se3015-1996, every obstacle
// record is drawn, each mine marked, and a pixel probe at each obstacle
// (t = 0, the robots elsewhere) finds its colour, and the 3-D view shows
// the mines; for ICEMAN with a disc launcher under se3015-1997w (its fire()
// writes 0x40, the launcher's bit 6; fig92 never does), a disc half-way through its flight is drawn
// where the test's own closed form puts it (x0 + vx tau (1 - e^{-s/tau}),
// from the disc_fire record), the legend names obstacles, mines and discs,
// the timeline marks the scatter shots and discs it draws, and every camera
// renders. The two decoy lights of scenarios/course-1996.toml are drawn
// from their deploy records' tick on, at their places.
//
// Usage: node course_test.mjs SIMBOT ICEMAN FIG92 SOURCE_DIR OUTDIR
import { execFileSync } from 'node:child_process';
import { mkdirSync, readFileSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { pathToFileURL } from 'node:url';

import { launchChromium, watchConsole } from './chromium.mjs';


const [simbot, iceman, fig92, sourceDir, outArg] = process.argv.slice(2);
const out = resolve(outArg);
mkdirSync(out, { recursive: true });
const failures = [];
function check(ok, message) {
  if (!ok) {
    failures.push(message);
    console.log('FAIL: ' + message);
  }
}
const TPS = 9216000;
const records = (path, type) => readFileSync(path, 'utf8').split('\n')
  .filter((l) => l.includes(`"type":"${type}"`)).map((l) => JSON.parse(l));

function runPair(name, a, b, args) {
  const trace = join(out, `${name}.jsonl`), page = join(out, `${name}.html`);
  execFileSync(simbot, ['match', a, b, ...args, '--trace', trace, '--replay', page],
    { stdio: ['ignore', 'ignore', 'inherit'], cwd: sourceDir });
  return { trace, page };
}
const run = (name, args) => runPair(name, iceman, fig92, args);
const mines = run('mines', ['--scenario', 'scenarios/mines.toml', '--rules', 'se3015-1996', '--seconds', '60']);
const decoys = run('decoys', ['--scenario', 'scenarios/course-1996.toml', '--seconds', '50']);
// programs/backer.dc sets a block down behind it and backs into it: one
// push of about 0.6 ft, ended by the wall.
const pushes = runPair('pushes', join(sourceDir, 'programs/backer.dc'), fig92,
  ['--hw', 'A=profiles/hardware/blocks.toml', '--seconds', '4']);
const discs = run('discs', ['--rules', 'se3015-1997w', '--hw', 'A=profiles/hardware/disc-launcher.toml',
  '--seconds', '60']);

const browser = await launchChromium();
const page = await browser.newPage({ viewport: { width: 1400, height: 1000 } });
const problems = [];
// The test's own read-backs (view3dStats, the probes' getImageData) make
// Chromium note their cost: the test's doing, not the page's.
const readPixelsNote = /GL Driver Message \(OpenGL, Performance.*ReadPixels|willReadFrequently/;
watchConsole(page, problems, (type, text) => type === 'warning' && readPixelsNote.test(text));

async function open(path) {
  await page.goto(pathToFileURL(path).href);
  await page.waitForFunction(() => window.simbotViewer && window.simbotViewer.ready === true, null,
    { timeout: 60000 });
}
// The 2-D canvas's colour at a field point (ft), and whether it is `hex`.
async function probe(x, y) {
  return page.evaluate(([fx, fy]) => {
    const p = window.simbotViewer.fieldPixelOf(fx, fy);
    const d = document.getElementById('field2d').getContext('2d')
      .getImageData(Math.round(p.x), Math.round(p.y), 1, 1).data;
    return [d[0], d[1], d[2]];
  }, [x, y]);
}
const rgb = (hex) => [1, 3, 5].map((k) => parseInt(hex.slice(k, k + 2), 16));
const near = (a, b) => a.every((v, k) => Math.abs(v - b[k]) <= 3);
const legend = () => page.evaluate(() => [...document.querySelectorAll('#legend .legend-item')]
  .map((e) => e.dataset.symbol));

// ---- obstacles and mines
await open(mines.page);
const obstacles = records(mines.trace, 'obstacle');
check(obstacles.length === 3 && obstacles.filter((o) => o.mine).length === 2,
  `scenarios/mines.toml: 3 obstacles, 2 of them mines (${obstacles.length})`);
await page.evaluate(() => window.simbotViewer.seek(0));
const drawn = await page.evaluate(() => window.simbotViewer.courseDrawn());
check(drawn.obstacles === obstacles.length && drawn.mines === 2,
  `the page drew ${drawn.obstacles} obstacles and ${drawn.mines} mines`);
for (const o of obstacles) {
  // Half a radius east of a mine's centre, off its white X; a box's centre.
  const x = o.kind === 'circle' ? o.x_ft + 0.5 * o.radius_ft : o.x_ft;
  const got = await probe(x, o.y_ft);
  const want = rgb(o.mine ? '#d04040' : '#8d7b68');
  check(near(got, want), `obstacle ${o.index} (${o.name}) at (${x}, ${o.y_ft}) drawn ${got}, want ${want}`);
}
const mineLegend = await legend();
for (const s of ['field:obstacle', 'field:mine'])
  check(mineLegend.includes(s), `the legend names "${s}"`);
const cameras = await page.evaluate(() => window.simbotViewer.cameras());
for (const name of cameras) {
  const stats = await page.evaluate((n) => { window.simbotViewer.setCamera(n); return window.simbotViewer.view3dStats(); }, name);
  check(stats.nonBackground > 0.01 * stats.width * stats.height, `camera "${name}" renders (mines)`);
}
// The overhead 3-D view shows the mines: more red pixels (the mines'
// #d04040, lit) than the same view, at t = 0 with the same start poses,
// of the disc run's field without them (both have the robots' beacons).
const redPixels = () => page.evaluate(() => {
  window.simbotViewer.setCamera('overhead');
  window.simbotViewer.seek(0);
  const gl = document.querySelector('#view3d canvas');
  const c = document.createElement('canvas');
  c.width = gl.width; c.height = gl.height;
  const ctx = c.getContext('2d', { willReadFrequently: true });
  ctx.drawImage(gl, 0, 0);
  const d = ctx.getImageData(0, 0, c.width, c.height).data;
  let n = 0;
  for (let k = 0; k < d.length; k += 4) if (d[k] > 120 && d[k + 1] < 90 && d[k + 2] < 90) ++n;
  return n;
});
const withObstacles = await redPixels();
await page.screenshot({ path: join(out, 'course-mines.png') });

// ---- decoy lights (scenarios/course-1996.toml: ICEMAN sets down two)
await open(decoys.page);
const deploys = records(decoys.trace, 'deploy');
check(deploys.length === 2 && deploys.every((d) => d.kind === 'decoy_light'), `two decoy lights set down (${deploys.length})`);
if (deploys.length) {
  const last = deploys[deploys.length - 1].t;
  await page.evaluate((t) => window.simbotViewer.seek(t - 1), deploys[0].t);
  check((await page.evaluate(() => window.simbotViewer.courseDrawn())).decoy_lights === 0, 'no decoy light before the first is set down');
  await page.evaluate((t) => window.simbotViewer.seek(t + 9216000), last);
  check((await page.evaluate(() => window.simbotViewer.courseDrawn())).decoy_lights === deploys.length, 'every decoy light drawn after');
  for (const d of deploys) {
    const got = await probe(d.x_ft, d.y_ft);
    check(near(got, rgb('#ff5050')), `decoy light ${d.number} at (${d.x_ft.toFixed(2)}, ${d.y_ft.toFixed(2)}) drawn ${got}`);
  }
  check((await legend()).includes('field:decoy_light'), 'the legend names decoy lights');
}

// ---- discs
await open(discs.page);
const fires = records(discs.trace, 'disc_fire');
const ends = records(discs.trace, 'disc_hit').concat(records(discs.trace, 'disc_miss'));
check(fires.length > 0, `ICEMAN's disc launcher fired (${fires.length} discs)`);
const course = await page.evaluate(() => window.simbotViewer.course());
check(course.discs === fires.length, `the page knows ${course.discs} discs, the trace ${fires.length}`);
const disc = fires[0];
const end = ends.filter((e) => e.robot === disc.robot && e.disc === disc.disc && e.t > disc.t)
  .sort((a, b) => a.t - b.t)[0];
check(end !== undefined, 'the first disc ends');
if (end) {
  const mid = Math.round((disc.t + end.t) / 2);
  const s = (mid - disc.t) / TPS, f = disc.drag_time_s * (1 - Math.exp(-s / disc.drag_time_s));
  const x = disc.x_ft + disc.vx_fps * f, y = disc.y_ft + disc.vy_fps * f;
  await page.evaluate((t) => window.simbotViewer.seek(t), mid);
  const d = await page.evaluate(() => window.simbotViewer.courseDrawn());
  check(d.discs >= 1, `a disc in flight drawn at ${mid / TPS} s (${d.discs})`);
  const got = await probe(x, y);
  check(near(got, rgb('#f5f0a0')), `the disc drawn at (${x.toFixed(3)}, ${y.toFixed(3)}) ft: ${got}`);
  await page.evaluate(() => window.simbotViewer.setCamera('corner SW'));
  await page.screenshot({ path: join(out, 'course-discs.png') });
  await page.evaluate(() => window.simbotViewer.seek(0));
}
const without = await redPixels();
check(withObstacles > without + 100, `the 3-D overhead view shows the mines: ${withObstacles} red pixels, ${without} without them`);
const discLegend = await legend();
check(discLegend.includes('field:disc'), 'the legend names discs');
await page.evaluate((e) => { window.simbotViewer.setWindow(0, e); window.simbotViewer.seek(30 * 9216000); }, 60 * TPS);
const symbols = await page.evaluate(() => window.simbotViewer.timelineSymbols());
const scatter = records(discs.trace, 'scatter_shot');
if (scatter.length) check(symbols.includes('scatter_shot'), `the timeline marks scatter shots (${scatter.length})`);
check(symbols.includes('disc_fire'), `the timeline marks discs fired: ${symbols.join(', ')}`);
for (const sym of symbols) check(discLegend.includes(sym), `the legend lists "${sym}"`);

// ---- a pushed block moves with its pusher (not at push_start and
// push_end only). The plant moves the block along the push by exactly the
// robot's displacement along it (docs/plant.md "Deployables"): at each of
// the pusher's samples inside the push the block must be at
// push_start's place + u ((sample - robot at push_start) . u), u the unit
// vector from the push_start place to the push_end one, all from the
// trace; so never back, and on the segment.
await open(pushes.page);
const pushStarts = records(pushes.trace, 'push_start'), pushEnds = records(pushes.trace, 'push_end');
check(pushStarts.length === 1 && pushEnds.length === 1, `backer: one push (${pushStarts.length}, ${pushEnds.length})`);
if (pushStarts.length === 1 && pushEnds.length === 1) {
  const s0 = pushStarts[0], s1 = pushEnds[0];
  const dx = s1.x_ft - s0.x_ft, dy = s1.y_ft - s0.y_ft, len = Math.hypot(dx, dy);
  check(len > 0.5, `the push moved the block ${len.toFixed(3)} ft`);
  const inside = records(pushes.trace, 'sample').filter((r) => r.robot === s0.robot && r.t > s0.t && r.t < s1.t);
  check(inside.length >= 10, `the pusher's samples inside the push: ${inside.length}`);
  const index = (await page.evaluate(() => window.simbotViewer.course())).deployables - 1;
  let last = 0, worst = 0;
  for (const r of inside) {
    const p = await page.evaluate(([i, t]) => window.simbotViewer.deployableAt(i, t), [index, r.t]);
    const expected = ((r.x_ft - s0.robot_x_ft) * dx + (r.y_ft - s0.robot_y_ft) * dy) / len;
    worst = Math.max(worst, Math.hypot(p.x - (s0.x_ft + expected * dx / len), p.y - (s0.y_ft + expected * dy / len)));
    const along = ((p.x - s0.x_ft) * dx + (p.y - s0.y_ft) * dy) / len;
    check(along >= last - 1e-9 && along <= len + 1e-9, `block at ${r.time_s.toFixed(3)} s: ${along.toFixed(4)} ft along, after ${last.toFixed(4)}`);
    last = along;
  }
  check(worst < 1e-9, `the block moves by the pusher's displacement along the push (off by ${worst} ft)`);
  const mid = inside[Math.floor(inside.length / 2)];
  const pm = await page.evaluate(([i, t]) => window.simbotViewer.deployableAt(i, t), [index, mid.t]);
  const done = ((pm.x - s0.x_ft) * dx + (pm.y - s0.y_ft) * dy) / len / len;
  check(done > 0.2 && done < 0.8, `half way through the push the block is ${(100 * done).toFixed(0)}% of the way`);
}

check(problems.length === 0, `console: ${problems.join(' | ')}`);
const caught = await page.evaluate(() => window.simbotViewer.errors);
check(caught.length === 0, `the viewer caught errors: ${caught.join(' | ')}`);
await browser.close();
if (failures.length) {
  console.log(`${failures.length} check(s) failed`);
  process.exit(1);
}
console.log('course_test: all checks passed');

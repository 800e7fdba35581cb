// simbot serve's pages in real Chromium (playwright-core), against the real
// server (`simbot serve`) on the loopback:
// - a team submits, through the /submit form, a program whose line 3 lacks
//   its ';': the page says nothing was kept and marks line 3 with the
//   compiler's "bad.dc:3:8: error: expected ';'" (the missing ';' is after
//   `int x`, column 8 of "  int x"), and the team has no version;
// - it submits ICEMAN through the form: kept as version 1, the course's
//   checks (checks/iceman.toml) shown with it, ICEMAN's known failure among
//   them ("no motor string overwritten" on seed 3, docs/check.md);
// - a second team (fig92, by the API) plays it in a scrimmage and the
//   instructor's round robin; the standings page lists both teams with
//   their games, and the hits it shows for each match equal those of the
//   same match played by `simbot match` directly (the server is not its
//   own oracle);
// - the match page shows `simbot explain`'s report, and its replay link
//   opens the replay viewer, which draws without an error.
// - the team's robot form shows each value with its unit, range and
//   source; a mass of 900 lb is refused with simbot's loader's own
//   FILE:LINE:COL error, 15 kg and a 95 ft/s gun are kept as a hardware
//   file of those two values, and the team's scrimmages are played with
//   it: each ends where `simbot match --hw A=that file` ends, not where the
//   course's robot does.
// Team names with markup are shown as text (no element made of them).
// Screenshots go to OUTDIR (the ones in docs/serve-*.png come from here).
//
// Usage: node server_test.mjs SIMBOT SOURCE_DIR SHARED_DIR OUTDIR
import { execFileSync, spawn } from 'node:child_process';
import { mkdirSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { createServer } from 'node:net';
import { join, resolve } from 'node:path';

import { launchChromium, watchConsole } from './chromium.mjs';


const [simbot, sourceDir, sharedDir, outArg] = process.argv.slice(2);
const out = resolve(outArg);
rmSync(out, { recursive: true, force: true });
mkdirSync(out, { recursive: true });
const failures = [];
function check(ok, message) {
  if (!ok) {
    failures.push(message);
    console.log('FAIL: ' + message);
  }
}
const SECONDS = 20; // the round robin's games; a scrimmage is the server's 180 s

const freePort = () => new Promise((done) => {
  const s = createServer();
  s.listen(0, '127.0.0.1', () => {
    const { port } = s.address();
    s.close(() => done(port));
  });
});
const port = await freePort();
const base = `http://127.0.0.1:${port}`;
const data = join(out, 'data');
const server = spawn(simbot, ['serve', '--data', data, '--port', String(port),
  '--house', join(sourceDir, 'programs'), '--checks', join(sourceDir, 'checks/iceman.toml')],
{ stdio: ['ignore', 'inherit', 'inherit'] });
let browser;
try {
  for (let i = 0; ; i++) {
    try {
      await fetch(`${base}/api/standings`);
      break;
    } catch {
      if (i > 150) throw new Error('simbot serve did not start');
      await new Promise((r) => setTimeout(r, 200));
    }
  }
  const instructor = readFileSync(join(data, 'instructor-token'), 'utf8').trim();
  const api = async (method, path, token, body) => {
    const r = await fetch(base + path, {
      method,
      headers: { Authorization: `Bearer ${token}`, 'Content-Type': 'application/json' },
      body: body === undefined ? undefined : JSON.stringify(body),
    });
    return { status: r.status, body: await r.json() };
  };
  const ice = (await api('POST', '/api/teams', instructor, { name: 'Ice<i>man</i>' })).body;
  const fig = (await api('POST', '/api/teams', instructor, { name: 'Fig 92' })).body;

  browser = await launchChromium();
  const page = await browser.newPage({ viewport: { width: 1200, height: 900 } });
  const problems = [];
  const readPixelsNote = /GL Driver Message \(OpenGL, Performance.*ReadPixels|willReadFrequently/;
  // The forms' answers to a program that does not compile and to a robot
  // the loader refuses are 422s, as the API's are.
  const expected422 = /status of 422 .*\/(submit|teams\/\d+\/robot)\)$/;
  watchConsole(page, problems, (type, text, url) => expected422.test(`${text} (${url})`) ||
    (type === 'warning' && readPixelsNote.test(text)));

  // ---- a program that does not compile, through the form
  const bad = join(out, 'bad.dc');
  writeFileSync(bad, 'main()\n{\n  int x\n  x = 1;\n}\n');
  await page.goto(`${base}/submit`);
  await page.fill('#token', ice.token);
  await page.setInputFiles('#program', bad);
  await Promise.all([page.waitForNavigation(), page.click('button[type=submit]')]);
  check(await page.locator('#compile-errors').count() === 1, 'the compile error is reported');
  check(await page.locator('tr#line-3.error').count() === 1, 'line 3 is marked as an error');
  const note = await page.locator('tr#line-3 + tr.note.error').textContent();
  check(note.includes("^ bad.dc:3:8: error: expected ';'"),
    `the error is shown under line 3 at column 8: ${JSON.stringify(note)}`);
  check(note.indexOf('^') === 7, `the caret stands under column 8: ${JSON.stringify(note)}`);
  await page.screenshot({ path: join(out, 'serve-compile-error.png'), fullPage: true });
  check((await (await fetch(`${base}/api/teams/${ice.id}`)).json()).versions.length === 0,
    'nothing was kept');

  // ---- ICEMAN through the form: kept, its checks shown
  await page.fill('#token', ice.token);
  await page.setInputFiles('#program', join(sharedDir, 'programs/iceman.dc'));
  await Promise.all([page.waitForNavigation(), page.click('button[type=submit]')]);
  check((await page.locator('#accepted').textContent()).includes('version 1'), 'ICEMAN kept as version 1');
  const failed = await page.locator('table.checks tr', { hasText: 'no motor string overwritten' })
    .filter({ hasText: 'failed' }).allTextContents();
  check(failed.length === 1 && /\b3\b/.test(failed[0]),
    `the course's checks shown, ICEMAN's overwritten send on seed 3 among them: ${failed}`);

  // ---- the team's robot: a value out of its range refused by simbot's
  // loader at its line and column (robot.toml line 2: "[robot]" then
  // "mass = { value = 900, ..."; column 18 is the value's, as simbot
  // match --hw says it), then a lighter robot with a slower gun kept
  await page.goto(`${base}/teams/${ice.id}/robot`);
  const massRow = await page.locator('tr#key-robot\\.mass').textContent();
  check(massRow.includes('35') && massRow.includes('0.5 to 500 lb') && massRow.includes("the competition limit"),
    `mass shown with its value, range and source: ${massRow.replace(/\s+/g, ' ')}`);
  await page.fill('[id="v.robot.mass"]', '900');
  await page.fill('#token', ice.token);
  await Promise.all([page.waitForNavigation(), page.click('button[value=save]')]);
  const refused = await page.locator('#problem').textContent();
  check(refused.includes("robot.toml:2:18: error: 'robot.mass' must be between 0.5 and 500 lb, got 900 lb"),
    `the loader's error: ${refused}`);
  await page.fill('[id="v.robot.mass"]', '15');
  await page.selectOption('[name="u.robot.mass"]', 'kg');
  await page.fill('[id="v.gun.muzzle_speed"]', '95');
  await page.fill('#token', ice.token);
  await Promise.all([page.waitForNavigation(), page.click('button[value=save]')]);
  check(await page.locator('#saved').count() === 1, 'the robot is saved');
  const hardware = await page.locator('#hardware').textContent();
  check(/mass = \{ value = 15\.0, unit = "kg"/.test(hardware) && /muzzle_speed = \{ value = 95\.0, unit = "ft\/s"/.test(hardware),
    `the hardware file holds what was changed, and only that: ${hardware}`);
  check(!/body_diameter/.test(hardware), 'values left as the course has them are not in it');
  await page.evaluate(() => document.getElementById('key-robot.motor_lag').scrollIntoView());
  await page.screenshot({ path: join(out, 'serve-robot.png') });
  const robotFile = join(out, 'robot.toml');
  writeFileSync(robotFile, hardware);

  // ---- fig92 by the API, a scrimmage and a round robin
  const form = new FormData();
  form.append('program', new Blob([readFileSync(join(sharedDir, 'programs/fig92.dc'))]), 'fig92.dc');
  const sent = await fetch(`${base}/api/submissions`,
    { method: 'POST', headers: { Authorization: `Bearer ${fig.token}` }, body: form });
  check(sent.status === 201, `fig92 submitted: ${sent.status}`);
  const scrimmage = (await api('POST', '/api/scrimmages', ice.token,
    { opponent: fig.id, seed: 4 })).body.match_id;
  const house = (await api('POST', '/api/scrimmages', ice.token,
    { opponent: 'house:turret', seed: 5 })).body.match_id;
  const tournament = (await api('POST', '/api/tournaments', instructor,
    { seconds: SECONDS, rounds: 2, seed: 11 })).body;
  check(tournament.games === 2, `a round robin of 2 teams, 2 rounds: 2 games (${tournament.games})`);
  for (let i = 0; ; i++) {
    const t = (await api('GET', `/api/tournaments/${tournament.id}`, instructor)).body;
    const m = await Promise.all([scrimmage, house].map(async (id) =>
      (await api('GET', `/api/matches/${id}`, instructor)).body.status));
    if (t.status === 'done' && m.every((s) => s === 'done')) break;
    if (i > 600) throw new Error('the matches did not finish in 120 s');
    await new Promise((r) => setTimeout(r, 200));
  }

  // ---- the standings page
  await page.goto(`${base}/`);
  const rows = await page.locator('table.standings tr').allTextContents();
  check(rows.length === 3 && rows.some((r) => r.includes('Ice<i>man</i>')) &&
    rows.some((r) => r.includes('Fig 92')), `both teams are in the standings: ${rows}`);
  check(await page.locator('i').count() === 0, 'a name with markup makes no element');
  // Each match's hits as the page shows them, against simbot match itself.
  const games = (await api('GET', `/api/tournaments/${tournament.id}`, instructor)).body;
  for (const id of [scrimmage, house]) {
    const m = (await api('GET', `/api/matches/${id}`, instructor)).body;
    const b = id === house ? join(sourceDir, 'programs/turret.dc') : join(sharedDir, 'programs/fig92.dc');
    // ICEMAN's robot is its team's: the scrimmages are played with its file.
    const direct = JSON.parse(execFileSync(simbot, ['match', join(sharedDir, 'programs/iceman.dc'), b,
      '--seed', String(m.seed), '--seconds', String(m.seconds), '--hw', `A=${robotFile}`, '--json'],
    { stdio: ['ignore', 'pipe', 'ignore'] }));
    const plain = JSON.parse(execFileSync(simbot, ['match', join(sharedDir, 'programs/iceman.dc'), b,
      '--seed', String(m.seed), '--seconds', String(m.seconds), '--json'], { stdio: ['ignore', 'pipe', 'ignore'] }));
    check(JSON.stringify(direct.robots[0].final_pose) !== JSON.stringify(plain.robots[0].final_pose),
      `the tailored robot plays another match than the course's (match ${id})`);
    check(JSON.stringify(m.result.robots[0].final_pose) === JSON.stringify(direct.robots[0].final_pose),
      `match ${id} ends where simbot match --hw puts ICEMAN: ${JSON.stringify(m.result.robots[0].final_pose)}`);
    const shown = (await page.locator(`table.matches tr:has(a[href="/matches/${id}"])`).textContent());
    const hits = direct.robots.map((r) => `${r.hits} hits`).join(' / ');
    check(shown.includes(hits) && shown.includes(direct.winner),
      `match ${id} shows ${hits}, winner ${direct.winner} as simbot match gives: ${shown}`);
  }
  check(games.table.length === 2 && games.games.done === 2, `the round robin's table: ${JSON.stringify(games)}`);
  await page.screenshot({ path: join(out, 'serve-standings.png'), fullPage: true });

  // ---- a match's page, its report and its replay
  await page.click(`a[href="/matches/${scrimmage}"]`);
  await page.waitForSelector('pre.report', { timeout: 120000 });
  const report = await page.locator('pre.report').textContent();
  check(report.startsWith('simbot explain: 180.000 s, seed 4'),
    `the scrimmage's explain report is shown: ${report.slice(0, 80)}`);
  check(report.includes('A A.dc:') && report.includes('B B.dc:') && !report.includes(out),
    `the report names the programs, not the server's folders: ${report.slice(0, 300)}`);
  await page.screenshot({ path: join(out, 'serve-match.png') });
  await page.click('a.replay');
  await page.waitForFunction(() => window.simbotViewer && window.simbotViewer.ready === true, null,
    { timeout: 60000 });
  await page.screenshot({ path: join(out, 'serve-replay.png') });
  check(problems.length === 0, `no error in any page: ${problems.join('; ')}`);
} catch (e) {
  check(false, `${e.stack || e}`);
} finally {
  if (browser) await browser.close();
  server.kill('SIGTERM');
}
if (failures.length) {
  console.log(`${failures.length} failure(s)`);
  process.exit(1);
}
console.log('server browser test: all passed');

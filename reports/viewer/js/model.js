// model.js -- the run, from the page's data, in the shapes the views need.
//
// The data (reports/viewer.cpp) holds the trace's records as columns per kind
// (trace/records.def), each sorted by tick. The model is built once when
// the page opens: per robot, samples as typed arrays, handler and reflex
// spans, eye-reading steps, serial bytes, frames; balls paired with their
// outcomes; and one sorted list of ticks per kind of event for stepping.
// Views then look things up by binary search and never scan whole runs.

// Index of the last element of the sorted array `a` that is <= t, or -1.
function lastAtOrBefore(a, t) {
  let lo = 0, hi = a.length - 1, found = -1;
  while (lo <= hi) {
    const mid = (lo + hi) >> 1;
    if (a[mid] <= t) { found = mid; lo = mid + 1; } else { hi = mid - 1; }
  }
  return found;
}

// Index of the first element of the sorted array `a` that is >= t (a.length if none).
function firstAtOrAfter(a, t) {
  let lo = 0, hi = a.length;
  while (lo < hi) {
    const mid = (lo + hi) >> 1;
    if (a[mid] < t) lo = mid + 1; else hi = mid;
  }
  return lo;
}

function wrap360(deg) {
  const d = deg % 360;
  return d < 0 ? d + 360 : d;
}

function wrap180(deg) {
  const d = wrap360(deg + 180) - 180;
  return d;
}

const ROBOT_NAMES = ['A', 'B'];

function buildModel(data) {
  const K = data.kinds;
  const rows = (kind) => (K[kind] ? K[kind].t.length : 0);
  const col = (kind, field) => (K[kind] && K[kind][field]) || [];
  const run = {};
  for (const key of Object.keys(K.run || {})) run[key] = K.run[key][0];
  const tps = run.ticks_per_second || 9216000;
  const endRows = rows('end');
  const endTick = endRows ? K.end.t[0] : run.end_t;

  const robots = [];
  for (let i = 0; i < rows('robot'); ++i) {
    const r = {};
    for (const key of Object.keys(K.robot)) r[key] = K.robot[key][i];
    r.name = ROBOT_NAMES[r.robot];
    r.tps = tps;
    r.lines = r.source.split('\n');
    if (r.lines.length && r.lines[r.lines.length - 1] === '') r.lines.pop();
    robots[r.robot] = r;
  }
  for (const r of robots) {
    r.samples = robotSamples(K.sample, r.robot);
    r.serial = robotColumns(K.serial_byte, r.robot, ['byte']);
    r.serialIsr = robotColumns(K.serial_isr, r.robot, ['end_t']);
    r.latched = robotColumns(K.frame_latched, r.robot, ['bytes']);
    r.rejected = robotColumns(K.frame_rejected, r.robot, ['bytes']);
    r.eyes = [eyeSteps(K.ad_read, r.robot, 0), eyeSteps(K.ad_read, r.robot, 1)];
    r.handlers = handlerSpans(K, r.robot, endTick);
    r.reflexes = reflexSpans(K, r.robot, endTick);
    r.shotTicks = robotColumns(K.ball_launch, r.robot, []).t;
    r.hitTicks = robotColumns(K.ball_hit, r.robot, []).t;
    r.watch = watchSeries(data.watch && data.watch[r.name]);
    const result = robotColumns(K.result, r.robot, ['hits', 'shots', 'faulted', 'exited',
      'frames_latched', 'frames_rejected']);
    r.result = result.t.length ? {
      hits: result.hits[0], shots: result.shots[0], faulted: result.faulted[0], exited: result.exited[0],
      framesLatched: result.frames_latched[0], framesRejected: result.frames_rejected[0],
    } : null;
  }

  const model = {
    run, tps, endTick, robots,
    balls: pairBalls(K),
    course: buildCourse(K),
    marks: fieldMarks(K),
    events: eventList(K),
    faults: rowsOf(K.fault),
    reloads: rowsOf(K.reload),
    plantFaults: rowsOf(K.plant_fault),
    injections: rowsOf(K.injection),
    consoleLines: rowsOf(K.console),
    truncatedAt: data.truncated_at === undefined ? null : data.truncated_at,
    charTicks: data.char_ticks,  // one serial character (timebase/tick.h)
    winner: endRows ? K.end.winner[0] : '',
    coin: endRows ? K.end.tie_broken_by_coin[0] : false,
    steps: stepLists(K),
  };
  model.markTicks = model.marks.map((m) => m.t);
  return model;
}

// Rows of one kind as objects (small kinds only).
function rowsOf(c) {
  const out = [];
  if (!c) return out;
  const keys = Object.keys(c);
  for (let i = 0; i < c.t.length; ++i) {
    const row = {};
    for (const k of keys) row[k] = c[k][i];
    out.push(row);
  }
  return out;
}

// The columns `fields` (and t) of the rows of one robot.
function robotColumns(c, robot, fields) {
  const out = { t: [] };
  for (const f of fields) out[f] = [];
  if (!c) return out;
  for (let i = 0; i < c.t.length; ++i) {
    if (c.robot[i] !== robot) continue;
    out.t.push(c.t[i]);
    for (const f of fields) out[f].push(c[f][i]);
  }
  return out;
}

function robotSamples(c, robot) {
  const idx = [];
  if (c) for (let i = 0; i < c.t.length; ++i) if (c.robot[i] === robot) idx.push(i);
  const n = idx.length;
  const s = {
    t: new Float64Array(n), x: new Float64Array(n), y: new Float64Array(n), h: new Float64Array(n),
    vl: new Float64Array(n), vr: new Float64Array(n), el: new Int32Array(n), er: new Int32Array(n),
    line: new Int32Array(n), fn: new Array(n), inHandler: new Uint8Array(n),
  };
  idx.forEach((i, k) => {
    s.t[k] = c.t[i]; s.x[k] = c.x_ft[i]; s.y[k] = c.y_ft[i]; s.h[k] = c.heading_deg[i];
    s.vl[k] = c.left_fps[i]; s.vr[k] = c.right_fps[i]; s.el[k] = c.eye_left[i]; s.er[k] = c.eye_right[i];
    s.line[k] = c.line[i]; s.fn[k] = c.function[i]; s.inHandler[k] = c.in_handler[i] ? 1 : 0;
  });
  return s;
}

function eyeSteps(c, robot, channel) {
  const out = { t: [], v: [] };
  if (!c) return out;
  for (let i = 0; i < c.t.length; ++i) {
    if (c.robot[i] !== robot || c.channel[i] !== channel) continue;
    out.t.push(c.t[i]);
    out.v.push(c.value[i]);
  }
  return out;
}

// Edge-handler spans: acceptance to RETI (still open at the end: to the end).
function handlerSpans(K, robot, endTick) {
  const spans = [];
  const open = [];
  const acc = K.interrupt_accepted, ret = K.interrupt_returned;
  const events = [];
  if (acc) for (let i = 0; i < acc.t.length; ++i) if (acc.robot[i] === robot) events.push([acc.t[i], 0, i]);
  if (ret) for (let i = 0; i < ret.t.length; ++i) if (ret.robot[i] === robot) events.push([ret.t[i], 1, i]);
  events.sort((a, b) => a[0] - b[0] || a[1] - b[1]);
  for (const [t, kind, i] of events) {
    if (kind === 0) {
      open.push({ start: t, end: endTick, depth: open.length, handler: acc.handler[i],
        line: acc.line[i], function: acc.function[i], source: acc.source[i] });
    } else if (open.length) {
      const span = open.pop();
      span.end = t;
      spans.push(span);
    }
  }
  for (const span of open) spans.push(span);
  spans.sort((a, b) => a.start - b.start);
  return { start: spans.map((s) => s.start), spans };
}

function reflexSpans(K, robot, endTick) {
  const spans = [];
  let open = null;
  const st = K.reflex_start, en = K.reflex_end;
  const events = [];
  if (st) for (let i = 0; i < st.t.length; ++i) if (st.robot[i] === robot) events.push([st.t[i], 0, st.bumper[i]]);
  if (en) for (let i = 0; i < en.t.length; ++i) if (en.robot[i] === robot) events.push([en.t[i], 1, en.bumper[i]]);
  events.sort((a, b) => a[0] - b[0] || b[1] - a[1]);
  for (const [t, kind, bumper] of events) {
    if (kind === 0) {
      if (open) { open.end = t; spans.push(open); }  // a reflex under way starts over
      open = { start: t, end: endTick, bumper };
    } else if (open) {
      open.end = t;
      spans.push(open);
      open = null;
    }
  }
  if (open) spans.push(open);
  return { start: spans.map((s) => s.start), spans };
}

function watchSeries(vars) {
  const out = [];
  if (!vars) return out;
  for (const name of Object.keys(vars).sort()) out.push({ name, t: vars[name].t, v: vars[name].v });
  return out;
}

// Each launch with its flight and outcome. Ball numbers are slots, reused
// after a ball ends: a launch takes the first outcome of its number after it.
function pairBalls(K) {
  const balls = [];
  const open = new Map();
  const events = [];
  const add = (kind, c) => { if (c) for (let i = 0; i < c.t.length; ++i) events.push([c.t[i], kind, i]); };
  add(0, K.ball_launch);
  add(1, K.ball_skip);
  add(2, K.ball_hit);
  add(2.5, K.ball_miss);
  events.sort((a, b) => a[0] - b[0] || a[1] - b[1]);
  for (const [t, kind, i] of events) {
    if (kind === 0) {
      const c = K.ball_launch;
      const ball = { t0: t, robot: c.robot[i], gun: c.gun[i], number: c.ball[i], x0: c.x_ft[i],
        y0: c.y_ft[i], z0: c.z_ft[i], vx: c.vx_fps[i], vy: c.vy_fps[i], vz: c.vz_fps[i], end: null, skip: null, outcome: null };
      open.set(ball.number, ball);
      balls.push(ball);
      continue;
    }
    const c = kind === 1 ? K.ball_skip : kind === 2 ? K.ball_hit : K.ball_miss;
    const ball = open.get(c.ball[i]);
    if (!ball) continue;
    if (kind === 1) { ball.skip = t; continue; }
    ball.end = t;
    ball.outcome = kind === 2
      ? { hit: true, what: 'robot', target: c.target[i], x: c.x_ft[i], y: c.y_ft[i], z: c.z_ft[i] }
      : { hit: false, what: c.hit[i], x: c.x_ft[i], y: c.y_ft[i], z: c.z_ft[i], closest: c.closest_ft[i] };
    open.delete(c.ball[i]);
  }
  return balls;
}

// Where a ball is at tick t (exactly the plant's closed form).
function ballPosition(ball, t, tps, g) {
  const s = (t - ball.t0) / tps;
  let z = ball.z0 + ball.vz * s - 0.5 * g * s * s;
  if (ball.skip !== null && t >= ball.skip) z = 0;
  return { x: ball.x0 + ball.vx * s, y: ball.y0 + ball.vy * s, z: Math.max(z, 0) };
}

// Things drawn on the field where they happened: ball outcomes, referee actions.
function fieldMarks(K) {
  const marks = [];
  const hit = K.ball_hit, miss = K.ball_miss;
  if (hit) for (let i = 0; i < hit.t.length; ++i)
    marks.push({ t: hit.t[i], kind: 'hit', robot: hit.robot[i], x: hit.x_ft[i], y: hit.y_ft[i],
      text: `hit ${ROBOT_NAMES[hit.target[i]]}` });
  if (miss) for (let i = 0; i < miss.t.length; ++i) {
    const closest = miss.closest_ft[i];
    marks.push({ t: miss.t[i], kind: 'miss', robot: miss.robot[i], x: miss.x_ft[i], y: miss.y_ft[i],
      text: `miss (${miss.hit[i]})` + (closest === null ? '' : `, closest ${closest.toFixed(2)} ft`) });
  }
  for (const [kind, label] of [['referee_turn', 'referee: turned'], ['referee_put_back', 'referee: put back']]) {
    const c = K[kind];
    if (c) for (let i = 0; i < c.t.length; ++i)
      marks.push({ t: c.t[i], kind: 'referee', robot: c.robot[i], x: null, y: null, text: label });
  }
  marks.sort((a, b) => a.t - b.t);
  return marks;
}

// The discrete events of the timeline's event lane, per robot.
const EVENT_STYLE = {
  edge_enter: { glyph: 'v', color: '#e0b040', label: 'edge (enter)' },
  edge_leave: { glyph: '^', color: '#a08040', label: 'edge (leave)' },
  contact: { glyph: 'o', color: '#e07030', label: 'contact' },
  solenoid_stroke: { glyph: '|', color: '#b0b0ff', label: 'gun stroke' },
  gun_empty: { glyph: '|', color: '#707090', label: 'gun empty' },
  gun_misfire: { glyph: '|', color: '#c060c0', label: 'misfire' },
  gun_jammed: { glyph: '|', color: '#ff40ff', label: 'jammed' },
  ball_launch: { glyph: '>', color: '#80c0ff', label: 'launch' },
  ball_hit: { glyph: '*', color: '#ff4040', label: 'hit' },
  ball_miss: { glyph: 'x', color: '#909090', label: 'miss' },
  referee_turn: { glyph: 'R', color: '#ffffff', label: 'referee turn' },
  referee_put_back: { glyph: 'P', color: '#ffffff', label: 'referee put back' },
  injection: { glyph: '!', color: '#40ffa0', label: 'injection' },
  fault: { glyph: 'F', color: '#ff2020', label: 'FAULT' },
  reload: { glyph: 'L', color: '#ffa040', label: 'reloaded' },
  frame_overwritten: { glyph: 'W', color: '#ff8080', label: 'send overwritten' },
  console: { glyph: 'c', color: '#c0c0c0', label: 'console' },
  exit: { glyph: 'E', color: '#c0c0c0', label: 'main returned' },
  scatter_shot: { glyph: 'S', color: '#ffd040', label: 'scatter shot (Detect to Engage)' },
  reset: { glyph: 'Z', color: '#ff6060', label: 'board reset (brown-out / injected)' },
  restart: { glyph: 'M', color: '#60ff60', label: 'restart from main' },
  disc_fire: { glyph: 'D', color: '#f5f0a0', label: 'disc fired' },
  disc_hit: { glyph: '#', color: '#ff4040', label: 'disc hit' },
  disc_miss: { glyph: 'd', color: '#909090', label: 'disc miss' },
  disc_empty: { glyph: '|', color: '#908860', label: 'disc magazine empty' },
  deploy: { glyph: 'B', color: '#b08850', label: 'deployed (block / decoy)' },
  deploy_empty: { glyph: '|', color: '#806040', label: 'nothing left to deploy' },
  push_end: { glyph: 'b', color: '#d0a060', label: 'block pushed' },
  screen_hides: { glyph: 's', color: '#7090b0', label: 'beacon behind a decoy screen (or out)' },
};

function describeEvent(kind, c, i) {
  switch (kind) {
    case 'edge_enter': case 'edge_leave': return `${c.detector[i]} detector`;
    case 'contact': return `${c.bumper[i]} bumper, with ${c.with[i]}`;
    case 'solenoid_stroke': case 'gun_empty': case 'gun_misfire': case 'gun_jammed': return `gun ${c.gun[i] + 1}`;
    case 'ball_launch': return `gun ${c.gun[i] + 1}, ball ${c.ball[i]}`;
    case 'ball_hit': return `hit ${ROBOT_NAMES[c.target[i]]}`;
    case 'ball_miss': return `${c.hit[i]}` + (c.closest_ft[i] === null ? '' : `, closest ${c.closest_ft[i].toFixed(2)} ft`);
    case 'injection': return `${c.what[i]} (line ${c.line[i]})`;
    case 'fault': return `line ${c.line[i]}: ${c.message[i]}`;
    case 'reload': return `reload ${c.reloads[i]}: main starts again`;
    case 'frame_overwritten': {
      // Each send's line, and the line that called its function (0: none).
      const site = (line, caller) => `line ${line}` + (caller > 0 ? ` (called from line ${caller})` : '');
      return `the send from ${site(c.line[i], c.caller_line[i])} overwrote the send from ` +
        `${site(c.previous_line[i], c.previous_caller_line[i])}: the port had taken ` +
        `${c.fetched[i]} of its ${c.previous_count[i]} bytes`;
    }
    case 'console': return c.text[i];
    case 'scatter_shot': return `gun ${c.gun[i] + 1}, ball ${c.ball[i]}: eyes ${c.eye_left[i]}/${c.eye_right[i]} ` +
      `not above ${c.threshold[i]}` + (c.scores[i] ? '' : ' (does not score)');
    case 'reset': return c.cause[i] === 'brown_out'
      ? `brown-out` + (c.voltage_v[i] === null ? '' : ` at ${c.voltage_v[i].toFixed(2)} V`) : 'injected reset';
    case 'restart': return 'main starts again' + (c.voltage_v[i] === null ? '' : ` (${c.voltage_v[i].toFixed(2)} V)`);
    case 'disc_fire': return `disc ${c.disc[i]}`;
    case 'disc_hit': return `disc ${c.disc[i]} hit ${ROBOT_NAMES[c.target[i]]}`;
    case 'disc_miss': return `disc ${c.disc[i]}: ${c.hit[i]}` +
      (c.closest_ft[i] === null ? '' : `, closest ${c.closest_ft[i].toFixed(2)} ft`);
    case 'deploy': return `${c.kind[i]} ${c.number[i]} (bit ${c.bit[i]})`;
    case 'deploy_empty': return `no ${c.kind[i]} left (bit ${c.bit[i]})`;
    case 'screen_hides': return `${ROBOT_NAMES[1 - c.robot[i]]} ` +
      (c.hidden[i] ? 'hidden by' : 'no longer hidden by') + ` a decoy screen (${ROBOT_NAMES[c.owner[i]]}'s screen ${c.number[i]})`;
    case 'push_end': return `pushed block ${c.block[i]} ${c.pushed_ft[i].toFixed(2)} ft (${c.by[i]})`;
    default: return '';
  }
}

function eventList(K) {
  const perRobot = [[], []];
  for (const kind of Object.keys(EVENT_STYLE)) {
    const c = K[kind];
    if (!c) continue;
    for (let i = 0; i < c.t.length; ++i)
      perRobot[c.robot[i]].push({ t: c.t[i], kind, text: describeEvent(kind, c, i) });
  }
  return perRobot.map((list) => {
    list.sort((a, b) => a.t - b.t);
    return { t: list.map((e) => e.t), list };
  });
}

// Kinds the user can step through, each a sorted list of ticks.
const STEP_KINDS = [
  ['frames', 'motor frames', ['frame_latched', 'frame_rejected']],
  ['rejected', 'rejected frames', ['frame_rejected']],
  ['sends', 'serial sends', ['serial_send']],
  ['overwritten', 'overwritten sends', ['frame_overwritten']],
  ['interrupts', 'edge interrupts', ['interrupt_accepted']],
  ['edges', 'edge detector', ['edge_enter', 'edge_leave']],
  ['contacts', 'contacts', ['contact']],
  ['reflexes', 'reflexes', ['reflex_start']],
  ['strokes', 'gun strokes', ['solenoid_stroke', 'gun_empty', 'gun_misfire', 'gun_jammed']],
  ['launches', 'launches', ['ball_launch']],
  ['hits', 'hits', ['ball_hit']],
  ['misses', 'misses', ['ball_miss']],
  ['referee', 'referee', ['referee_turn', 'referee_put_back']],
  ['injections', 'injections', ['injection']],
  ['faults', 'faults and reloads', ['fault', 'reload']],
  ['console', 'console', ['console']],
  ['scatter', 'scatter shots', ['scatter_shot']],
  ['resets', 'resets', ['reset', 'restart']],
  ['discs', 'discs', ['disc_fire', 'disc_hit', 'disc_miss', 'disc_empty']],
  ['deploys', 'deployed', ['deploy', 'deploy_empty', 'push_end']],
];

function stepLists(K) {
  const out = [];
  for (const [id, label, kinds] of STEP_KINDS) {
    const ticks = [];
    for (const kind of kinds) if (K[kind]) for (const t of K[kind].t) ticks.push(t);
    if (!ticks.length) continue;
    ticks.sort((a, b) => a - b);
    out.push({ id, label, ticks });
  }
  return out;
}

// A robot's pose at tick t: a sample's own values at its tick, linear
// between samples (heading along the shorter arc).
function poseAt(robot, t) {
  const s = robot.samples;
  const n = s.t.length;
  if (!n) return { x_ft: robot.x_ft, y_ft: robot.y_ft, heading_deg: robot.heading_deg };
  const i = lastAtOrBefore(s.t, t);
  if (i < 0) return { x_ft: s.x[0], y_ft: s.y[0], heading_deg: s.h[0] };
  if (s.t[i] === t || i === n - 1) return { x_ft: s.x[i], y_ft: s.y[i], heading_deg: s.h[i] };
  const f = (t - s.t[i]) / (s.t[i + 1] - s.t[i]);
  return {
    x_ft: s.x[i] + f * (s.x[i + 1] - s.x[i]),
    y_ft: s.y[i] + f * (s.y[i + 1] - s.y[i]),
    heading_deg: wrap360(s.h[i] + f * wrap180(s.h[i + 1] - s.h[i])),
  };
}

// The latest sample of a robot at or before t (index, or -1).
function sampleIndex(robot, t) {
  return lastAtOrBefore(robot.samples.t, t);
}

// The edge handler in service at tick t (exactly, from its acceptance and
// RETI records), or null.
function handlerAt(robot, t) {
  const h = robot.handlers;
  for (let i = lastAtOrBefore(h.start, t); i >= 0; --i) {
    if (h.spans[i].end > t) return h.spans[i];
    if (h.spans[i].depth === 0) break;
  }
  return null;
}

// app.js -- the page: controls, playback, the header and log, and the test
// hook (window.simbotViewer). One cursor (a tick) drives every view; a
// frame draws the 2-D field, the 3-D scene, the timeline and the source
// panels for it.

const SPEEDS = [0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1, 2, 5, 10, 20, 50, 100];

function startViewer() {
  const hook = { ready: false, errors: [] };
  window.simbotViewer = hook;
  window.addEventListener('error', (e) => hook.errors.push(String(e.message || e)));
  const $ = (id) => document.getElementById(id);

  const data = JSON.parse($('simbot-data').textContent);
  const model = buildModel(data);
  const tps = model.tps;
  const names = model.robots.map((r) => r.name);
  const fmt = (t) => `${(t / tps).toFixed(6)} s`;

  let cursor = 0, playing = false, speed = 1, lastFrame = null;
  let startT = 0, endT = model.endTick;

  // ---- views
  const field = createField2d($('field2d'), model, $('field-labels'));
  const scene = createScene3d($('view3d'), model);
  const timeline = createTimeline($('timeline'), $('tooltip'), model, {
    seek: (t) => seek(t),
    windowChanged: () => {},
  });
  const panels = model.robots.map((robot) => {
    const div = document.createElement('div');
    div.className = 'source';
    div.id = `source-${robot.name}`;
    $('sources').appendChild(div);
    return createSourcePanel(div, robot);
  });

  // ---- header: programs, live and final score, winner, faults
  $('title').textContent = model.robots.map((r) => `${r.name}: ${r.program}`).join('  vs  ') +
    `   (seed ${model.run.seed}, profile ${model.run.profile})`;
  document.title = `simbot replay: ${model.robots.map((r) => r.program.split('/').pop()).join(' vs ')}`;
  for (const f of model.faults) {
    const div = document.createElement('div');
    div.className = 'fault';
    div.textContent = `FAULT: robot ${names[f.robot]} at ${fmt(f.t)}, line ${f.line}: ${f.message}`;
    div.addEventListener('click', () => seek(f.t));
    $('faults').appendChild(div);
  }
  if (model.truncatedAt !== null) {
    const div = document.createElement('div');
    div.className = 'fault';
    div.textContent = `This run made more trace records than a page holds: the page shows it up to ` +
      `${fmt(model.truncatedAt)} (and its result); the --trace file has all of it.`;
    $('faults').appendChild(div);
  }
  for (const f of model.plantFaults) {
    const div = document.createElement('div');
    div.className = 'fault';
    div.textContent = `PLANT FAULT at ${fmt(f.t)}: ${f.message}; the run ended there`;
    div.addEventListener('click', () => seek(f.t));
    $('faults').appendChild(div);
  }
  function updateScore() {
    const parts = model.robots.map((r) => {
      const hits = lastAtOrBefore(r.hitTicks, cursor) + 1, shots = lastAtOrBefore(r.shotTicks, cursor) + 1;
      const final = r.result ? ` (final ${r.result.hits}/${r.result.shots})` : '';
      return `<span class="robot" style="color:${ROBOT_COLORS[r.robot]}">${r.name}: ${hits} hits / ${shots} shots${final}</span>`;
    });
    if (model.winner) parts.push(`<span class="winner">winner ${model.winner}${model.coin ? ' (coin flip)' : ''}</span>`);
    $('score').innerHTML = parts.join('');
  }

  // ---- the log: injections, faults, console lines (click to go there)
  const logEntries = [];
  for (const i of model.injections) logEntries.push([i.t, `${names[i.robot]} injection ${i.what} at line ${i.line}`]);
  for (const f of model.faults) logEntries.push([f.t, `${names[f.robot]} FAULT line ${f.line}: ${f.message}`]);
  for (const l of model.reloads) logEntries.push([l.t, `${names[l.robot]} reloaded (reload ${l.reloads}): main starts again`]);
  for (const c of model.consoleLines.slice(0, 2000)) logEntries.push([c.t, `${names[c.robot]} console: ${c.text}`]);
  logEntries.sort((a, b) => a[0] - b[0]);
  for (const [t, text] of logEntries) {
    const div = document.createElement('div');
    div.className = 'entry';
    div.textContent = `${fmt(t).padStart(16)}  ${text}`;
    div.addEventListener('click', () => seek(t));
    $('log').appendChild(div);
  }

  // ---- the timeline's legend: every symbol its lanes can draw
  for (const s of LANE_SYMBOLS.concat(Object.entries(EVENT_STYLE).map(([key, e]) =>
    ({ key, shape: 'glyph', glyph: e.glyph, color: e.color, label: e.label })))) {
    const item = document.createElement('span');
    item.className = 'legend-item';
    item.dataset.symbol = s.key;
    const swatch = document.createElement('span');
    swatch.className = 'swatch';
    if (s.shape === 'glyph') {
      swatch.textContent = s.glyph;
      swatch.style.color = s.color;
    } else if (s.shape === 'line' || s.shape === 'dash') {
      swatch.style.borderTop = `2px ${s.shape === 'dash' ? 'dashed' : 'solid'} ${s.color}`;
      swatch.style.height = '0';
    } else {
      swatch.style.background = s.color;
      if (s.shape === 'tick') { swatch.style.minWidth = '3px'; swatch.style.width = '3px'; }
      if (s.shape === 'bar') swatch.style.height = '4px';
    }
    item.appendChild(swatch);
    item.appendChild(document.createTextNode(s.label));
    $('legend').appendChild(item);
  }
  // ---- the field's legend: what the course puts on the field, for a run that has it
  const present = new Set();
  for (const o of model.course.obstacles) present.add(o.mine ? 'mine' : 'obstacle');
  if (model.course.discs.length) present.add('disc');
  for (const d of model.course.deployables) present.add(COURSE_STYLE[d.kind] ? d.kind : 'block');
  for (const [key, style] of Object.entries(COURSE_STYLE)) {
    if (!present.has(key)) continue;
    const item = document.createElement('span');
    item.className = 'legend-item course';
    item.dataset.symbol = `field:${key}`;
    const swatch = document.createElement('span');
    swatch.className = 'swatch';
    swatch.style.background = style.color;
    item.appendChild(swatch);
    item.appendChild(document.createTextNode(`field: ${style.label}`));
    $('legend').appendChild(item);
  }
  $('trails').addEventListener('change', () => { field.setTrails($('trails').checked); render(); });

  createExplainPanel($('explain-body'), data.explain || [], (t) => seek(t));

  // ---- controls
  for (const s of SPEEDS) {
    const o = document.createElement('option');
    o.value = String(s);
    o.textContent = s < 1 ? `1/${Math.round(1 / s)}x` : `${s}x`;
    $('speed').appendChild(o);
  }
  $('speed').value = '1';
  $('speed').addEventListener('change', () => { speed = Number($('speed').value); });
  for (const k of model.steps) {
    const o = document.createElement('option');
    o.value = k.id;
    o.textContent = `${k.label} (${k.ticks.length})`;
    $('step-kind').appendChild(o);
  }
  const stepTicks = () => (model.steps.find((k) => k.id === $('step-kind').value) || { ticks: [] }).ticks;
  function step(direction) {
    const ticks = stepTicks();
    const i = direction > 0 ? firstAtOrAfter(ticks, cursor + 1) : lastAtOrBefore(ticks, cursor - 1);
    if (i >= 0 && i < ticks.length) seek(ticks[i]);
  }
  $('step-prev').addEventListener('click', () => step(-1));
  $('step-next').addEventListener('click', () => step(1));
  $('play').addEventListener('click', () => (playing ? pause() : play()));
  $('replay').addEventListener('click', () => { seek(startT); play(); });
  $('seek').addEventListener('input', () => seek(Math.round(startT + Number($('seek').value) / 100000 * (endT - startT))));
  $('start').value = (startT / tps).toFixed(3);
  $('end').value = (endT / tps).toFixed(3);
  const setRange = () => {
    const s = Math.max(0, Math.round(Number($('start').value) * tps));
    const e = Math.min(model.endTick, Math.round(Number($('end').value) * tps));
    if (!(e > s)) return;
    startT = s;
    endT = e;
    timeline.setWindow(startT, endT);
    seek(Math.min(Math.max(cursor, startT), endT));
  };
  $('start').addEventListener('change', setRange);
  $('end').addEventListener('change', setRange);
  for (const name of scene.presets) {
    const b = document.createElement('button');
    b.textContent = name;
    b.addEventListener('click', () => { scene.setPreset(name); render(); });
    $('cameras').appendChild(b);
  }
  scene.onPreset((name) => {
    for (const b of $('cameras').children) b.classList.toggle('active', b.textContent === name);
  });
  scene.setPreset('corner SW');
  model.robots.forEach((robot, i) => {
    const label = document.createElement('label');
    label.textContent = `${robot.name} eye thresholds `;
    const input = document.createElement('input');
    input.placeholder = 'e.g. 48, 800';
    input.title = "the program's own thresholds, drawn on the eye curves";
    input.addEventListener('input', () => {
      const values = input.value.split(/[,\s]+/).map(Number).filter((v) => Number.isFinite(v) && v > 0);
      timeline.setThresholds(i, values);
    });
    label.appendChild(input);
    $('thresholds').appendChild(label);
  });
  document.addEventListener('keydown', (e) => {
    if (e.target.tagName === 'INPUT' || e.target.tagName === 'SELECT') return;
    if (e.key === ' ') { e.preventDefault(); playing ? pause() : play(); }
    if (e.key === 'ArrowRight') step(1);
    if (e.key === 'ArrowLeft') step(-1);
  });
  window.addEventListener('resize', () => { field.resize(); scene.resize(); timeline.resize(); render(); });

  // ---- time and playback
  function seek(t) {
    cursor = Math.min(Math.max(Math.round(t), 0), model.endTick);
    render();
  }
  function play() {
    if (cursor >= endT) cursor = startT;
    playing = true;
    lastFrame = null;
    $('play').innerHTML = '&#x2016; pause';
    requestAnimationFrame(frame);
  }
  function pause() {
    playing = false;
    $('play').innerHTML = '&#x25B6; play';
  }
  function frame(now) {
    if (!playing) return;
    if (lastFrame !== null) {
      cursor = Math.min(endT, cursor + Math.round((now - lastFrame) / 1000 * speed * tps));
      if (cursor >= endT) pause();
    }
    lastFrame = now;
    followCursor();
    render();
    if (playing) requestAnimationFrame(frame);
  }
  // Keeps the cursor inside the timeline's window while playing.
  function followCursor() {
    const [from, to] = timeline.window();
    if (cursor > to || cursor < from) {
      const span = to - from;
      const f = Math.max(0, Math.min(cursor - 0.1 * span, model.endTick - span));
      timeline.setWindow(f, f + span);
    }
  }

  function render() {
    try {
      const poses = model.robots.map((r) => poseAt(r, cursor));
      const states = model.robots.map((r) => {
        // Faulted from its latest fault up to the reload after it (--reload-on-fault).
        const latest = (rows) => rows.filter((x) => x.robot === r.robot && x.t <= cursor).pop();
        const fault = latest(model.faults), reload = latest(model.reloads);
        return { inHandler: handlerAt(r, cursor) !== null, faulted: Boolean(fault && (!reload || reload.t < fault.t)) };
      });
      field.draw(cursor, poses, states);
      scene.update(cursor, poses);
      timeline.setCursor(cursor);
      timeline.draw();
      panels.forEach((p) => p.update(cursor));
      updateScore();
      $('clock').textContent = `${fmt(cursor)}  tick ${cursor.toLocaleString('en')}`;
      $('seek').value = String(Math.round((cursor - startT) / Math.max(1, endT - startT) * 100000));
    } catch (e) {
      hook.errors.push(String(e && e.stack || e));
      throw e;
    }
  }

  // ---- the test hook
  const robotIndex = (name) => {
    const i = names.indexOf(name);
    if (i < 0) throw new Error(`no robot '${name}'`);
    return i;
  };
  Object.assign(hook, {
    seek,
    time: () => cursor,
    play,
    pause,
    playing: () => playing,
    setSpeed: (x) => { speed = x; $('speed').value = String(x); },
    pose: (name) => poseAt(model.robots[robotIndex(name)], cursor),
    currentLine: (name) => panels[robotIndex(name)].currentLine(),
    cameras: () => scene.presets.slice(),
    setCamera: (name) => { scene.setPreset(name); render(); },
    view3dStats: () => scene.stats(),
    explainText: () => $('explain-body').textContent,
    trails: () => field.trails(),
    courseDrawn: () => field.courseDrawn(),
    fieldPixelOf: (x, y) => field.pixelOf(x, y),
    course: () => ({ obstacles: model.course.obstacles.length, discs: model.course.discs.length,
      deployables: model.course.deployables.length }),
    // Deployable i's centre at tick t as the page draws it (null before it is set down).
    deployableAt: (i, t) => deployablePosition(model.course.deployables[i], t, model.robots),
    timelineSymbols: () => timeline.symbols(),
    setWindow: (from, to) => timeline.setWindow(from, to),
  });
  render();
  hook.ready = true;
  // The page is ready: the test reads this mark's time since navigation start.
  performance.mark('simbot-ready');
}

startViewer();

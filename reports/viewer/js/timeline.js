// timeline.js -- per robot, lanes on one time axis, on a canvas.
//
// Lanes: serial bytes on the wire (a box per 9,600-tick character, its text
// when there is room), motor frames (latched green, rejected red), handlers
// in service (the edge handler as a bar, the serial library's interrupts
// as thin bars inside it), discrete events (edges, contacts, reflexes,
// strokes, launches, hits, misses...), and the eye readings the program saw
// as step curves with the user's thresholds. The window [from, to] zooms
// with the wheel and pans with a drag; a click moves the cursor. Only what
// falls inside the window is drawn, found by binary search, and items that
// would share a pixel column are drawn once.

// Everything the lanes draw besides the event glyphs (EVENT_STYLE), for
// the legend: a box, a thin bar, a line or a dashed line of a colour.
const LANE_SYMBOLS = [
  { key: 'serial_byte', shape: 'box', color: '#3d6fa8', label: 'serial byte on TXD' },
  { key: 'frame_latched', shape: 'tick', color: '#3fbf5f', label: 'frame latched' },
  { key: 'frame_rejected', shape: 'tick', color: '#ff4040', label: 'frame rejected' },
  { key: 'handler', shape: 'box', color: '#a05cd6', label: 'edge handler in service' },
  { key: 'serial_isr', shape: 'bar', color: '#f0d060', label: 'serial transmit interrupt' },
  { key: 'reflex', shape: 'box', color: 'rgba(224,112,48,0.35)', label: 'bumper reflex' },
  { key: 'eye_left', shape: 'line', color: '#59d16b', label: 'left eye (ad_rd8)' },
  { key: 'eye_right', shape: 'line', color: '#e85fa0', label: 'right eye (ad_rd8)' },
  { key: 'threshold', shape: 'dash', color: '#d0d0d0', label: 'your threshold' },
  { key: 'cursor', shape: 'tick', color: '#ffffff', label: 'cursor' },
];

function createTimeline(canvas, tooltip, model, callbacks) {
  const ctx = canvas.getContext('2d');
  const lanes = [];
  const AXIS_H = 22;
  const laneHeights = { serial: 18, frames: 14, handlers: 18, events: 18, eyes: 70 };
  for (const robot of model.robots)
    for (const kind of ['serial', 'frames', 'handlers', 'events', 'eyes'])
      lanes.push({ robot, kind, height: laneHeights[kind] });
  const LABEL_W = 92;
  let from = 0, to = model.endTick, cursor = 0, dpr = 1;
  let thresholds = model.robots.map(() => []);
  let hoverItems = [];  // {x0, x1, y0, y1, text} of what was drawn, for the tooltip
  let drawn = new Set();  // the symbols (LANE_SYMBOLS keys, EVENT_STYLE kinds) the last draw drew

  function resize() {
    dpr = window.devicePixelRatio || 1;
    let h = AXIS_H;
    for (const lane of lanes) h += lane.height + 4;
    canvas.style.height = `${h}px`;
    canvas.width = Math.round(canvas.clientWidth * dpr);
    canvas.height = Math.round(h * dpr);
  }

  const width = () => canvas.width / dpr - LABEL_W;
  const xOf = (t) => LABEL_W + (t - from) / (to - from) * width();
  const tOf = (x) => from + (x - LABEL_W) / width() * (to - from);

  function drawAxis() {
    ctx.fillStyle = '#c8ccd2';
    ctx.font = '11px sans-serif';
    ctx.textBaseline = 'middle';
    ctx.textAlign = 'center';
    const span = (to - from) / model.tps;
    const steps = [1e-5, 2e-5, 5e-5, 1e-4, 2e-4, 5e-4, 1e-3, 2e-3, 5e-3, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5,
      1, 2, 5, 10, 20, 30, 60, 120];
    const step = steps.find((s) => span / s <= 10) || 300;
    const digits = Math.max(0, -Math.floor(Math.log10(step) + 1e-9));
    ctx.strokeStyle = 'rgba(255,255,255,0.12)';
    for (let s = Math.ceil(from / model.tps / step) * step; s * model.tps <= to; s += step) {
      const x = xOf(s * model.tps);
      ctx.beginPath();
      ctx.moveTo(x, AXIS_H - 4);
      ctx.lineTo(x, canvas.height / dpr);
      ctx.stroke();
      ctx.fillText(`${s.toFixed(digits)} s`, x, AXIS_H / 2);
    }
  }

  function remember(x0, x1, y0, y1, text) {
    hoverItems.push({ x0: Math.min(x0, x1 - 2), x1: Math.max(x1, x0 + 2), y0, y1, text });
  }

  // Boxes [t, t + len) from sorted ticks, one per pixel column at most.
  function drawBoxes(ticks, len, y, h, color, label) {
    const lo = firstAtOrAfter(ticks, from - len), hi = firstAtOrAfter(ticks, to);
    let lastX = -Infinity;
    ctx.fillStyle = color;
    for (let i = lo; i < hi; ++i) {
      const x0 = xOf(ticks[i]), x1 = xOf(ticks[i] + len);
      if (x1 - lastX < 1 && x1 - x0 < 1) continue;
      lastX = x1;
      ctx.fillRect(x0, y, Math.max(1, x1 - x0 - (x1 - x0 > 4 ? 1 : 0)), h);
      drawn.add('serial_byte');
      if (label) label(i, x0, x1);
    }
  }

  function drawSerial(robot, y, h) {
    const s = robot.serial;
    const charPx = xOf(model.charTicks) - xOf(0);
    drawBoxes(s.t, model.charTicks, y + 2, h - 4, '#3d6fa8', (i, x0, x1) => {
      const b = s.byte[i];
      const text = b === 0 ? 'NUL' : b >= 32 && b < 127 ? String.fromCharCode(b) : `0x${b.toString(16)}`;
      if (charPx >= 14) {
        ctx.fillStyle = '#ffffff';
        ctx.fillText(text, (x0 + x1) / 2, y + h / 2);
        ctx.fillStyle = '#3d6fa8';
      }
      if (charPx >= 3) remember(x0, x1, y, y + h, `${robot.name} TXD byte ${text} (${b}) at ${fmtT(s.t[i])}`);
    });
  }

  function drawFrames(robot, y, h) {
    for (const [frames, color, what, key] of [[robot.latched, '#3fbf5f', 'latched', 'frame_latched'],
      [robot.rejected, '#ff4040', 'REJECTED', 'frame_rejected']]) {
      const lo = firstAtOrAfter(frames.t, from), hi = firstAtOrAfter(frames.t, to);
      let lastX = -Infinity;
      ctx.fillStyle = color;
      for (let i = lo; i < hi; ++i) {
        const x = xOf(frames.t[i]);
        if (x - lastX < 1) continue;
        lastX = x;
        ctx.fillRect(x - 1, y + 1, 2, h - 2);
        drawn.add(key);
        remember(x - 3, x + 3, y, y + h, `${robot.name} frame ${what} "${frames.bytes[i]}" at ${fmtT(frames.t[i])}`);
      }
    }
  }

  function drawHandlers(robot, y, h) {
    const spans = robot.handlers.spans;
    const hi = firstAtOrAfter(robot.handlers.start, to);
    ctx.fillStyle = '#a05cd6';
    for (let i = 0; i < hi; ++i) {
      const sp = spans[i];
      if (sp.end < from) continue;
      const x0 = xOf(sp.start), x1 = xOf(sp.end);
      ctx.fillRect(x0, y + 2 + 2 * sp.depth, Math.max(1, x1 - x0), h - 4 - 4 * sp.depth);
      drawn.add('handler');
      remember(x0, x1, y, y + h, `${robot.name} ${sp.handler} (${sp.source}) in service ` +
        `${fmtT(sp.start)} to ${fmtT(sp.end)}, ${((sp.end - sp.start) / model.tps * 1000).toFixed(3)} ms; ` +
        `it interrupted line ${sp.line} in ${sp.function || 'start-up'}`);
    }
    // the serial library's transmit interrupts, nested inside
    const isr = robot.serialIsr;
    const lo = firstAtOrAfter(isr.t, from - 2000), top = firstAtOrAfter(isr.t, to);
    ctx.fillStyle = '#f0d060';
    let lastX = -Infinity;
    for (let i = lo; i < top; ++i) {
      const x0 = xOf(isr.t[i]), x1 = xOf(isr.end_t[i]);
      if (x1 - lastX < 1 && x1 - x0 < 1) continue;
      lastX = x1;
      ctx.fillRect(x0, y + h / 2 - 2, Math.max(1, x1 - x0), 4);
      drawn.add('serial_isr');
      if (x1 - x0 >= 2) remember(x0, x1, y, y + h, `${robot.name} serial transmit interrupt ` +
        `${fmtT(isr.t[i])} to ${fmtT(isr.end_t[i])} (${isr.end_t[i] - isr.t[i]} ticks)`);
    }
  }

  function drawEvents(robot, y, h) {
    // reflexes as spans behind the glyphs
    const rs = robot.reflexes;
    ctx.fillStyle = 'rgba(224,112,48,0.35)';
    for (let i = 0; i < firstAtOrAfter(rs.start, to); ++i) {
      const sp = rs.spans[i];
      if (sp.end < from) continue;
      const x0 = xOf(sp.start), x1 = xOf(sp.end);
      ctx.fillRect(x0, y + 1, Math.max(1, x1 - x0), h - 2);
      drawn.add('reflex');
      remember(x0, x1, y, y + h, `${robot.name} bumper reflex (${sp.bumper}) ${fmtT(sp.start)} to ${fmtT(sp.end)}`);
    }
    const ev = model.events[robot.robot];
    const lo = firstAtOrAfter(ev.t, from), hi = firstAtOrAfter(ev.t, to);
    ctx.font = 'bold 12px monospace';
    ctx.textAlign = 'center';
    ctx.textBaseline = 'middle';
    let lastX = -Infinity, lastKind = '';
    for (let i = lo; i < hi; ++i) {
      const e = ev.list[i];
      const x = xOf(e.t);
      if (x - lastX < 3 && e.kind === lastKind) continue;
      lastX = x;
      lastKind = e.kind;
      const style = EVENT_STYLE[e.kind];
      ctx.fillStyle = style.color;
      ctx.fillText(style.glyph, x, y + h / 2);
      drawn.add(e.kind);
      remember(x - 4, x + 4, y, y + h, `${robot.name} ${style.label} at ${fmtT(e.t)}${e.text ? ': ' + e.text : ''}`);
    }
  }

  function drawEyes(robot, y, h) {
    const max = robot.eye_max;
    const yOf = (v) => y + h - 2 - v / max * (h - 4);
    ctx.strokeStyle = 'rgba(255,255,255,0.08)';
    ctx.strokeRect(LABEL_W, y, width(), h);
    ctx.setLineDash([4, 3]);
    ctx.strokeStyle = '#d0d0d0';
    for (const v of thresholds[robot.robot]) {
      drawn.add('threshold');
      ctx.beginPath();
      ctx.moveTo(LABEL_W, yOf(v));
      ctx.lineTo(LABEL_W + width(), yOf(v));
      ctx.stroke();
    }
    ctx.setLineDash([]);
    for (const [steps, color, key] of [[robot.eyes[0], '#59d16b', 'eye_left'], [robot.eyes[1], '#e85fa0', 'eye_right']]) {
      if (!steps.t.length) continue;
      drawn.add(key);
      const first = Math.max(0, lastAtOrBefore(steps.t, from));
      const hi = firstAtOrAfter(steps.t, to);
      let value = steps.t[first] <= from ? steps.v[first] : 0;  // 0: not read yet
      ctx.strokeStyle = color;
      ctx.beginPath();
      ctx.moveTo(LABEL_W, yOf(value));
      for (let i = first; i < hi; ++i) {
        if (steps.t[i] <= from) continue;
        const x = xOf(steps.t[i]);
        ctx.lineTo(x, yOf(value));
        value = steps.v[i];
        ctx.lineTo(x, yOf(value));
      }
      ctx.lineTo(LABEL_W + width(), yOf(value));
      ctx.stroke();
    }
    remember(LABEL_W, LABEL_W + width(), y, y + h, null);  // the tooltip reads the curves instead
  }

  function eyeTooltip(robot, t) {
    const out = [];
    for (const [steps, side] of [[robot.eyes[0], 'left'], [robot.eyes[1], 'right']]) {
      const i = lastAtOrBefore(steps.t, t);
      out.push(`${side} ${i < 0 ? '(not read yet)' : steps.v[i]}`);
    }
    return `${robot.name} eyes as ad_rd8 read them at ${fmtT(t)}: ${out.join(', ')}`;
  }

  function draw() {
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.fillStyle = '#15191e';
    ctx.fillRect(0, 0, canvas.width / dpr, canvas.height / dpr);
    hoverItems = [];
    drawn = new Set();
    drawAxis();
    let y = AXIS_H;
    const labels = { serial: 'TXD', frames: 'frames', handlers: 'handlers', events: 'events', eyes: 'eyes' };
    for (const lane of lanes) {
      ctx.fillStyle = lane.robot.robot === 0 ? 'rgba(74,163,255,0.06)' : 'rgba(255,138,61,0.06)';
      ctx.fillRect(0, y, canvas.width / dpr, lane.height);
      ctx.fillStyle = ROBOT_COLORS[lane.robot.robot];
      ctx.font = '11px sans-serif';
      ctx.textAlign = 'left';
      ctx.textBaseline = 'middle';
      ctx.fillText(`${lane.robot.name} ${labels[lane.kind]}`, 6, y + Math.min(lane.height, 18) / 2);
      ctx.save();
      ctx.beginPath();
      ctx.rect(LABEL_W, y, width(), lane.height);
      ctx.clip();
      ctx.font = '10px monospace';
      ctx.textAlign = 'center';
      const fn = { serial: drawSerial, frames: drawFrames, handlers: drawHandlers, events: drawEvents, eyes: drawEyes }[lane.kind];
      fn(lane.robot, y, lane.height);
      ctx.restore();
      lane.y = y;
      y += lane.height + 4;
    }
    const cx = xOf(cursor);
    if (cx >= LABEL_W) {
      drawn.add('cursor');
      ctx.strokeStyle = '#ffffff';
      ctx.lineWidth = 1;
      ctx.beginPath();
      ctx.moveTo(cx, 0);
      ctx.lineTo(cx, canvas.height / dpr);
      ctx.stroke();
    }
  }

  function fmtT(t) { return `${(t / model.tps).toFixed(6)} s`; }

  // ---- interaction
  let drag = null;
  canvas.addEventListener('wheel', (e) => {
    e.preventDefault();
    const t = tOf(e.offsetX);
    const k = Math.exp(e.deltaY * 0.0015);
    const span = Math.min(model.endTick, Math.max(200, (to - from) * k));
    from = t - (t - from) * span / (to - from);
    to = from + span;
    clampWindow();
    callbacks.windowChanged(from, to);
    draw();
  }, { passive: false });
  canvas.addEventListener('mousedown', (e) => { drag = { x: e.offsetX, from, to, moved: false }; });
  window.addEventListener('mouseup', (e) => {
    if (drag && !drag.moved && e.target === canvas && e.offsetX >= LABEL_W) callbacks.seek(Math.round(tOf(e.offsetX)));
    drag = null;
  });
  canvas.addEventListener('mousemove', (e) => {
    if (drag) {
      const dx = e.offsetX - drag.x;
      if (Math.abs(dx) > 3) drag.moved = true;
      if (drag.moved) {
        const dt = dx / width() * (drag.to - drag.from);
        from = drag.from - dt;
        to = drag.to - dt;
        clampWindow();
        callbacks.windowChanged(from, to);
        draw();
      }
      tooltip.style.display = 'none';
      return;
    }
    showTooltip(e);
  });
  canvas.addEventListener('mouseleave', () => { tooltip.style.display = 'none'; });

  function showTooltip(e) {
    const x = e.offsetX, y = e.offsetY;
    let text = null;
    for (let i = hoverItems.length - 1; i >= 0; --i) {
      const it = hoverItems[i];
      if (x >= it.x0 && x <= it.x1 && y >= it.y0 && y <= it.y1) {
        if (it.text === null) {
          const lane = lanes.find((l) => y >= l.y && y <= l.y + l.height);
          text = lane ? eyeTooltip(lane.robot, tOf(x)) : null;
        } else {
          text = it.text;
        }
        break;
      }
    }
    if (!text) { tooltip.style.display = 'none'; return; }
    tooltip.textContent = text;
    tooltip.style.display = 'block';
    tooltip.style.left = `${e.pageX + 12}px`;
    tooltip.style.top = `${e.pageY + 12}px`;
  }

  function clampWindow() {
    const span = to - from;
    if (from < 0) { from = 0; to = span; }
    if (to > model.endTick) { to = model.endTick; from = Math.max(0, to - span); }
  }

  resize();
  return {
    draw,
    resize,
    setCursor(t) { cursor = t; },
    setWindow(f, t) { from = f; to = Math.max(t, f + 100); draw(); },
    window: () => [from, to],
    symbols: () => [...drawn],
    setThresholds(robotIndex, values) { thresholds[robotIndex] = values; draw(); },
  };
}

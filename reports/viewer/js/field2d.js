// field2d.js -- the field from above, to scale, on a 2-D canvas.
//
// North (+y) is up, as in the thesis's figures. Everything is drawn in feet
// through one transform; the canvas is redrawn whole at every frame (a few
// hundred shapes), the robots' trails too (a few thousand points). The
// marks' labels are elements over it (see placeLabels).

const ROBOT_COLORS = ['#4aa3ff', '#ff8a3d'];
const FOV_RADIUS_FT = 30;  // the eyes see to the end of the field and beyond

function createField2d(canvas, model, labelLayer) {
  const ctx = canvas.getContext('2d');
  let trails = true;
  let trailPoints = [];  // per robot, the points of the path the last draw drew
  let courseDrawn = {};  // what the last draw drew of the course (course.js)
  const half = model.run.field_size_ft / 2;
  const margin = 0.6;  // ft around the field
  let scale = 1, cx = 0, cy = 0;

  function resize() {
    const dpr = window.devicePixelRatio || 1;
    const w = canvas.clientWidth, h = canvas.clientHeight;
    canvas.width = Math.round(w * dpr);
    canvas.height = Math.round(h * dpr);
    scale = Math.min(w, h) / (2 * (half + margin)) * dpr;
    cx = canvas.width / 2;
    cy = canvas.height / 2;
  }

  // Feet to canvas pixels.
  const px = (x) => cx + x * scale;
  const py = (y) => cy - y * scale;
  // A heading (clockwise from +y) as a canvas angle (from +x, y down).
  const canvasAngle = (headingDeg) => (headingDeg - 90) * Math.PI / 180;

  function drawField() {
    const run = model.run;
    ctx.fillStyle = '#1d2a1f';
    ctx.fillRect(px(-half), py(half), 2 * half * scale, 2 * half * scale);
    ctx.strokeStyle = '#8a8f98';
    ctx.lineWidth = Math.max(2, 0.15 * scale);
    ctx.strokeRect(px(-half), py(half), 2 * half * scale, 2 * half * scale);
    // the edge wire ring, and the band in which a detector reads low
    const w = half - run.wire_inset_ft;
    ctx.strokeStyle = 'rgba(230, 200, 60, 0.25)';
    ctx.lineWidth = 2 * run.wire_sensitivity_ft * scale;
    ctx.strokeRect(px(-w), py(w), 2 * w * scale, 2 * w * scale);
    ctx.strokeStyle = '#e6c83c';
    ctx.lineWidth = Math.max(1, 0.03 * scale);
    ctx.strokeRect(px(-w), py(w), 2 * w * scale, 2 * w * scale);
    // the divider
    const t = Math.max(run.divider_thickness_ft, 1.5 / scale);
    ctx.fillStyle = '#c8c8c8';
    ctx.fillRect(px(run.divider_x_ft - t / 2), py(run.divider_north_ft), t * scale,
      (run.divider_north_ft - run.divider_south_ft) * scale);
    // a 1-ft grid, faint
    ctx.strokeStyle = 'rgba(255,255,255,0.05)';
    ctx.lineWidth = 1;
    ctx.beginPath();
    for (let k = -Math.floor(half); k <= half; ++k) {
      ctx.moveTo(px(k), py(-half)); ctx.lineTo(px(k), py(half));
      ctx.moveTo(px(-half), py(k)); ctx.lineTo(px(half), py(k));
    }
    ctx.stroke();
  }

  // The half-plane the eyes see, and the wedge inside which both eyes see
  // the beacon (|bearing| below the far eye's limiting angle).
  function drawEyes(robot, pose) {
    const a = canvasAngle(pose.heading_deg);
    const x = px(pose.x_ft), y = py(pose.y_ft);
    ctx.save();
    ctx.beginPath();
    ctx.rect(px(-half), py(half), 2 * half * scale, 2 * half * scale);
    ctx.clip();
    ctx.fillStyle = 'rgba(255,255,255,0.035)';
    ctx.beginPath();
    ctx.moveTo(x, y);
    ctx.arc(x, y, FOV_RADIUS_FT * scale, a - Math.PI / 2, a + Math.PI / 2);
    ctx.closePath();
    ctx.fill();
    const left = robot.eye_right_limit_deg * Math.PI / 180;  // the right eye is far for a target on the left
    const right = robot.eye_left_limit_deg * Math.PI / 180;
    ctx.fillStyle = ROBOT_COLORS[robot.robot] + '30';
    ctx.beginPath();
    ctx.moveTo(x, y);
    ctx.arc(x, y, FOV_RADIUS_FT * scale, a - left, a + right);
    ctx.closePath();
    ctx.fill();
    ctx.restore();
  }

  function drawRobot(robot, pose, state) {
    const r = robot.body_diameter_ft / 2;
    const x = px(pose.x_ft), y = py(pose.y_ft);
    const a = canvasAngle(pose.heading_deg);
    ctx.fillStyle = ROBOT_COLORS[robot.robot];
    ctx.strokeStyle = state.faulted ? '#ff2020' : state.inHandler ? '#ffffff' : '#101010';
    ctx.lineWidth = state.faulted || state.inHandler ? 3 : 1.5;
    ctx.beginPath();
    ctx.arc(x, y, r * scale, 0, 2 * Math.PI);
    ctx.fill();
    ctx.stroke();
    ctx.strokeStyle = '#101010';
    ctx.lineWidth = Math.max(2, 0.08 * scale);
    ctx.beginPath();
    ctx.moveTo(x, y);
    ctx.lineTo(x + Math.cos(a) * r * 1.25 * scale, y + Math.sin(a) * r * 1.25 * scale);
    ctx.stroke();
    ctx.fillStyle = '#ffffff';
    ctx.font = `${Math.round(0.5 * scale)}px sans-serif`;
    ctx.textAlign = 'center';
    ctx.textBaseline = 'middle';
    ctx.fillText(robot.name, x - Math.cos(a) * r * 0.35 * scale, y - Math.sin(a) * r * 0.35 * scale);
  }

  function drawBalls(t) {
    const g = model.run.gravity_fps2;
    for (const ball of model.balls) {
      if (t < ball.t0 || (ball.end !== null && t >= ball.end)) continue;
      const p = ballPosition(ball, t, model.tps, g);
      ctx.strokeStyle = ROBOT_COLORS[ball.robot] + '80';
      ctx.lineWidth = 1;
      ctx.beginPath();
      ctx.moveTo(px(ball.x0), py(ball.y0));
      ctx.lineTo(px(p.x), py(p.y));
      ctx.stroke();
      ctx.fillStyle = '#ffffff';
      ctx.beginPath();
      ctx.arc(px(p.x), py(p.y), Math.max(3, (0.08 + 0.03 * p.z) * scale), 0, 2 * Math.PI);
      ctx.fill();
    }
  }

  // Each robot's path from the start to its pose at t: its samples (20 Hz).
  function drawTrails(t, poses) {
    trailPoints = [];
    if (!trails) return;
    model.robots.forEach((robot, i) => {
      const s = robot.samples;
      const last = lastAtOrBefore(s.t, t);
      ctx.strokeStyle = ROBOT_COLORS[robot.robot] + 'a0';
      ctx.lineWidth = 1.5;
      ctx.beginPath();
      ctx.moveTo(px(last < 0 ? poses[i].x_ft : s.x[0]), py(last < 0 ? poses[i].y_ft : s.y[0]));
      for (let k = 1; k <= last; ++k) ctx.lineTo(px(s.x[k]), py(s.y[k]));
      ctx.lineTo(px(poses[i].x_ft), py(poses[i].y_ft));
      ctx.stroke();
      trailPoints.push({ robot: robot.name, points: Math.max(0, last) + 2 });
    });
  }

  // The marks' labels are elements over the canvas, placed so that no two
  // overlap: each goes to the right of its mark or, if that is taken, the
  // nearest free place above or below it, inside the field's panel.
  const labelPool = [];
  function placeLabels(labels) {
    const dpr = window.devicePixelRatio || 1;
    const W = canvas.clientWidth, H = canvas.clientHeight;
    const placed = [];
    labels.forEach((l, i) => {
      let div = labelPool[i];
      if (!div) {
        div = document.createElement('div');
        labelPool.push(div);
        labelLayer.appendChild(div);
      }
      div.className = `mark-label ${l.kind}`;
      div.textContent = l.text;
      div.style.display = 'block';
      div.style.color = l.color;
      div.style.opacity = String(l.alpha);
      div.style.fontSize = `${l.fontPx}px`;
      const box = div.getBoundingClientRect();
      const w = box.width + 2, h = box.height + 2;  // a pixel apart
      const x0 = Math.min(Math.max(0, l.x / dpr), Math.max(0, W - w));
      const y0 = l.y / dpr - h;
      let at = null;
      for (let k = 0; k <= 40 && !at; ++k) {
        const dy = (k % 2 ? 1 : -1) * Math.ceil(k / 2) * h;
        const y = Math.min(Math.max(0, y0 + dy), Math.max(0, H - h));
        if (!placed.some((p) => x0 < p.x + p.w && p.x < x0 + w && y < p.y + p.h && p.y < y + h)) at = { x: x0, y };
      }
      if (!at) at = { x: x0, y: Math.max(0, ...placed.map((p) => p.y + p.h)) };  // below all of them
      placed.push({ x: at.x, y: at.y, w, h });
      div.style.left = `${at.x}px`;
      div.style.top = `${at.y}px`;
    });
    for (let i = labels.length; i < labelPool.length; ++i) labelPool[i].style.display = 'none';
  }

  // Ball outcomes and referee actions: shown for a while after they happen.
  function drawMarks(t) {
    const labels = [];
    const keep = 4 * model.tps;
    const from = firstAtOrAfter(model.markTicks, t - keep);
    const dpr = window.devicePixelRatio || 1;
    const fontPx = Math.max(11, Math.round(0.32 * scale / dpr));
    for (let i = from; i < model.marks.length && model.marks[i].t <= t; ++i) {
      const m = model.marks[i];
      const alpha = 1 - (t - m.t) / keep;
      let x = m.x, y = m.y;
      if (x === null) ({ x_ft: x, y_ft: y } = poseAt(model.robots[m.robot], m.t));
      ctx.globalAlpha = Math.max(0.15, alpha);
      ctx.strokeStyle = m.kind === 'hit' ? '#ff3030' : m.kind === 'miss' ? '#b0b0b0' : '#ffffff';
      ctx.lineWidth = 2;
      const s = 0.22 * scale;
      ctx.beginPath();
      if (m.kind === 'hit') {
        ctx.arc(px(x), py(y), s, 0, 2 * Math.PI);
      } else {
        ctx.moveTo(px(x) - s, py(y) - s); ctx.lineTo(px(x) + s, py(y) + s);
        ctx.moveTo(px(x) - s, py(y) + s); ctx.lineTo(px(x) + s, py(y) - s);
      }
      ctx.stroke();
      labels.push({ kind: m.kind, text: m.text, color: ctx.strokeStyle, alpha: ctx.globalAlpha, fontPx,
        x: px(x) + s * 1.3, y: py(y) - s });
    }
    ctx.globalAlpha = 1;
    if (labelLayer) placeLabels(labels);
  }

  function draw(t, poses, states) {
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.fillStyle = '#111418';
    ctx.fillRect(0, 0, canvas.width, canvas.height);
    drawField();
    model.robots.forEach((robot, i) => drawEyes(robot, poses[i]));
    drawTrails(t, poses);
    courseDrawn = drawCourse2d(ctx, px, py, scale, model, t);
    drawBalls(t);
    model.robots.forEach((robot, i) => drawRobot(robot, poses[i], states[i]));
    drawMarks(t);
  }

  resize();
  return {
    draw,
    resize,
    setTrails(on) { trails = Boolean(on); },
    trails: () => trailPoints.slice(),
    courseDrawn: () => Object.assign({}, courseDrawn),
    // Canvas pixel (device pixels) of a field point, for a test's probe.
    pixelOf: (x, y) => ({ x: px(x), y: py(y) }),
  };
}

// field2d.js -- the field from above, to scale, on a 2-D canvas.
//
// North (+y) is up, as in the thesis's figures. Everything is drawn in feet
// through one transform; the canvas is redrawn whole at every frame (a few
// hundred shapes).

const ROBOT_COLORS = ['#4aa3ff', '#ff8a3d'];
const FOV_RADIUS_FT = 30;  // the eyes see to the end of the field and beyond

function createField2d(canvas, model) {
  const ctx = canvas.getContext('2d');
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

  // Ball outcomes and referee actions: shown for a while after they happen.
  function drawMarks(t) {
    const keep = 4 * model.tps;
    const from = firstAtOrAfter(model.markTicks, t - keep);
    ctx.font = `${Math.max(11, Math.round(0.32 * scale))}px sans-serif`;
    ctx.textAlign = 'left';
    ctx.textBaseline = 'bottom';
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
      ctx.fillStyle = ctx.strokeStyle;
      ctx.fillText(m.text, px(x) + s * 1.3, py(y) - s);
    }
    ctx.globalAlpha = 1;
  }

  function draw(t, poses, states) {
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.fillStyle = '#111418';
    ctx.fillRect(0, 0, canvas.width, canvas.height);
    drawField();
    model.robots.forEach((robot, i) => drawEyes(robot, poses[i]));
    drawBalls(t);
    model.robots.forEach((robot, i) => drawRobot(robot, poses[i], states[i]));
    drawMarks(t);
  }

  resize();
  return { draw, resize };
}

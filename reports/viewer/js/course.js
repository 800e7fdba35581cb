// course.js -- what the wider competition puts on the field (DESIGN.md "The
// wider competition"): fixed obstacles (mines marked), discs in flight,
// deployed blocks (moving when pushed) and decoys, from their records.
//
// Obstacles come from the `obstacle` records (circle, or the outline in
// points_ft). A disc flies from its disc_fire to its disc_hit or disc_miss
// along the launch velocity by the closed form of the plant,
// s(t) = tau (1 - e^{-t/tau}) times the launch velocity. Deployables come
// from `deploy` records (kind block, decoy_light or decoy_screen, where it
// was set down); a block's later positions from any record that names it
// (`block` or `deployable`) with x_ft and y_ft, held between records.
// During a push (push_start to push_end) the block moves with its pusher:
// the plant moves it along the push by exactly the robot's displacement
// along the push's normal (plant/arena_blocks.cpp), so the page moves it
// along the segment from its push_start to its push_end place by the
// drawn robot's displacement along that segment from its centre at the
// push_start (exact at the robot's samples, where the page's pose is).

// A deployable's number in a record (`deploy` has `number`, from 1 per
// item of its robot's table; a block's later records `block` or `number`).
function deployableId(c, i) {
  for (const f of ['block', 'deployable', 'number', 'index'])
    if (c[f] && c[f][i] !== undefined && c[f][i] !== null) return c[f][i];
  return i;
}

function buildCourse(K) {
  const obstacles = rowsOf(K.obstacle).map((o) => ({
    index: o.index, name: o.name, kind: o.kind, mine: o.mine, height: o.height_ft,
    x: o.x_ft, y: o.y_ft, radius: o.radius_ft, points: o.points_ft || [],
    label: `obstacle ${o.index}` + (o.name ? ` (${o.name})` : ''),
  }));
  return { obstacles, discs: pairDiscs(K), deployables: deployables(K) };
}

// Each disc_fire with its outcome; disc numbers are reused after a disc ends.
function pairDiscs(K) {
  const discs = [];
  const open = new Map();
  const events = [];
  const add = (kind, c) => { if (c) for (let i = 0; i < c.t.length; ++i) events.push([c.t[i], kind, i]); };
  add(0, K.disc_fire);
  add(1, K.disc_hit);
  add(1.5, K.disc_miss);
  events.sort((a, b) => a[0] - b[0] || a[1] - b[1]);
  for (const [t, kind, i] of events) {
    if (kind === 0) {
      const c = K.disc_fire;
      const disc = { t0: t, robot: c.robot[i], number: c.disc[i], x0: c.x_ft[i], y0: c.y_ft[i],
        z: c.z_ft[i], vx: c.vx_fps[i], vy: c.vy_fps[i], tau: c.drag_time_s[i], end: null, outcome: null };
      open.set(`${disc.robot}:${disc.number}`, disc);
      discs.push(disc);
      continue;
    }
    const c = kind === 1 ? K.disc_hit : K.disc_miss;
    const key = `${c.robot[i]}:${c.disc[i]}`;
    const disc = open.get(key);
    if (!disc) continue;
    disc.end = t;
    disc.outcome = kind === 1 ? { hit: true, what: `hit ${ROBOT_NAMES[c.target[i]]}`, x: c.x_ft[i], y: c.y_ft[i] }
      : { hit: false, what: c.hit[i], x: c.x_ft[i], y: c.y_ft[i] };
    open.delete(key);
  }
  return discs;
}

// Where a disc is at tick t: the plant's closed form.
function discPosition(disc, t, tps) {
  const s = (t - disc.t0) / tps;
  const f = disc.tau * (1 - Math.exp(-s / disc.tau));
  return { x: disc.x0 + disc.vx * f, y: disc.y0 + disc.vy * f, z: disc.z };
}

function deployables(K) {
  const out = [];
  const byId = new Map();
  const c = K.deploy;
  if (c) for (let i = 0; i < c.t.length; ++i) {
    const get = (f, d) => (c[f] && c[f][i] !== undefined && c[f][i] !== null ? c[f][i] : d);
    const d = { t0: c.t[i], robot: c.robot[i], kind: get('kind', 'block'), id: deployableId(c, i),
      x: get('x_ft', 0), y: get('y_ft', 0), heading: get('heading_deg', 0),
      size: get('size_ft', get('side_ft', 0.5)), width: get('width_ft', 2), height: get('height_ft', 1),
      moves: { t: [], x: [], y: [] } };
    out.push(d);
    byId.set(`${d.robot}:${d.kind}:${d.id}`, d);
  }
  // A block's later positions: records other than deploy that name it, by
  // its owner (`owner`, else the record's robot) and number.
  for (const kind of Object.keys(K)) {
    if (kind === 'deploy' || !kind.startsWith('block')) continue;
    const r = K[kind];
    if (!r.x_ft || !r.y_ft) continue;
    for (let i = 0; i < r.t.length; ++i) {
      const owner = r.owner ? r.owner[i] : r.robot ? r.robot[i] : 0;
      const d = byId.get(`${owner}:block:${deployableId(r, i)}`);
      if (!d) continue;
      d.moves.t.push(r.t[i]); d.moves.x.push(r.x_ft[i]); d.moves.y.push(r.y_ft[i]);
    }
  }
  // The plant's pushes (push_start, push_end): `block` is the block's
  // number on the field, from 1 in the order blocks were set down, which
  // is the order of the block `deploy` records.
  const blocks = out.filter((d) => d.kind === 'block');
  for (const kind of ['push_start', 'push_end']) {
    const r = K[kind];
    if (!r) continue;
    for (let i = 0; i < r.t.length; ++i) {
      const d = blocks[r.block[i] - 1];
      if (!d) continue;
      d.moves.t.push(r.t[i]); d.moves.x.push(r.x_ft[i]); d.moves.y.push(r.y_ft[i]);
    }
  }
  for (const d of out) {
    const order = d.moves.t.map((_, k) => k).sort((a, b) => d.moves.t[a] - d.moves.t[b]);
    d.moves = { t: order.map((k) => d.moves.t[k]), x: order.map((k) => d.moves.x[k]), y: order.map((k) => d.moves.y[k]) };
  }
  // Each push as one span: a push_start and the next push_end of the same
  // block and robot.
  for (const d of blocks) d.pushes = [];
  const starts = rowsOf(K.push_start), ends = rowsOf(K.push_end);
  for (const s of starts) {
    const d = blocks[s.block - 1];
    const e = ends.find((x) => x.block === s.block && x.robot === s.robot && x.t >= s.t);
    if (d && e) d.pushes.push({ robot: s.robot, t0: s.t, t1: e.t, x0: s.x_ft, y0: s.y_ft, x1: e.x_ft, y1: e.y_ft,
      rx: s.robot_x_ft, ry: s.robot_y_ft });
  }
  return out;
}

// Where a block is during a push at tick t, t0 <= t < t1: on its push's
// segment, as far along it as its pusher has moved along it since the
// push_start (the robot's centre then is in the record); linear in time
// if the page has no pose of the robot.
function pushPosition(p, t, robots) {
  const dx = p.x1 - p.x0, dy = p.y1 - p.y0;
  const len = Math.hypot(dx, dy);
  if (!(len > 0)) return { x: p.x0, y: p.y0 };
  let along = p.t1 > p.t0 ? len * (t - p.t0) / (p.t1 - p.t0) : len;
  const robot = robots && robots[p.robot];
  if (robot && p.rx !== undefined && p.rx !== null) {
    const q = poseAt(robot, t);
    along = ((q.x_ft - p.rx) * dx + (q.y_ft - p.ry) * dy) / len;
  }
  const f = Math.min(1, Math.max(0, along / len));
  return { x: p.x0 + f * dx, y: p.y0 + f * dy };
}

// A deployable's centre at tick t (moving with its pusher during a push,
// else its last recorded position), or null before it was set down.
function deployablePosition(d, t, robots) {
  if (t < d.t0) return null;
  for (const p of d.pushes || []) if (p.t0 <= t && t < p.t1) return pushPosition(p, t, robots);
  const k = lastAtOrBefore(d.moves.t, t);
  return k < 0 ? { x: d.x, y: d.y } : { x: d.moves.x[k], y: d.moves.y[k] };
}

// The field's legend: every kind of thing the course can put on the
// field, each with its colour (the same in 2-D and 3-D).
const COURSE_STYLE = {
  obstacle: { color: '#8d7b68', label: 'obstacle' },
  mine: { color: '#d04040', label: 'mine (obstacle, mine = true)' },
  disc: { color: '#f5f0a0', label: 'disc in flight' },
  block: { color: '#b08850', label: 'deployed block' },
  decoy_light: { color: '#ff5050', label: 'decoy light' },
  decoy_screen: { color: '#7090b0', label: 'decoy screen' },
};

// Draws the course's things at tick t through the field's transform;
// returns counts of what it drew (the test hook's).
function drawCourse2d(ctx, px, py, scale, model, t) {
  const drawn = { obstacles: 0, mines: 0, discs: 0, blocks: 0, decoy_lights: 0, decoy_screens: 0 };
  for (const o of model.course.obstacles) {
    const style = COURSE_STYLE[o.mine ? 'mine' : 'obstacle'];
    ctx.fillStyle = style.color;
    ctx.strokeStyle = '#202020';
    ctx.lineWidth = 1.5;
    ctx.beginPath();
    if (o.kind === 'circle') {
      ctx.arc(px(o.x), py(o.y), o.radius * scale, 0, 2 * Math.PI);
    } else {
      for (let k = 0; k + 1 < o.points.length; k += 2)
        (k ? ctx.lineTo : ctx.moveTo).call(ctx, px(o.points[k]), py(o.points[k + 1]));
      ctx.closePath();
    }
    ctx.fill();
    ctx.stroke();
    if (o.mine) {  // a mine: an X across it
      const s = 0.6 * (o.radius || 0.4) * scale;
      ctx.strokeStyle = '#ffffff';
      ctx.lineWidth = 2;
      ctx.beginPath();
      ctx.moveTo(px(o.x) - s, py(o.y) - s); ctx.lineTo(px(o.x) + s, py(o.y) + s);
      ctx.moveTo(px(o.x) - s, py(o.y) + s); ctx.lineTo(px(o.x) + s, py(o.y) - s);
      ctx.stroke();
      ++drawn.mines;
    }
    ++drawn.obstacles;
  }
  for (const d of model.course.deployables) {
    const p = deployablePosition(d, t, model.robots);
    if (!p) continue;
    const style = COURSE_STYLE[d.kind] || COURSE_STYLE.block;
    ctx.fillStyle = style.color;
    ctx.strokeStyle = style.color;
    if (d.kind === 'decoy_screen') {
      // A segment across the robot's heading when it was set down.
      const a = d.heading * Math.PI / 180, w = d.width / 2;
      const ux = Math.cos(a), uy = -Math.sin(a);
      ctx.lineWidth = Math.max(3, 0.12 * scale);
      ctx.beginPath();
      ctx.moveTo(px(p.x - ux * w), py(p.y - uy * w));
      ctx.lineTo(px(p.x + ux * w), py(p.y + uy * w));
      ctx.stroke();
      ++drawn.decoy_screens;
    } else if (d.kind === 'decoy_light') {
      ctx.beginPath();
      ctx.arc(px(p.x), py(p.y), Math.max(4, 0.15 * scale), 0, 2 * Math.PI);
      ctx.fill();
      ctx.strokeStyle = '#ffd0d0';
      ctx.lineWidth = 1;
      ctx.beginPath();
      ctx.arc(px(p.x), py(p.y), Math.max(7, 0.3 * scale), 0, 2 * Math.PI);
      ctx.stroke();
      ++drawn.decoy_lights;
    } else {
      const s = d.size * scale;
      ctx.fillRect(px(p.x) - s / 2, py(p.y) - s / 2, s, s);
      ++drawn.blocks;
    }
  }
  for (const disc of model.course.discs) {
    if (t < disc.t0 || (disc.end !== null && t >= disc.end)) continue;
    const p = discPosition(disc, t, model.tps);
    ctx.strokeStyle = ROBOT_COLORS[disc.robot] + '80';
    ctx.lineWidth = 1;
    ctx.beginPath();
    ctx.moveTo(px(disc.x0), py(disc.y0));
    ctx.lineTo(px(p.x), py(p.y));
    ctx.stroke();
    ctx.fillStyle = COURSE_STYLE.disc.color;
    ctx.strokeStyle = '#303030';
    ctx.beginPath();
    ctx.ellipse(px(p.x), py(p.y), Math.max(4, 0.2 * scale), Math.max(4, 0.2 * scale), 0, 0, 2 * Math.PI);
    ctx.fill();
    ctx.stroke();
    ++drawn.discs;
  }
  return drawn;
}

// The course in the 3-D scene: obstacles built once (extruded outlines),
// discs, blocks and decoys placed at each update.
function createCourse3d(scene, model) {
  for (const o of model.course.obstacles) {
    const material = new THREE.MeshPhongMaterial({ color: COURSE_STYLE[o.mine ? 'mine' : 'obstacle'].color });
    let mesh;
    if (o.kind === 'circle') {
      mesh = new THREE.Mesh(new THREE.CylinderGeometry(o.radius, o.radius, o.height, 32), material);
      mesh.position.set(o.x, o.height / 2, -o.y);
    } else {
      // The outline in the x-(-z) plane, extruded up by the height.
      const shape = new THREE.Shape();
      for (let k = 0; k + 1 < o.points.length; k += 2)
        (k ? shape.lineTo : shape.moveTo).call(shape, o.points[k], o.points[k + 1]);
      mesh = new THREE.Mesh(new THREE.ExtrudeGeometry(shape, { depth: o.height, bevelEnabled: false }), material);
      mesh.rotation.x = -Math.PI / 2;  // shape y -> three -z, extrusion z -> three y
    }
    scene.add(mesh);
  }
  const discGeometry = new THREE.CylinderGeometry(0.2, 0.2, 0.04, 20);
  const discMaterial = new THREE.MeshPhongMaterial({ color: COURSE_STYLE.disc.color, emissive: 0x303010 });
  const discMeshes = [];
  const things = model.course.deployables.map((d) => {
    let mesh;
    if (d.kind === 'decoy_light') {
      mesh = new THREE.Mesh(new THREE.SphereGeometry(0.15, 12, 8),
        new THREE.MeshPhongMaterial({ color: COURSE_STYLE.decoy_light.color, emissive: 0x802020 }));
    } else if (d.kind === 'decoy_screen') {
      mesh = new THREE.Mesh(new THREE.BoxGeometry(d.width, d.height, 0.05),
        new THREE.MeshPhongMaterial({ color: COURSE_STYLE.decoy_screen.color }));
      mesh.rotation.y = -d.heading * Math.PI / 180;
    } else {
      mesh = new THREE.Mesh(new THREE.BoxGeometry(d.size, d.size, d.size),
        new THREE.MeshPhongMaterial({ color: COURSE_STYLE.block.color }));
    }
    mesh.visible = false;
    scene.add(mesh);
    return { d, mesh };
  });
  return function update(t) {
    for (const { d, mesh } of things) {
      const p = deployablePosition(d, t, model.robots);
      mesh.visible = p !== null;
      if (!p) continue;
      const up = d.kind === 'decoy_light' ? 0.75 : d.kind === 'decoy_screen' ? d.height / 2 : d.size / 2;
      mesh.position.set(p.x, up, -p.y);
    }
    let n = 0;
    for (const disc of model.course.discs) {
      if (t < disc.t0 || (disc.end !== null && t >= disc.end)) continue;
      if (n === discMeshes.length) {
        const mesh = new THREE.Mesh(discGeometry, discMaterial);
        scene.add(mesh);
        discMeshes.push(mesh);
      }
      const p = discPosition(disc, t, model.tps);
      discMeshes[n].position.set(p.x, p.z, -p.y);
      discMeshes[n].visible = true;
      ++n;
    }
    for (let k = n; k < discMeshes.length; ++k) discMeshes[k].visible = false;
  };
}

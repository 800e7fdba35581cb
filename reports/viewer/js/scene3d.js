// scene3d.js -- the arena in 3-D with three.js (Debian's r111, inlined).
//
// Scene units are feet. Field (x, y) maps to three's (x, -y) on the floor
// (three's z points south) with y up, so a heading h (clockwise from north)
// points along (sin h, 0, -cos h). The camera presets are the 1997
// program's: overhead, the four corners, and each robot's own eye view;
// dragging the view orbits freely from wherever the camera is.

const EYE_HEIGHT_FT = 2.6;  // the eyes sit above the robot's own beacon (thesis VII)

function createScene3d(container, model) {
  const canvas = document.createElement('canvas');
  container.appendChild(canvas);
  const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
  const clearColor = new THREE.Color(0x1a1f26);
  renderer.setClearColor(clearColor, 1);
  const scene = new THREE.Scene();
  const camera = new THREE.PerspectiveCamera(50, 1, 0.05, 200);
  const controls = new THREE.OrbitControls(camera, canvas);
  controls.enableDamping = false;
  const half = model.run.field_size_ft / 2;

  scene.add(new THREE.AmbientLight(0xffffff, 0.55));
  const sun = new THREE.DirectionalLight(0xffffff, 0.75);
  sun.position.set(-6, 20, 10);
  scene.add(sun);

  buildArena(scene, model, half);
  const robots = model.robots.map((robot) => buildRobot(scene, robot));
  const updateCourse = createCourse3d(scene, model);
  const ballGeometry = new THREE.SphereGeometry(0.09, 12, 8);
  const ballMaterial = new THREE.MeshPhongMaterial({ color: 0xffffff });
  const ballMeshes = [];

  const presets = ['overhead', 'corner SW', 'corner SE', 'corner NE', 'corner NW']
    .concat(model.robots.map((r) => `${r.name} eye`));
  let preset = 'corner SW';
  let poses = model.robots.map((r) => ({ x_ft: r.x_ft, y_ft: r.y_ft, heading_deg: r.heading_deg }));
  controls.addEventListener('start', () => { preset = 'free orbit'; notify(); });
  let onPresetChange = () => {};
  function notify() { onPresetChange(preset); }

  function placeCamera() {
    const corner = { 'corner SW': [-1, -1], 'corner SE': [1, -1], 'corner NE': [1, 1], 'corner NW': [-1, 1] };
    camera.up.set(0, 1, 0);
    if (preset === 'overhead') {
      camera.position.set(0, 3.6 * half, 0.001);
      controls.target.set(0, 0, 0);
    } else if (corner[preset]) {
      const [sx, sy] = corner[preset];
      camera.position.set(sx * (half + 3), 0.95 * half + 2, -sy * (half + 3));
      controls.target.set(0, 0, 0);
    } else if (preset.endsWith(' eye')) {
      const i = presets.indexOf(preset) - 5;
      const p = poses[i];
      const h = p.heading_deg * Math.PI / 180;
      const dx = Math.sin(h), dz = -Math.cos(h);
      const r = model.robots[i].body_diameter_ft / 2;
      camera.position.set(p.x_ft + dx * r * 0.9, EYE_HEIGHT_FT, -p.y_ft + dz * r * 0.9);
      controls.target.set(p.x_ft + dx * 10, EYE_HEIGHT_FT * 0.6, -p.y_ft + dz * 10);
    } else {
      return;  // free orbit: the camera stays where the user left it
    }
    camera.lookAt(controls.target);
    controls.update();
  }

  function resize() {
    const w = container.clientWidth, h = container.clientHeight;
    renderer.setPixelRatio(window.devicePixelRatio || 1);
    renderer.setSize(w, h, false);
    camera.aspect = w / Math.max(h, 1);
    camera.updateProjectionMatrix();
  }

  function update(t, newPoses) {
    poses = newPoses;
    model.robots.forEach((robot, i) => {
      const p = poses[i];
      robots[i].position.set(p.x_ft, 0, -p.y_ft);
      robots[i].rotation.y = -p.heading_deg * Math.PI / 180;
      // In its own eye view a robot's body would fill the screen.
      robots[i].visible = preset !== `${robot.name} eye`;
    });
    const g = model.run.gravity_fps2;
    let n = 0;
    for (const ball of model.balls) {
      if (t < ball.t0 || (ball.end !== null && t >= ball.end)) continue;
      if (n === ballMeshes.length) {
        const mesh = new THREE.Mesh(ballGeometry, ballMaterial);
        scene.add(mesh);
        ballMeshes.push(mesh);
      }
      const p = ballPosition(ball, t, model.tps, g);
      ballMeshes[n].position.set(p.x, p.z + 0.09, -p.y);
      ballMeshes[n].visible = true;
      ++n;
    }
    for (let k = n; k < ballMeshes.length; ++k) ballMeshes[k].visible = false;
    updateCourse(t);
    placeCamera();
    renderer.render(scene, camera);
  }

  function setPreset(name) {
    if (!presets.includes(name)) throw new Error(`no camera preset '${name}'`);
    preset = name;
    notify();
  }

  // Renders now and counts the pixels that are not the clear colour.
  function stats() {
    renderer.render(scene, camera);
    const gl = renderer.getContext();
    const w = gl.drawingBufferWidth, h = gl.drawingBufferHeight;
    const pixels = new Uint8Array(w * h * 4);
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, pixels);
    const r = Math.round(clearColor.r * 255), gg = Math.round(clearColor.g * 255), b = Math.round(clearColor.b * 255);
    let nonBackground = 0;
    for (let k = 0; k < pixels.length; k += 4)
      if (Math.abs(pixels[k] - r) > 2 || Math.abs(pixels[k + 1] - gg) > 2 || Math.abs(pixels[k + 2] - b) > 2)
        ++nonBackground;
    return { width: w, height: h, nonBackground };
  }

  resize();
  return {
    update, resize, setPreset, stats, presets,
    preset: () => preset,
    onPreset: (f) => { onPresetChange = f; },
  };
}

function buildArena(scene, model, half) {
  const run = model.run;
  const floor = new THREE.Mesh(new THREE.PlaneGeometry(2 * half, 2 * half),
    new THREE.MeshPhongMaterial({ color: 0x2c3f2e }));
  floor.rotation.x = -Math.PI / 2;
  scene.add(floor);
  // The room's floor around the field: a robot's eye view over a low wall
  // still shows the ground it looks at, not an empty sky.
  const room = new THREE.Mesh(new THREE.PlaneGeometry(8 * half, 8 * half),
    new THREE.MeshPhongMaterial({ color: 0x3a3631 }));
  room.rotation.x = -Math.PI / 2;
  room.position.y = -0.01;
  scene.add(room);
  const grid = new THREE.GridHelper(2 * half, 2 * half, 0x3d5540, 0x3d5540);
  grid.position.y = 0.002;
  scene.add(grid);
  // field walls: thin and low, so the corner cameras see over them
  const wallMaterial = new THREE.MeshPhongMaterial({ color: 0x8a8f98 });
  const wallHeight = 0.5, wallThick = 0.1;
  for (const [w, d, x, z] of [[2 * half, wallThick, 0, -half], [2 * half, wallThick, 0, half],
    [wallThick, 2 * half, -half, 0], [wallThick, 2 * half, half, 0]]) {
    const wall = new THREE.Mesh(new THREE.BoxGeometry(w, wallHeight, d), wallMaterial);
    wall.position.set(x, wallHeight / 2, z);
    scene.add(wall);
  }
  // the edge wire
  const wire = half - run.wire_inset_ft;
  const points = [[-wire, -wire], [wire, -wire], [wire, wire], [-wire, wire], [-wire, -wire]]
    .map(([x, y]) => new THREE.Vector3(x, 0.01, -y));
  scene.add(new THREE.Line(new THREE.BufferGeometry().setFromPoints(points),
    new THREE.LineBasicMaterial({ color: 0xe6c83c })));
  // the divider
  const length = run.divider_north_ft - run.divider_south_ft;
  const divider = new THREE.Mesh(
    new THREE.BoxGeometry(Math.max(run.divider_thickness_ft, 0.02), run.divider_height_ft, length),
    new THREE.MeshPhongMaterial({ color: 0xc8c8c8 }));
  divider.position.set(run.divider_x_ft, run.divider_height_ft / 2,
    -(run.divider_south_ft + run.divider_north_ft) / 2);
  scene.add(divider);
}

// A robot: its body as a cylinder of the target height, a nose showing its
// heading, and the two eyes. Built facing north (three's -z).
function buildRobot(scene, robot) {
  const group = new THREE.Group();
  const color = [0x4aa3ff, 0xff8a3d][robot.robot];
  const r = robot.body_diameter_ft / 2, h = robot.target_height_ft;
  const body = new THREE.Mesh(new THREE.CylinderGeometry(r, r, h, 32),
    new THREE.MeshPhongMaterial({ color }));
  body.position.y = h / 2;
  group.add(body);
  const nose = new THREE.Mesh(new THREE.BoxGeometry(0.12, 0.12, 0.5),
    new THREE.MeshPhongMaterial({ color: 0x202020 }));
  nose.position.set(0, 1.5, -r - 0.15);
  group.add(nose);
  for (const side of [-1, 1]) {
    const eye = new THREE.Mesh(new THREE.SphereGeometry(0.07, 10, 8),
      new THREE.MeshPhongMaterial({ color: 0xffee88, emissive: 0x333300 }));
    eye.position.set(side * 0.12, EYE_HEIGHT_FT - 0.1, -r * 0.7);
    group.add(eye);
  }
  const beacon = new THREE.Mesh(new THREE.CylinderGeometry(0.1, 0.1, 0.25, 12),
    new THREE.MeshPhongMaterial({ color: 0xff3030, emissive: 0x661010 }));
  beacon.position.y = h + 0.12;
  group.add(beacon);
  scene.add(group);
  return group;
}

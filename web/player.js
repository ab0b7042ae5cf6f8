// player.js: the browser animation of an mbcc result (`mbcc animate`).
// Bundled with three.js and OrbitControls into one script (make web), which
// mbcc inlines into the page with the data: nothing is fetched at view time.
//
// The data (a JSON script element, id "mbcc-data", written by
// compiler/tools/animate.c) holds the output times and, per body, its
// position r and Euler parameters p at every time, the points to draw in body
// axes, an optional shape, and for a flexible body its FE nodes, beams, the
// translational mode shapes at the nodes and the modal coordinates w at every
// time.  A node is drawn at r + A(p) (x_k + scale * X_k w).
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';

const data = JSON.parse(document.getElementById('mbcc-data').textContent);
const nframes = data.time.length;
const T0 = data.time[0], T1 = data.time[nframes - 1];

// Euler parameters (e0 scalar first) -> three's quaternion (x, y, z, w)
function quat(p, f) {
  return new THREE.Quaternion(p[4 * f + 1], p[4 * f + 2], p[4 * f + 3], p[4 * f]);
}
function vec(r, f) { return new THREE.Vector3(r[3 * f], r[3 * f + 1], r[3 * f + 2]); }

// nodes of flexible body b at frame f, global, with deformation scale s
function flexNodes(b, f, s) {
  const n = b.nodes.length / 3, nm = b.nmodes, out = [];
  const q = quat(b.p, f), r = vec(b.r, f);
  for (let k = 0; k < n; k++) {
    const x = new THREE.Vector3(b.nodes[3 * k], b.nodes[3 * k + 1], b.nodes[3 * k + 2]);
    for (let j = 0; j < nm; j++) {
      const w = b.w[nm * f + j] * s, X = b.modes[j];
      x.x += X[3 * k] * w; x.y += X[3 * k + 1] * w; x.z += X[3 * k + 2] * w;
    }
    out.push(x.applyQuaternion(q).add(r));
  }
  return out;
}

// the size of the scene: the extent of every point over every frame
const box = new THREE.Box3();
for (const b of data.bodies) {
  for (let f = 0; f < nframes; f += Math.max(1, Math.floor(nframes / 50))) {
    if (b.nodes) for (const x of flexNodes(b, f, 1)) box.expandByPoint(x);
    const q = quat(b.p, f), r = vec(b.r, f);
    box.expandByPoint(r);
    for (const s of b.points) box.expandByPoint(new THREE.Vector3(...s).applyQuaternion(q).add(r));
  }
}
for (const j of data.ground_points) box.expandByPoint(new THREE.Vector3(...j));
const size = Math.max(box.getSize(new THREE.Vector3()).length(), 1e-6);
const centre = box.getCenter(new THREE.Vector3());
const thick = size * 0.012;

// --- scene ----------------------------------------------------------------
const view = document.getElementById('view');
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio);
view.appendChild(renderer.domElement);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0xf4f5f7);
const camera = new THREE.PerspectiveCamera(40, 1, size * 1e-3, size * 100);
const controls = new OrbitControls(camera, renderer.domElement);
// looking down the model's z axis (the plane of planar mechanisms), a little
// from above and the side, from just far enough that the extent of the motion
// in x and y fills the view
function frameAll() {
  const ext = box.getSize(new THREE.Vector3()), half = THREE.MathUtils.degToRad(camera.fov / 2);
  const d = 1.35 * Math.max(ext.y / 2 / Math.tan(half), ext.x / 2 / (Math.tan(half) * camera.aspect)) + ext.z / 2;
  const dir = new THREE.Vector3(0.1, 0.25, 1).normalize();
  camera.up.set(0, 1, 0);
  camera.position.copy(centre).addScaledVector(dir, Math.max(d, 0.2 * size));
  controls.target.copy(centre);
  controls.update();
}
scene.add(new THREE.HemisphereLight(0xffffff, 0x8090a0, 2.0));
const sun = new THREE.DirectionalLight(0xffffff, 1.5);
sun.position.set(1, 2, 3);
scene.add(sun);
const axes = new THREE.AxesHelper(size * 0.15);
scene.add(axes);

const palette = [0x3a6ea5, 0xc0504d, 0x4f9a5a, 0xd08a2c, 0x7d5ba6, 0x2a9d9f, 0x9c6b3f, 0x5c6770];
const groundMat = new THREE.MeshStandardMaterial({ color: 0x666a70 });
const jointMat = new THREE.MeshStandardMaterial({ color: 0x222222 });

const Y = new THREE.Vector3(0, 1, 0);
// a cylinder of radius rad from a to b (unit cylinder, moved and stretched)
const unitCyl = new THREE.CylinderGeometry(1, 1, 1, 16);
function placeCylinder(mesh, a, b, rad) {
  const d = new THREE.Vector3().subVectors(b, a), len = d.length();
  mesh.position.copy(a).addScaledVector(d, 0.5);
  if (len > 0) mesh.quaternion.setFromUnitVectors(Y, d.divideScalar(len));
  mesh.scale.set(rad, Math.max(len, 1e-9), rad);
}
function cylinder(mat, a, b, rad) {
  const m = new THREE.Mesh(unitCyl, mat);
  placeCylinder(m, a, b, rad);
  return m;
}
const unitSphere = new THREE.SphereGeometry(1, 16, 12);
function sphere(mat, rad, at) {
  const m = new THREE.Mesh(unitSphere, mat);
  m.scale.setScalar(rad);
  if (at) m.position.copy(at);
  return m;
}

// the ground's joint points and axes
for (const j of data.ground_points) scene.add(sphere(groundMat, thick * 1.6, new THREE.Vector3(...j)));
for (const a of data.ground_axes) {
  const p = new THREE.Vector3(...a.point), d = new THREE.Vector3(...a.axis);
  const half = a.kind === 'prismatic' || a.kind === 'cylindrical' ? size * 0.3 : thick * 4;
  scene.add(cylinder(groundMat, p.clone().addScaledVector(d, -half), p.clone().addScaledVector(d, half),
                     a.kind === 'prismatic' || a.kind === 'cylindrical' ? thick * 0.4 : thick * 0.8));
}

// --- bodies -----------------------------------------------------------------
const bodies = data.bodies.map((b, i) => {
  const color = b.kind === 'virtual' ? 0x9aa0a6 : palette[i % palette.length];
  const mat = new THREE.MeshStandardMaterial({ color, metalness: 0.1, roughness: 0.6 });
  const group = new THREE.Group();
  group.name = b.name;
  scene.add(group);
  const item = { data: b, group, beams: [], nodes: [] };
  if (b.nodes) {
    // flexible: beams and nodes are placed in global coordinates every frame
    const nn = b.nodes.length / 3;
    for (let k = 0; k < nn; k++) { const s = sphere(mat, thick * 0.9); scene.add(s); item.nodes.push(s); }
    for (const e of b.beams) { const c = cylinder(mat, Y, Y, thick * 0.5); scene.add(c); item.beams.push(c); }
    return item;
  }
  // rigid or virtual: everything fixed in the body frame (the group)
  const origin = new THREE.Vector3();
  if (b.shape) {
    const s = b.shape;
    let g;
    if (s.type === 'box') g = new THREE.BoxGeometry(s.size[0], s.size[1], s.size[2]);
    else if (s.type === 'sphere') g = new THREE.SphereGeometry(s.radius, 24, 16);
    else g = new THREE.CylinderGeometry(s.radius, s.radius, s.length, 24);
    const m = new THREE.Mesh(g, mat);
    if (s.type === 'cylinder') {
      // three's cylinder is along y; the model's along the named body axis
      const ax = new THREE.Vector3(...s.axis);
      m.quaternion.setFromUnitVectors(Y, ax);
    }
    m.position.set(...s.offset);
    group.add(m);
  } else if (b.kind !== 'virtual') {
    group.add(sphere(mat, thick * 2.2, origin));
  } else {
    group.add(sphere(mat, thick * 1.2, origin));
  }
  // links from the body frame origin to each of its joint and marker points
  for (const p of b.points) {
    const v = new THREE.Vector3(...p);
    if (!b.shape && v.length() > 1e-12) group.add(cylinder(mat, origin, v, thick * (b.kind === 'virtual' ? 0.4 : 0.8)));
    group.add(sphere(jointMat, thick * 1.2, v));
  }
  return item;
});

// --- playback ----------------------------------------------------------------
const ui = {
  play: document.getElementById('play'),
  slider: document.getElementById('time'),
  label: document.getElementById('tlabel'),
  speed: document.getElementById('speed'),
  speedLabel: document.getElementById('slabel'),
  scale: document.getElementById('scale'),
};
ui.slider.max = String(nframes - 1);
const hasFlex = data.bodies.some(b => b.nodes);
if (!hasFlex) document.getElementById('scalebox').style.display = 'none';
ui.scale.value = String(data.deformation_scale);

const state = { frame: 0, playing: false, time: T0, last: null, speed: 1 };
// the default speed makes one pass last about 8 s of wall time
const duration = Math.max(T1 - T0, 1e-9);
ui.speed.value = String(Math.max(-4, Math.min(1, Math.log10(duration / 8))));

function speedNow() { return Math.pow(10, Number(ui.speed.value)); }
function showSpeed() {
  const s = speedNow();
  ui.speedLabel.textContent = (s >= 0.01 ? s.toPrecision(2) : s.toExponential(1)) + '\u00d7 real time';
}

function frameAt(t) {
  // the last output time at or before t (times are increasing)
  let lo = 0, hi = nframes - 1;
  while (lo < hi) { const mid = (lo + hi + 1) >> 1; if (data.time[mid] <= t) lo = mid; else hi = mid - 1; }
  return lo;
}

function setFrame(f) {
  state.frame = f;
  const scale = Number(ui.scale.value) || 0;
  for (const item of bodies) {
    const b = item.data;
    if (b.nodes) {
      const x = flexNodes(b, f, scale);
      x.forEach((p, k) => item.nodes[k].position.copy(p));
      b.beams.forEach((e, i) => placeCylinder(item.beams[i], x[e[0]], x[e[1]], thick * 0.5));
      item.global = x;
    } else {
      item.group.position.copy(vec(b.r, f));
      item.group.quaternion.copy(quat(b.p, f));
    }
  }
  ui.slider.value = String(f);
  ui.label.textContent = 't = ' + data.time[f].toPrecision(4) + ' s  (' + (f + 1) + '/' + nframes + ')';
}

function resize() {
  const w = view.clientWidth, h = view.clientHeight;
  renderer.setSize(w, h);
  camera.aspect = w / Math.max(h, 1);
  camera.updateProjectionMatrix();
}
window.addEventListener('resize', resize);

function setPlaying(p) {
  state.playing = p;
  state.last = null;
  ui.play.textContent = p ? 'Pause' : 'Play';
}
ui.play.addEventListener('click', () => setPlaying(!state.playing));
ui.slider.addEventListener('input', () => {
  const f = Number(ui.slider.value);
  state.time = data.time[f];
  setFrame(f);
});
ui.speed.addEventListener('input', showSpeed);
ui.scale.addEventListener('input', () => setFrame(state.frame));
window.addEventListener('keydown', e => { if (e.key === ' ') { setPlaying(!state.playing); e.preventDefault(); } });

function tick(now) {
  if (state.playing) {
    if (state.last !== null) {
      state.time += (now - state.last) / 1000 * speedNow();
      if (state.time > T1) state.time = T0 + (state.time - T1) % duration; // loop
    }
    state.last = now;
    const f = frameAt(state.time);
    if (f !== state.frame) setFrame(f);
  }
  controls.update();
  renderer.render(scene, camera);
  requestAnimationFrame(tick);
}

resize();
frameAll();
showSpeed();
setFrame(0);
renderer.render(scene, camera);

// a small hook for tests and scripts: what is on the page, and the controls
window.mbccScene = {
  model: data.model,
  bodies: bodies.length,
  bodyNames: bodies.map(b => b.data.name),
  meshes: bodies.map(b => b.group.children.length + b.nodes.length + b.beams.length),
  frames: nframes,
  get frame() { return state.frame; },
  get time() { return data.time[state.frame]; },
  get playing() { return state.playing; },
  play() { setPlaying(true); },
  pause() { setPlaying(false); },
  setFrame(f) { state.time = data.time[f]; setFrame(f); renderer.render(scene, camera); },
  setSpeed(s) { ui.speed.value = String(Math.log10(s)); showSpeed(); },
  // global positions of a flexible body's nodes at the current frame (deformation scale 1)
  nodes(name) {
    const b = data.bodies.find(x => x.name === name);
    return b && b.nodes ? flexNodes(b, state.frame, 1).map(v => [v.x, v.y, v.z]) : null;
  },
  ready: true,
};
requestAnimationFrame(tick);

// prru view: draws the body poses that `prru view` computed with the pose
// kernel (prru_poses, in double) and wrote into the page as JSON numbers.
// Nothing here computes kinematics: each body's mesh is placed by the
// frame (R, p) of the data, the rails and the U-joint centres come as
// numbers too. The data arrays stay JavaScript doubles (window.prruView
// reads them back for the browser test); only WebGL sees float32.
/* global document, window, URL, Blob, performance, requestAnimationFrame */

const $ = (id) => document.getElementById(id);
const D = JSON.parse($('prru-data').textContent);

// Any failure is also said in the page, not only in the console.
window.addEventListener('error', (e) => { $('error').textContent = `prru view: ${e.message}`; });

// three.js (the pinned build/three.module.min.js) travels as text in the
// page: a module of its own through a blob: URL, so nothing is fetched.
const threeUrl = URL.createObjectURL(new Blob([$('prru-three').textContent], { type: 'text/javascript' }));
const THREE = await import(threeUrl);
URL.revokeObjectURL(threeUrl);

const F = D.frames;
const NB = D.bodies.length;
const COLORS = { rail: 0x9a9a9a, slider: 0x222222, upper: 0x2f6fd6, lower: 0xe8892b, platform: 0x3aa655, force: 0xc0143c };

// ---- scene ----
const canvas = $('view3d');
let renderer;
try {
  renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
} catch (e) {
  $('error').textContent = `prru view: this browser cannot draw WebGL here (${e.message}); the data is in the page's prru-data script`;
  throw e;
}
renderer.setPixelRatio(window.devicePixelRatio || 1);
renderer.setClearColor(0xffffff, 1);
const scene = new THREE.Scene();
scene.add(new THREE.HemisphereLight(0xffffff, 0x888888, 2.2));
const sun = new THREE.DirectionalLight(0xffffff, 1.6);
sun.position.set(1, -2, 3);
scene.add(sun);

const lo = D.extent.lo, hi = D.extent.hi;
const centre = new THREE.Vector3((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2);
const size = Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1e-3);
const L = D.length_scale;
const camera = new THREE.PerspectiveCamera(35, 1, size / 100, size * 100);
camera.up.set(0, 0, 1);

// Orbit with the mouse (drag), zoom with the wheel.
const orbit = { az: -0.9, el: 0.35, r: 2.2 * size };
function placeCamera() {
  const c = Math.cos(orbit.el);
  camera.position.set(centre.x + orbit.r * c * Math.cos(orbit.az), centre.y + orbit.r * c * Math.sin(orbit.az),
    centre.z + orbit.r * Math.sin(orbit.el));
  camera.lookAt(centre);
}
let drag = null;
canvas.addEventListener('pointerdown', (e) => { drag = [e.clientX, e.clientY]; canvas.setPointerCapture(e.pointerId); });
canvas.addEventListener('pointerup', () => { drag = null; });
canvas.addEventListener('pointermove', (e) => {
  if (!drag) return;
  orbit.az -= (e.clientX - drag[0]) * 0.01;
  orbit.el = Math.max(-1.5, Math.min(1.5, orbit.el + (e.clientY - drag[1]) * 0.01));
  drag = [e.clientX, e.clientY];
  render();
});
canvas.addEventListener('wheel', (e) => {
  e.preventDefault();
  orbit.r *= Math.exp(e.deltaY * 0.001);
  render();
}, { passive: false });

// The floor grid at the lowest rail end, for depth.
const grid = new THREE.GridHelper(2 * size, 20, 0xcccccc, 0xe4e4e4);
grid.rotation.x = Math.PI / 2;
grid.position.set(centre.x, centre.y, lo[2]);
scene.add(grid);

function material(color) {
  return new THREE.MeshStandardMaterial({ color, roughness: 0.6, metalness: 0.1 });
}

// A cylinder of radius r from a to b (fixed parts: the rails).
function fixedCylinder(a, b, r, color) {
  const va = new THREE.Vector3(...a), vb = new THREE.Vector3(...b);
  const len = va.distanceTo(vb);
  const g = new THREE.CylinderGeometry(r, r, len, 16);
  const m = new THREE.Mesh(g, material(color));
  m.position.copy(va).add(vb).multiplyScalar(0.5);
  m.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), vb.clone().sub(va).normalize());
  return m;
}

for (const r of D.rails) scene.add(fixedCylinder([r[0], r[1], r[2]], [r[0], r[1], r[3]], 0.012 * L * 4, COLORS.rail));

// One object per body, its geometry in the body's own frame (origin at the
// frame origin, the link's long axis as the kernel's frame has it).
const bodies = D.bodies.map((b) => {
  const o = new THREE.Object3D();
  o.matrixAutoUpdate = false;
  let g, color;
  if (b.kind === 'platform') {
    g = new THREE.BoxGeometry(2 * D.plate_half, 2 * D.plate_half, 0.04 * L);
    color = COLORS.platform;
  } else if (b.kind === 'slider') {
    g = new THREE.BoxGeometry(0.25 * L, 0.25 * L, 0.3 * L);
    color = COLORS.slider;
  } else {
    g = new THREE.CylinderGeometry(0.05 * L, 0.05 * L, b.length, 16);
    g.applyQuaternion(new THREE.Quaternion().setFromUnitVectors(new THREE.Vector3(0, 1, 0),
      new THREE.Vector3(...b.axis)));
    color = b.kind === 'upper' ? COLORS.upper : COLORS.lower;
  }
  o.add(new THREE.Mesh(g, material(color)));
  if (b.kind === 'platform') o.add(fixedCylinder([0, 0, 0], [0, 0, D.plate_half], 0.02 * L, COLORS.platform));
  scene.add(o);
  return o;
});

// Reaction forces on the platform at the U joints (optional).
const R_ = D.reactions;
const arrows = [];
if (R_) {
  for (let i = 0; i < R_.labels.length; i++) {
    const a = new THREE.ArrowHelper(new THREE.Vector3(0, 0, 1), new THREE.Vector3(), 1, COLORS.force, 0.2 * L, 0.1 * L);
    a.visible = false;
    scene.add(a);
    arrows.push(a);
  }
} else {
  $('arrows-label').hidden = true;
}

// ---- frames ----
const m4 = new THREE.Matrix4();
let frame = 0;

// Body b at frame k: rotation R_b (row-major) and the frame origin
// p_b - R_b com_b (p is the centre of mass, as prru_poses gives it).
function bodyMatrix(k, b, out) {
  const R = F.R[k], p = F.p[k], c = D.bodies[b].com, r = 9 * b, s = 3 * b;
  const o = [0, 1, 2].map((i) => p[s + i] - (R[r + 3 * i] * c[0] + R[r + 3 * i + 1] * c[1] + R[r + 3 * i + 2] * c[2]));
  return out.set(R[r], R[r + 1], R[r + 2], o[0], R[r + 3], R[r + 4], R[r + 5], o[1],
    R[r + 6], R[r + 7], R[r + 8], o[2], 0, 0, 0, 1);
}

function showFrame(k) {
  frame = k;
  for (let b = 0; b < NB; b++) {
    bodies[b].matrix.copy(bodyMatrix(k, b, m4));
    bodies[b].matrixWorldNeedsUpdate = true;
  }
  const on = R_ && $('arrows').checked;
  arrows.forEach((a, i) => {
    const f = R_.f[k].slice(3 * i, 3 * i + 3), at = R_.at[k].slice(3 * i, 3 * i + 3);
    const n = Math.hypot(...f);
    a.visible = on && n > 0;
    if (!a.visible) return;
    a.position.set(...at);
    a.setDirection(new THREE.Vector3(f[0] / n, f[1] / n, f[2] / n));
    const len = n * R_.scale;
    a.setLength(len, Math.min(0.3 * len, 0.25 * L), Math.min(0.15 * len, 0.12 * L));
  });
  const q = F.q[k];
  $('time').textContent = `frame ${k + 1}/${F.t.length}  t = ${F.t[k].toFixed(4)} s  ` +
    `q = (${q[0].toFixed(4)}, ${q[1].toFixed(4)}, ${q[2].toFixed(4)})`;
  if ($('scrub').value !== String(k)) $('scrub').value = String(k);
  drawMapMarker(q);
  render();
}

function resize() {
  const w = canvas.clientWidth, h = canvas.clientHeight;
  if (canvas.width !== Math.floor(w * renderer.getPixelRatio()) || canvas.height !== Math.floor(h * renderer.getPixelRatio())) {
    renderer.setSize(w, h, false);
    camera.aspect = w / Math.max(h, 1);
    camera.updateProjectionMatrix();
  }
}
function render() {
  resize();
  placeCamera();
  renderer.render(scene, camera);
}
window.addEventListener('resize', render);

// ---- play, pause, scrub ----
let playing = false, t0 = 0, wall0 = 0;
function frameAt(t) {
  let a = 0, b = F.t.length - 1;
  while (a < b) {
    const m = (a + b + 1) >> 1;
    if (F.t[m] <= t) a = m; else b = m - 1;
  }
  return a;
}
function tick(now) {
  if (!playing) return;
  const span = F.t[F.t.length - 1] - F.t[0];
  let t = t0 + (now - wall0) / 1000;
  if (t > F.t[F.t.length - 1]) { t0 = F.t[0]; wall0 = now; t = t0; }
  const k = span > 0 ? frameAt(t) : (frame + 1) % F.t.length;
  if (k !== frame) showFrame(k);
  requestAnimationFrame(tick);
}
function setPlaying(on) {
  playing = on;
  $('play').textContent = on ? 'Pause' : 'Play';
  if (on) {
    if (frame === F.t.length - 1) frame = 0;
    t0 = F.t[frame];
    wall0 = performance.now();
    requestAnimationFrame(tick);
  }
}
$('play').addEventListener('click', () => setPlaying(!playing));
$('scrub').max = String(F.t.length - 1);
$('scrub').addEventListener('input', () => { setPlaying(false); showFrame(Number($('scrub').value)); });
$('arrows').addEventListener('change', () => showFrame(frame));

// ---- w_R map (prru map CSV given with --map) ----
// Viridis, 9 stops (matplotlib's colormap, CC0).
const VIRIDIS = [[68, 1, 84], [71, 44, 122], [59, 81, 139], [44, 113, 142], [33, 144, 141],
  [39, 173, 129], [92, 200, 99], [170, 220, 50], [253, 231, 37]];
function viridis(x) {
  const s = Math.max(0, Math.min(1, x)) * (VIRIDIS.length - 1), i = Math.min(Math.floor(s), VIRIDIS.length - 2), f = s - i;
  const c = VIRIDIS[i].map((v, j) => Math.round(v + f * (VIRIDIS[i + 1][j] - v)));
  return `rgb(${c[0]},${c[1]},${c[2]})`;
}
const M = D.map;
const MAP_BOX = { x: 46, y: 10, w: 210, h: 240 };
let mapImage = null;
function mapToPixel(q1, q2) {
  const n1 = M.q1.length, n2 = M.q2.length;
  const d1 = (M.q1[n1 - 1] - M.q1[0]) / (n1 - 1), d2 = (M.q2[n2 - 1] - M.q2[0]) / (n2 - 1);
  return [MAP_BOX.x + (q1 - M.q1[0] + d1 / 2) / (n1 * d1) * MAP_BOX.w,
    MAP_BOX.y + MAP_BOX.h - (q2 - M.q2[0] + d2 / 2) / (n2 * d2) * MAP_BOX.h];
}
function drawMap() {
  const cv = $('map2d'), g = cv.getContext('2d');
  const n1 = M.q1.length, n2 = M.q2.length;
  // Colours on a log scale from the smallest ok w_R to the 98th
  // percentile (the few values near the singular locus would wash out the
  // rest); larger ones are yellow.
  const ok = M.w.filter((w, i) => M.status[i] === 'ok').sort((a, b) => a - b);
  const wlo = ok.length ? ok[0] : 1, whi = ok.length ? ok[Math.floor(0.98 * (ok.length - 1))] : 1;
  const l0 = Math.log(wlo), lw = Math.log(whi) - l0;
  g.fillStyle = '#fff';
  g.fillRect(0, 0, cv.width, cv.height);
  const cw = MAP_BOX.w / n1, ch = MAP_BOX.h / n2;
  for (let i = 0; i < n1; i++) {
    for (let j = 0; j < n2; j++) {
      const w = M.w[i * n2 + j], st = M.status[i * n2 + j];
      g.fillStyle = st === 'ok' ? viridis(lw > 0 ? (Math.log(w) - l0) / lw : 0) : st === 'other_mode' ? '#777' : '#ccc';
      g.fillRect(MAP_BOX.x + i * cw, MAP_BOX.y + MAP_BOX.h - (j + 1) * ch, cw + 0.5, ch + 0.5);
    }
  }
  g.strokeStyle = '#444';
  g.strokeRect(MAP_BOX.x, MAP_BOX.y, MAP_BOX.w, MAP_BOX.h);
  g.fillStyle = '#222';
  g.font = '11px system-ui, sans-serif';
  g.textAlign = 'center';
  g.fillText(`q1 (rad): ${M.q1[0].toPrecision(3)} .. ${M.q1[n1 - 1].toPrecision(3)}`, MAP_BOX.x + MAP_BOX.w / 2, MAP_BOX.y + MAP_BOX.h + 16);
  g.save();
  g.translate(14, MAP_BOX.y + MAP_BOX.h / 2);
  g.rotate(-Math.PI / 2);
  g.fillText(`q2 (rad): ${M.q2[0].toPrecision(3)} .. ${M.q2[n2 - 1].toPrecision(3)}`, 0, 0);
  g.restore();
  // Colour bar (log scale).
  const bx = MAP_BOX.x + MAP_BOX.w + 14;
  for (let y = 0; y < MAP_BOX.h; y++) {
    g.fillStyle = viridis(1 - y / MAP_BOX.h);
    g.fillRect(bx, MAP_BOX.y + y, 12, 1.5);
  }
  g.textAlign = 'left';
  g.fillStyle = '#222';
  g.fillText(`${whi < M.w_max ? '\u2265 ' : ''}${whi.toPrecision(3)}`, bx + 16, MAP_BOX.y + 8);
  g.fillText(`${wlo.toPrecision(3)}`, bx + 16, MAP_BOX.y + MAP_BOX.h);
  g.fillText('w_R', bx + 16, MAP_BOX.y + MAP_BOX.h / 2);
  g.fillText('grey: singular/unreachable,', MAP_BOX.x, MAP_BOX.y + MAP_BOX.h + 32);
  g.fillText('dark: other assembly mode; red: the run', MAP_BOX.x, MAP_BOX.y + MAP_BOX.h + 45);
  mapImage = g.getImageData(0, 0, cv.width, cv.height);
}
function drawMapMarker(q) {
  if (!M || !mapImage) return;
  const g = $('map2d').getContext('2d');
  g.putImageData(mapImage, 0, 0);
  g.strokeStyle = '#e00';
  g.lineWidth = 1.5;
  g.beginPath();
  F.q.forEach((qq, k) => {
    const [x, y] = mapToPixel(qq[0], qq[1]);
    if (k === 0) g.moveTo(x, y); else g.lineTo(x, y);
  });
  g.stroke();
  const [x, y] = mapToPixel(q[0], q[1]);
  g.fillStyle = '#e00';
  g.beginPath();
  g.arc(x, y, 4, 0, 2 * Math.PI);
  g.fill();
}
if (M) {
  $('map-panel').hidden = false;
  $('map-title').textContent = `w_R map at q3 = ${M.q3} m (${M.file})`;
  drawMap();
}

// ---- text (always as text nodes: user text never becomes markup) ----
const legend = [['rails', COLORS.rail], ['sliders', COLORS.slider], ['upper links', COLORS.upper],
  ['lower links', COLORS.lower], ['platform', COLORS.platform]].concat(R_ ? [['U-joint forces on P', COLORS.force]] : []);
for (const [name, c] of legend) {
  const s = document.createElement('span'), i = document.createElement('i');
  i.style.background = `#${c.toString(16).padStart(6, '0')}`;
  s.append(i, name);
  $('legend').append(s);
}
$('info').textContent = [
  `run: ${D.source.file}`,
  ...D.source.comments,
  `model: ${D.model.name} (${D.model.file}, sha256 ${D.model.sha256})`,
  D.model.description,
  `frames: ${F.t.length} of the run's ${D.source.rows} rows; t = ${F.t[0]} .. ${F.t[F.t.length - 1]} s`,
  R_ ? `arrows: force of each lower link on the platform at its U joint, ${R_.scale.toPrecision(3)} m per N` : 'no reaction columns in the run (simulate --no-reactions?)',
  M ? `map: ${M.file}` : '',
  ...(M ? M.comments : []),
  `drawn by prru ${D.prru} view with three.js r${THREE.REVISION}`,
].filter((s) => s !== '').join('\n');

// ---- what the browser test reads ----
window.prruView = {
  nframes: F.t.length,
  frame: () => frame,
  setFrame: (k) => { setPlaying(false); showFrame(k); },
  play: () => setPlaying(true),
  pause: () => setPlaying(false),
  // The data the page was given for frame k, as it holds it.
  poseAt: (k) => ({ row: F.row[k], t: F.t[k], q: F.q[k], R: F.R[k], p: F.p[k] }),
  // The placement of every body as drawn now: three.js keeps Matrix4
  // elements in a plain (double) array, column-major.
  drawn: () => bodies.map((o) => Array.from(o.matrix.elements)),
  ready: true,
};
showFrame(0);

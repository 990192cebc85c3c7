// The room inspector: one or more rooms (the JSON in #rooms, written by pipeline/viewer/payload.py) drawn with
// three.js: floor, walls, doors and windows, objects (their meshes, or boxes), and a relation graph as arrows from
// anchor to target coloured by relation. The project's plan is z-up; three.js is y-up: (x, y, z) -> (x, z, -y).
// window.viewer exposes the state the tests read (objects and edges drawn, frames) and the actions of the controls.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';

const ROOMS = JSON.parse(document.getElementById('rooms').textContent);
const RELATION = { support: 0x222222, adjacent: 0xd62728, proximal: 0xff7f0e, distant: 0x1f77b4,
                   kept: 0x2ca02c, lost: 0xd62728, unplanned: 0x9467bd };
const ROLE = { hub: 0xffd400, chain: 0x00c8ff };
const up = (x, y, z) => new THREE.Vector3(x, z, -y);
const state = { room: 0, graph: null, pruned: false, groups: false, step: null, selected: null,
                objects: 0, edges: 0, frames: 0, drawn: false, first_frame_ms: null };

const canvas = document.getElementById('view');
const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
const scene = new THREE.Scene();
scene.background = new THREE.Color(0xf4f4f4);
scene.add(new THREE.HemisphereLight(0xffffff, 0x888888, 2.2));
const sun = new THREE.DirectionalLight(0xffffff, 1.2);
sun.position.set(3, 8, 5);
scene.add(sun);
const camera = new THREE.PerspectiveCamera(50, 1, 0.05, 200);
const controls = new OrbitControls(camera, canvas);
let world = new THREE.Group();
scene.add(world);
let meshes = new Map();  // object id -> THREE.Mesh

function colour(text) {  // a stable colour per category
  let h = 0;
  for (const c of text) h = (h * 31 + c.charCodeAt(0)) >>> 0;
  return new THREE.Color().setHSL((h % 360) / 360, 0.55, 0.6);
}

function decode(b64, Type) {
  const bytes = Uint8Array.from(atob(b64), (c) => c.charCodeAt(0));
  return new Type(bytes.buffer);
}

function floorMesh(room) {
  const shape = new THREE.Shape(room.outline.map(([x, y]) => new THREE.Vector2(x, y)));
  const geometry = new THREE.ShapeGeometry(shape);
  geometry.rotateX(-Math.PI / 2);  // plan (x, y) -> (x, 0, -y)
  return new THREE.Mesh(geometry, new THREE.MeshLambertMaterial({ color: 0xdddddd, side: THREE.DoubleSide }));
}

function slab(a, b, normal, thickness, z0, z1, material) {  // a box along the segment a-b, outside its inner face
  const length = Math.hypot(b[0] - a[0], b[1] - a[1]);
  const mesh = new THREE.Mesh(new THREE.BoxGeometry(length, z1 - z0, thickness), material);
  const mid = [(a[0] + b[0]) / 2 - normal[0] * thickness / 2, (a[1] + b[1]) / 2 - normal[1] * thickness / 2];
  mesh.position.copy(up(mid[0], mid[1], (z0 + z1) / 2));
  mesh.rotation.y = Math.atan2(b[1] - a[1], b[0] - a[0]);
  return mesh;
}

function objectMesh(o) {
  let geometry;
  if (o.mesh) {
    const v = decode(o.mesh.v, Float32Array), f = decode(o.mesh.f, Uint32Array), p = new Float32Array(v.length);
    for (let i = 0; i < v.length; i += 3) { p[i] = v[i]; p[i + 1] = v[i + 2]; p[i + 2] = -v[i + 1]; }
    geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(p, 3));
    geometry.setIndex(new THREE.BufferAttribute(f, 1));
    geometry.computeVertexNormals();
  } else {
    const [cx, cy, cz, hx, hy, hz, yaw] = o.box;
    geometry = new THREE.BoxGeometry(2 * hx, 2 * hz, 2 * hy);
    geometry.rotateY(yaw);
    geometry.translate(cx, cz, -cy);
  }
  const material = new THREE.MeshLambertMaterial({ color: colour(o.category), transparent: true, opacity: 0.85,
                                                   side: THREE.DoubleSide });
  const mesh = new THREE.Mesh(geometry, material);
  mesh.userData = o;
  return mesh;
}

function anchorPoint(room, id, top) {  // where an edge starts or ends: a wall's middle, an object's top or centre
  const o = room.objects.find((x) => x.id === id);
  if (o) return up(o.box[0], o.box[1], top ? o.box[2] + o.box[5] : o.box[2]);
  const w = room.walls.find((x) => x.id === id);
  if (w) return up((w.a[0] + w.b[0]) / 2, (w.a[1] + w.b[1]) / 2, 1.0);
  return null;
}

function arrow(room, e) {
  let from = anchorPoint(room, e.source, true), to = anchorPoint(room, e.target, false);
  if (!from || !to) return null;
  if (e.edge_type === 'support') from = new THREE.Vector3(to.x, from.y, to.z);  // vertical, from the support's top
  const key = e.status in RELATION && state.graph === 'difference' ? e.status : (e.edge_type === 'support' ? 'support' : e.distance);
  const pruned = e.status === 'pruned';
  const dir = to.clone().sub(from), length = Math.max(dir.length(), 0.05);
  const helper = new THREE.ArrowHelper(dir.normalize(), from, length, pruned ? 0xaaaaaa : (RELATION[key] ?? 0x555555),
                                       Math.min(0.15, length / 3), 0.07);
  helper.userData = e;
  return helper;
}

function visible(room, id) {  // objects after the insertion step are hidden
  const o = room.objects.find((x) => x.id === id);
  return !o || state.step === null || o.order < state.step;
}

function build() {
  const room = ROOMS[state.room];
  scene.remove(world);
  world = new THREE.Group();
  meshes = new Map();
  world.add(floorMesh(room));
  const wallMaterial = new THREE.MeshLambertMaterial({ color: 0xbbbbbb, transparent: true, opacity: 0.45 });
  for (const w of room.walls) world.add(slab(w.a, w.b, w.normal, w.thickness, 0, room.height, wallMaterial));
  for (const o of room.openings) {
    const w = room.walls.find((x) => x.id === o.wall) ?? room.walls[0];
    const material = new THREE.MeshLambertMaterial({ color: o.kind === 'door' ? 0x2ca02c : 0x17becf });
    world.add(slab(o.a, o.b, w.normal, w.thickness + 0.04, o.z0, o.z1, material));
  }
  let shown = 0;
  for (const o of room.objects) {
    const mesh = objectMesh(o);
    mesh.visible = visible(room, o.id);
    shown += mesh.visible;
    if (state.groups && o.role) mesh.material.emissive = new THREE.Color(ROLE[o.role.includes('hub') ? 'hub' : 'chain']).multiplyScalar(0.5);
    if (o.id === state.selected) mesh.material.emissive = new THREE.Color(0x3355ff);
    meshes.set(o.id, mesh);
    world.add(mesh);
  }
  let drawn = 0;
  for (const e of (room.graphs[state.graph] ?? [])) {
    if (e.status === 'pruned' && !state.pruned) continue;
    if (!visible(room, e.source) || !visible(room, e.target)) continue;
    const a = arrow(room, e);
    if (a) { world.add(a); drawn += 1; }
  }
  scene.add(world);
  Object.assign(state, { objects: shown, edges: drawn, drawn: true });
  document.getElementById('counts').textContent = `${shown} objects, ${drawn} edges`;
}

function frame(room) {
  const xs = room.outline.map((p) => p[0]), ys = room.outline.map((p) => p[1]);
  const cx = (Math.min(...xs) + Math.max(...xs)) / 2, cy = (Math.min(...ys) + Math.max(...ys)) / 2;
  const span = Math.max(Math.max(...xs) - Math.min(...xs), Math.max(...ys) - Math.min(...ys), 2);
  controls.target.copy(up(cx, cy, 0.5));
  camera.position.copy(up(cx, cy - span * 0.9, span * 1.1));
  controls.update();
}

function edgesOf(id) {
  const room = ROOMS[state.room];
  return (room.graphs[state.graph] ?? []).filter((e) => e.source === id || e.target === id);
}

function describe(e) {
  const rel = e.edge_type === 'support' ? 'support' : `${e.direction ?? ''} ${e.distance ?? ''}`.trim();
  const gap = e.gap === null || e.gap === undefined ? '' : `, gap ${e.gap.toFixed(3)} m`;
  const why = e.rule ? ` (${e.rule})` : '';
  return `${e.source} → ${e.target}: ${rel}, ${e.status ?? 'kept'}${why}${gap}`;
}

function select(id) {
  state.selected = id;
  const list = document.getElementById('edges');
  list.replaceChildren(...edgesOf(id).map((e) => Object.assign(document.createElement('li'), { textContent: describe(e) })));
  const o = ROOMS[state.room].objects.find((x) => x.id === id);
  document.getElementById('picked').textContent = o ? `${o.id} (${o.category}, ${o.model})` : id;
  build();
  return edgesOf(id).map(describe);
}

function setRoom(k) {
  state.room = k;
  const room = ROOMS[k];
  const names = Object.keys(room.graphs);
  state.graph = names[0] ?? null;
  state.step = null;
  const graphs = document.getElementById('graph');
  graphs.replaceChildren(...names.map((n) => Object.assign(document.createElement('option'), { value: n, textContent: n })));
  const step = document.getElementById('step');
  step.max = room.objects.length;
  step.value = room.objects.length;
  document.getElementById('title').textContent = room.title;
  document.getElementById('edges').replaceChildren();
  frame(room);
  build();
}

function resize() {
  const w = canvas.clientWidth, h = canvas.clientHeight;
  renderer.setSize(w, h, false);
  camera.aspect = w / Math.max(h, 1);
  camera.updateProjectionMatrix();
}

const rooms = document.getElementById('room');
rooms.replaceChildren(...ROOMS.map((r, k) => Object.assign(document.createElement('option'), { value: k, textContent: r.title })));
rooms.onchange = () => setRoom(Number(rooms.value));
document.getElementById('graph').onchange = (ev) => { state.graph = ev.target.value; build(); };
document.getElementById('pruned').onchange = (ev) => { state.pruned = ev.target.checked; build(); };
document.getElementById('groups').onchange = (ev) => { state.groups = ev.target.checked; build(); };
document.getElementById('step').oninput = (ev) => { state.step = Number(ev.target.value); build(); };
canvas.addEventListener('click', (ev) => {
  const r = canvas.getBoundingClientRect();
  const pointer = new THREE.Vector2(((ev.clientX - r.left) / r.width) * 2 - 1, -((ev.clientY - r.top) / r.height) * 2 + 1);
  const ray = new THREE.Raycaster();
  ray.setFromCamera(pointer, camera);
  const hit = ray.intersectObjects([...meshes.values()].filter((m) => m.visible))[0];
  if (hit) select(hit.object.userData.id);
});
window.addEventListener('resize', resize);
window.viewer = { state, select, setRoom, build,
                  setGraph: (name) => { state.graph = name; build(); },
                  setStep: (k) => { state.step = k; build(); },
                  setPruned: (on) => { state.pruned = on; build(); } };
resize();
setRoom(0);
renderer.setAnimationLoop(() => {
  controls.update();
  renderer.render(scene, camera);
  state.frames += 1;
  if (state.frames === 1) state.first_frame_ms = performance.now();  // since the page's navigation began
});

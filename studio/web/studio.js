// dpc studio's page: the scene in three.js, the listener and sources draggable, the state
// polled from the server (GET /api/state every 150 ms, the response when its frame changes;
// docs/studio.md "API"); the surfaces' heat map (heat.js); the offline clock's sound through
// Web Audio (listen.js); with --bake, the probes and parameter maps (probes.js).
// window.studio exposes what the browser test reads.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/OrbitControls.js';
import { analyse, decayTitle, drawDecay, fillParams, statusText, materialColour } from './panels.js';
import { drawIr, fillIacc } from './ir_panel.js';
import { buildObjects, kLobeBand, lobe, meshGeometry, placeObjects, worldVertices } from './objects.js';
import { showProbes } from './probes.js';
import { heatMap } from './heat.js';
import { listenSwitch } from './listen.js';

const token = new URLSearchParams(location.search).get('token') || '';
const headers = { 'X-Dpc-Token': token, 'Content-Type': 'application/json' };
const api = (path, body) =>
  fetch(path, body ? { method: 'POST', headers, body: JSON.stringify(body) } : { headers })
    .then((r) => (r.ok ? r.json() : Promise.reject(new Error(`${path}: HTTP ${r.status}`))));
const studio = (window.studio = { ready: false, state: null, response: null, params: null, ir: null,
                                  probes: null, heat: null });

// The view: renderer, camera, orbit controls, light.
const view = document.getElementById('view');
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
view.appendChild(renderer.domElement);
const scene3 = new THREE.Scene();
scene3.background = new THREE.Color(0x15181c);
const camera = new THREE.PerspectiveCamera(50, 1, 0.05, 2000);
const controls = new OrbitControls(camera, renderer.domElement);
scene3.add(new THREE.HemisphereLight(0xffffff, 0x404050, 2.5));
function resize() {
  renderer.setSize(view.clientWidth, view.clientHeight);
  camera.aspect = view.clientWidth / view.clientHeight;
  camera.updateProjectionMatrix();
}
addEventListener('resize', resize);

// The mesh, one colour per material, seen from both sides (the camera is often inside).
function buildMesh(sc) {
  const geo = meshGeometry(sc);
  const mat = new THREE.MeshLambertMaterial({ vertexColors: true, side: THREE.DoubleSide,
                                              transparent: true, opacity: 0.55, depthWrite: false });
  const mesh = new THREE.Mesh(geo, mat);
  scene3.add(mesh, new THREE.LineSegments(new THREE.EdgesGeometry(geo, 20),
                                          new THREE.LineBasicMaterial({ color: 0x8090a0 })));
  geo.computeBoundingSphere();
  const { center, radius } = geo.boundingSphere;
  camera.position.copy(center).add(new THREE.Vector3(0.6, 1.1, 1.0).multiplyScalar(radius * 1.3));
  controls.target.copy(center);
  controls.update();
  return mesh;
}

// Markers: a sphere per source (red) and per listener (blue, played one lighter) with a cone
// pointing where it faces.
function marker(colour, radius, withNose) {
  const g = new THREE.Group();
  g.add(new THREE.Mesh(new THREE.SphereGeometry(radius, 24, 16), new THREE.MeshLambertMaterial({ color: colour })));
  if (withNose) {
    const nose = new THREE.Mesh(new THREE.ConeGeometry(radius * 0.5, radius * 1.6, 16),
                                new THREE.MeshLambertMaterial({ color: 0xffffff }));
    nose.rotation.z = -Math.PI / 2;  // the cone's +y to +x, the rest pose's forward
    nose.position.x = radius * 1.2;
    g.add(nose);
  }
  scene3.add(g);
  return g;
}
let mesh, sourceMarkers = [], listenerMarkers = [], objectGroups = [], paintHeat = () => {};
const pathLines = new THREE.LineSegments(new THREE.BufferGeometry(),
                                         new THREE.LineBasicMaterial({ color: 0xffd060 }));
const directLine = new THREE.Line(new THREE.BufferGeometry(), new THREE.LineBasicMaterial({ color: 0x60ff90 }));
const edgeLines = new THREE.LineSegments(new THREE.BufferGeometry(),
                                         new THREE.LineBasicMaterial({ color: 0xff40ff, depthTest: false }));
scene3.add(pathLines, directLine, edgeLines);

// Exact early paths source -> reflection points -> listener, and the direct sound.
function drawPaths(st) {
  const s = st.sources[st.source], l = st.listeners[st.played], seg = [];
  for (const p of st.paths) {
    const pts = [s, ...p.points, l];
    for (let k = 0; k + 1 < pts.length; ++k) seg.push(...pts[k], ...pts[k + 1]);
  }
  pathLines.geometry.setAttribute('position', new THREE.Float32BufferAttribute(seg, 3));
  directLine.visible = st.direct.visible;
  directLine.geometry.setAttribute('position', new THREE.Float32BufferAttribute([...s, ...l], 3));
  edgeLines.geometry.setAttribute('position', new THREE.Float32BufferAttribute(st.edges.flat(), 3));
}

// Dragging: a marker moves on the horizontal plane at its height; the engine hears of it
// every 100 ms while dragging and once more on release.
let drag = null, lastSent = 0;
const raycaster = new THREE.Raycaster();
function ray(ev) {
  const r = renderer.domElement.getBoundingClientRect();
  raycaster.setFromCamera(new THREE.Vector2(((ev.clientX - r.left) / r.width) * 2 - 1,
                                            -((ev.clientY - r.top) / r.height) * 2 + 1), camera);
  return raycaster;
}
function send(kind, index, p) {
  const position = [p.x, p.y, p.z];
  if (kind === 'listener') return api('/api/listener', { position, yaw: studio.state.listenerYaw[studio.state.played] });
  return api('/api/source', { index, position });
}
// Capture phase on the view, before OrbitControls sees the press: a press on a marker drags it.
view.addEventListener('pointerdown', (ev) => {
  if (!studio.state) return;
  const all = [...listenerMarkers.map((m, i) => ['listener', i, m]), ...sourceMarkers.map((m, i) => ['source', i, m])];
  for (const [kind, index, m] of all) {
    if (kind === 'listener' && index !== studio.state.played) continue;
    if (ray(ev).intersectObject(m, true).length) {
      drag = { kind, index, m, plane: new THREE.Plane(new THREE.Vector3(0, 1, 0), -m.position.y) };
      ev.stopPropagation();
      return;
    }
  }
}, true);
renderer.domElement.addEventListener('pointermove', (ev) => {
  if (!drag) return;
  const p = new THREE.Vector3();
  if (!ray(ev).ray.intersectPlane(drag.plane, p)) return;
  drag.m.position.copy(p);
  if (performance.now() - lastSent > 100) (lastSent = performance.now()), send(drag.kind, drag.index, p);
});
addEventListener('pointerup', () => {
  if (!drag) return;
  const d = drag;
  drag = null;
  send(d.kind, d.index, d.m.position);
});
renderer.domElement.addEventListener('dblclick', (ev) => {
  const hit = mesh && ray(ev).intersectObject(mesh)[0];
  if (!hit) return;
  const l = studio.state.listeners[studio.state.played];
  api('/api/listener', { position: [hit.point.x, l[1], hit.point.z], yaw: studio.state.listenerYaw[studio.state.played] });
});
// Keys as dpc-demo --interactive: W/S forward/back, A/D left/right 0.25 m, Q/E turn 15 degrees.
addEventListener('keydown', (ev) => {
  const st = studio.state;
  if (!st || ev.target.tagName === 'SELECT') return;
  let [x, y, z] = st.listeners[st.played], yaw = st.listenerYaw[st.played];
  const f = [Math.cos(yaw), -Math.sin(yaw)], r = [Math.sin(yaw), Math.cos(yaw)], k = ev.key.toLowerCase();
  const step = { w: [1, 0], s: [-1, 0], a: [0, -1], d: [0, 1] }[k];
  if (step) (x += 0.25 * (step[0] * f[0] + step[1] * r[0])), (z += 0.25 * (step[0] * f[1] + step[1] * r[1]));
  else if (k === 'q' || k === 'e') yaw += (k === 'q' ? 1 : -1) * Math.PI / 12;
  else return;
  api('/api/listener', { position: [x, y, z], yaw });
});

// Polling: the state every 150 ms, the response (and its parameters) when its frame changed;
// the newest IR (its IACC costs the server about 0.2 s of one core) 2 s after the last one.
let centres = [], responseAt = 0;
async function pollIr() {
  const ir = await api('/api/ir');  // the newest: the server keeps the frame's after each ask
  if (ir.frame === studio.ir?.frame) return;
  studio.ir = ir;
  drawIr(document.getElementById('ir'), ir);
  fillIacc(document.getElementById('iacc'), ir, centres);
}
async function poll() {
  const st = await api('/api/state');
  studio.state = st;
  st.sources.forEach((p, i) => (drag && drag.kind === 'source' && drag.index === i) || sourceMarkers[i].position.set(...p));
  st.sourceRotations.forEach((q, i) => sourceMarkers[i].quaternion.set(...q));
  placeObjects(objectGroups, st);
  st.listeners.forEach((p, i) => {
    const m = listenerMarkers[i];
    if (!(drag && drag.kind === 'listener' && drag.index === i)) m.position.set(...p);
    m.rotation.y = st.listenerYaw[i];
    m.children[0].material.color.set(i === st.played ? 0x7fb2ff : 0x3a5f99);
  });
  drawPaths(st);
  paintHeat(st);
  document.getElementById('status').textContent = statusText(st);
  if (studio.response?.frame !== st.frame && performance.now() - responseAt > 250) {
    responseAt = performance.now();
    const resp = await api(`/api/response?frame=${st.frame}`);
    studio.params = analyse(resp);
    studio.response = resp;
    document.getElementById('decay-title').textContent = decayTitle(resp);
    drawDecay(document.getElementById('decay'), studio.params, resp.binSeconds, centres);
    fillParams(document.getElementById('params'), studio.params, centres);
  }
  studio.ready = true;
}
function loop() {
  poll().catch((e) => console.warn(String(e))).finally(() => setTimeout(loop, 150));
}
// The IR on its own loop, 2 s after the previous answer: its IACC can take the server most of
// a second on a loaded machine, and the state must not wait for it.
function irLoop() {
  pollIr().catch((e) => console.warn(String(e))).finally(() => setTimeout(irLoop, 2000));
}

/// The page position (CSS pixels) of a world point, for tests that drag with a real mouse.
studio.screenOf = ([x, y, z]) => {
  const v = new THREE.Vector3(x, y, z).project(camera), r = renderer.domElement.getBoundingClientRect();
  return { x: r.left + ((v.x + 1) / 2) * r.width, y: r.top + ((1 - v.y) / 2) * r.height };
};

/// World positions of object i's drawn vertices, and source i's drawn balloon: the world
/// direction of its axis and its reach forward and back along it (m), for the browser test.
studio.objectVertices = (i) => worldVertices(objectGroups[i]);
/// The diffraction edges drawn, [[ax, ay, az, bx, by, bz], ...] (m), for the browser test.
studio.drawnEdges = () => {
  const a = edgeLines.geometry.attributes.position, out = [];
  for (let i = 0; a && i + 1 < a.count; i += 2)
    out.push([a.getX(i), a.getY(i), a.getZ(i), a.getX(i + 1), a.getY(i + 1), a.getZ(i + 1)]);
  return out;
};
/// Probe spheres in the scene: every InstancedMesh's instances (0 when there is no bake).
studio.drawnProbes = () => {
  let n = 0;
  scene3.traverse((o) => (n += o.isInstancedMesh ? o.count : 0));
  return n;
};
studio.balloon = (i) => {
  const b = sourceMarkers[i].getObjectByName('directivity');
  if (!b) return null;
  const o = new THREE.Vector3().setFromMatrixPosition(b.matrixWorld);
  const axis = new THREE.Vector3(1, 0, 0).transformDirection(b.matrixWorld);
  const along = worldVertices(b).map((v) => new THREE.Vector3(...v).sub(o).dot(axis));
  return { axis: axis.toArray(), forward: Math.max(...along), back: -Math.min(...along) };
};

async function start() {
  const sc = await api('/api/scene');
  centres = sc.bandCentresHz;
  document.getElementById('scene-name').textContent = sc.file;
  resize();
  mesh = buildMesh(sc);
  objectGroups = buildObjects(scene3, sc.objects);
  paintHeat = heatMap({ sc, mesh, objectGroups, studio, THREE });
  listenSwitch({ studio, token });
  sourceMarkers = sc.sources.map((s) => {
    const m = marker(0xe04040, 0.18, false), balloon = lobe(s.directivity[kLobeBand]);
    if (balloon) m.add(balloon);
    return m;
  });
  listenerMarkers = sc.listeners.map((l) => marker(0x7fb2ff, Math.min(l.radius, 0.25), true));
  const select = document.getElementById('source');
  sc.sources.forEach((s, i) => select.add(new Option(s.name, i)));
  select.onchange = () => api('/api/select', { source: Number(select.value) });
  document.getElementById('materials').innerHTML = sc.materials
    .map((m, i) => `<li><span class="swatch" style="background:${materialColour(i)}"></span>${m.name}</li>`).join('');
  // The bake's probes and maps, when dpc-demo plays from one (the scene names its file).
  if (sc.bake) await showProbes(api, { scene3, element: view, ray, studio, sourceNames: sc.sources.map((s) => s.name) });
  renderer.setAnimationLoop(() => { controls.update(); renderer.render(scene3, camera); });
  loop();
  irLoop();
}
start().catch((e) => console.error(String(e)));

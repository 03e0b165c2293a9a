// The browser test's moving things (tests/studio/browser_test.mjs): on scenes/two_rooms.json,
// whose door swings open at 4-5 s and shut at 9-10 s of scene time (played as a copy whose door
// loops, loopingDoorScene, so the test sees it open and shut whenever it starts), the page's drawn door
// stands where the engine traced it at every frame the test samples, and that pose is the
// scene file's keyframes interpolated at the frame's scene time (an interpolation written
// here, independent of scene/trajectory.cpp); the talker's directivity balloon points along
// the engine's forward axis with the first-order pattern's reach (scene/directivity.h).
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { sceneCopy } from './scene_copy.mjs';

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

/// q * v * conj(q): v turned by the unit quaternion q = [x, y, z, w].
function rotate([x, y, z, w], v) {
  const t = [2 * (y * v[2] - z * v[1]), 2 * (z * v[0] - x * v[2]), 2 * (x * v[1] - y * v[0])];
  return [v[0] + w * t[0] + (y * t[2] - z * t[1]), v[1] + w * t[1] + (z * t[0] - x * t[2]),
          v[2] + w * t[2] + (x * t[1] - y * t[0])];
}

/// Spherical interpolation along the shorter arc (a and b unit quaternions).
function slerp(a, b, u) {
  let d = a.reduce((s, v, i) => s + v * b[i], 0);
  const c = d < 0 ? b.map((v) => -v) : b;
  d = Math.abs(d);
  if (d > 1 - 1e-9) return a.map((v, i) => v + u * (c[i] - v));
  const th = Math.acos(d), s = Math.sin(th);
  return a.map((v, i) => (Math.sin((1 - u) * th) * v + Math.sin(u * th) * c[i]) / s);
}

/// An object's pose at time t from its keyframes: wrapped into the keyframes' span (the door
/// loops in the played copy), then clamped at the ends.
function poseAt(keys, t) {
  const t0 = keys[0].t, span = keys[keys.length - 1].t - t0;
  if (span > 0) t = t0 + (t - t0) - span * Math.floor((t - t0) / span);
  if (t <= keys[0].t) return { position: keys[0].position, rotation: keys[0].rotation };
  const last = keys[keys.length - 1];
  if (t >= last.t) return { position: last.position, rotation: last.rotation };
  const k = keys.findIndex((key) => key.t > t) - 1, a = keys[k], b = keys[k + 1];
  const u = (t - a.t) / (b.t - a.t);
  return { position: a.position.map((v, i) => v + u * (b.position[i] - v)), rotation: slerp(a.rotation, b.rotation, u) };
}

/// The OBJ's vertices ("v x y z" lines), as the scene's reader takes them (no transform).
function objVertices(file) {
  return fs.readFileSync(file, 'utf8').split('\n').filter((l) => l.startsWith('v '))
    .map((l) => l.trim().split(/\s+/).slice(1, 4).map(Number));
}

/// Largest distance between matching points of a and b.
const apart = (a, b) => Math.max(...a.map((v, i) => Math.hypot(...v.map((x, k) => x - b[i][k]))));
/// Largest distance from a point of either set to the nearest point of the other (the page's
/// mesh repeats each triangle's corners; its distinct vertices are the OBJ's).
function hausdorff(a, b) {
  const near = (p, q) => Math.min(...q.map((v) => Math.hypot(...v.map((x, k) => x - p[k]))));
  return Math.max(...a.map((p) => near(p, b)), ...b.map((p) => near(p, a)));
}

/// scenes/two_rooms.json written into dir with its door looping (its keyframes end closed, as
/// they start). Returns the copy's path.
export function loopingDoorScene(source, dir) {
  return sceneCopy(source, 'two_rooms.json', dir, (desc) => { for (const o of desc.objects) o.loop = true; });
}

/// Samples the page until it has seen the door open, shut and mid-swing; every sample's drawn
/// door checked. Returns the samples' scene times and their largest differences, m.
export async function checkMovingObjects(page, source) {
  const sceneFile = path.join(source, 'scenes/two_rooms.json');
  const desc = JSON.parse(fs.readFileSync(sceneFile, 'utf8')), door = desc.objects[0];
  const keys = door.trajectory.map((k) => ({ t: k.t, position: k.position, rotation: k.rotation }));
  const local = objVertices(path.join(path.dirname(sceneFile), door.mesh));
  const period = keys[keys.length - 1].t - keys[0].t;
  const seen = { closed: null, open: null, swinging: 0, samples: 0, drawnVsEngine: 0, engineVsKeys: 0 };
  // Bounded in time, not only in samples: on a loaded machine a sample can take seconds, and
  // the test's own timeout would end it with no word on where it stood (the page's frame and
  // scene time, how long since the frame last changed).
  const start = Date.now();
  let lastFrame = -1, frameSince = start;
  for (let i = 0; i < 3000; ++i) {
    const s = await page.evaluate(() => ({ st: window.studio.state, drawn: window.studio.objectVertices(0) }));
    if (s.st.frame !== lastFrame) (lastFrame = s.st.frame), (frameSince = Date.now());
    assert.ok(Date.now() - start < 300000,
              `door: 300 s and ${seen.samples} samples without the door seen open and shut (page at frame ${lastFrame}, ` +
              `scene time ${s.st.worldSeconds} s, unchanged for ${((Date.now() - frameSince) / 1000).toFixed(1)} s)`);
    const t = s.st.worldSeconds, pose = s.st.objects[0], keyed = poseAt(keys, t);
    const u = t - period * Math.floor(t / period);  // time within the door's loop
    const drawn = s.drawn, engine = local.map((v) => place(pose, v)), oracle = local.map((v) => place(keyed, v));
    // Float32 positions of a 2 m leaf and float quaternions: a few 1e-7 m; 1e-5 m allows
    // for three.js composing its matrix in doubles from float32 attributes.
    const d = hausdorff(drawn, engine);
    seen.drawnVsEngine = Math.max(seen.drawnVsEngine, d);
    assert.ok(d < 1e-5, `t ${t}: the drawn door is ${d} m from the engine's`);
    // The engine slerps in float (glm): 1e-4 m over a 1 m leaf is a 0.006 degree turn.
    seen.engineVsKeys = Math.max(seen.engineVsKeys, apart(engine, oracle));
    assert.ok(apart(engine, oracle) < 1e-4, `t ${t}: the engine's door is ${apart(engine, oracle)} m from the keyframes'`);
    ++seen.samples;
    if (u > 5.05 && u < 8.95) seen.open ??= { t, drawn };
    if ((u > 4.05 && u < 4.95) || (u > 9.05 && u < 9.95)) ++seen.swinging;
    if (u > 0.05 && u < 3.95) seen.closed ??= { t, drawn };
    if (seen.open && seen.closed && seen.swinging > 0) break;
    await sleep(100);
  }
  assert.ok(seen.open && seen.closed, `no frame with the door open and one with it shut (${seen.samples} samples)`);
  // The leaf turned 90 degrees about its hinge: its far edge (0.99 m out) moved by 1.4 m.
  const moved = apart(seen.open.drawn, seen.closed.drawn);  // the same vertices, in order
  assert.ok(moved > 1.3, `the drawn door moved ${moved} m between ${seen.closed.t} s and ${seen.open.t} s`);
  return { ...seen, moved, openT: seen.open.t, closedT: seen.closed.t };
}

/// world = R(rotation) * local + position.
function place(pose, v) {
  const r = rotate(pose.rotation, v);
  return r.map((x, i) => x + pose.position[i]);
}

/// The talker's balloon: its axis along the engine's rotation * +x and its reach forward and
/// back in the ratio of the first-order pattern at 1 kHz, 1 / |1 - 2a| (a from the scene file).
export async function checkDirectivity(page, source) {
  const desc = JSON.parse(fs.readFileSync(path.join(source, 'scenes/two_rooms.json'), 'utf8'));
  const a = desc.sources[0].directivity.a[4];
  const { balloon, rotation, omni } = await page.evaluate(() => ({
    balloon: window.studio.balloon(0), rotation: window.studio.state.sourceRotations[0], omni: window.studio.balloon(1) }));
  assert.equal(omni, null, 'the omni drums have a balloon');
  const axis = rotate(rotation, [1, 0, 0]);
  assert.ok(apart([balloon.axis], [axis]) < 1e-6, `balloon axis ${balloon.axis}, the engine's ${axis}`);
  // Float32 vertices: 1e-6 relative; 1e-4 leaves room for the lathe's rotation into +x.
  const ratio = balloon.forward / balloon.back, expected = 1 / Math.abs(1 - 2 * a);
  assert.ok(Math.abs(ratio / expected - 1) < 1e-4, `balloon forward/back ${ratio}, pattern ${expected}`);
  return { axis, ratio, expected, a };
}

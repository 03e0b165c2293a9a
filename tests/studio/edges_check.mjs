// The browser test's diffraction edges (tests/studio/browser_test.mjs): on
// scenes/shoebox-corner.json the listener walks in and out of a partition's shadow. At every
// frame the test samples, the edges the page draws are the engine's (/api/state's `edges`),
// each is an edge of the scene's OBJ (its endpoints two vertices of one triangle), and while
// the line of sight is blocked (a segment-triangle test written here) the engine's direct
// distance equals the shortest source-edge-listener path over the drawn edges, computed here
// from the geometry (Fermat's point on the edge: the unfolded straight line).
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const sub = (a, b) => a.map((v, i) => v - b[i]);
const dot = (a, b) => a.reduce((s, v, i) => s + v * b[i], 0);
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const norm = (a) => Math.sqrt(dot(a, a));

/// Vertices and triangles (0-based) of an OBJ file.
function readObj(file) {
  const v = [], f = [];
  for (const line of fs.readFileSync(file, 'utf8').split('\n')) {
    const w = line.trim().split(/\s+/);
    if (w[0] === 'v') v.push(w.slice(1, 4).map(Number));
    if (w[0] === 'f') f.push(w.slice(1, 4).map((x) => parseInt(x, 10) - 1));
  }
  return { v, f };
}

/// Whether the open segment p -> q crosses triangle t (Moller-Trumbore).
function crosses(p, q, [a, b, c]) {
  const d = sub(q, p), e1 = sub(b, a), e2 = sub(c, a), h = cross(d, e2), det = dot(e1, h);
  if (Math.abs(det) < 1e-12) return false;
  const s = sub(p, a), u = dot(s, h) / det, qv = cross(s, e1), v = dot(d, qv) / det, t = dot(e2, qv) / det;
  return u > 0 && v > 0 && u + v < 1 && t > 1e-6 && t < 1 - 1e-6;
}

/// The shortest path s -> Q -> l with Q on the segment a-b, or null when Q would fall outside.
function edgePathLength(s, l, a, b) {
  const len = norm(sub(b, a)), u = sub(b, a).map((x) => x / len);
  const sa = dot(sub(s, a), u), la = dot(sub(l, a), u);
  const ds = norm(sub(sub(s, a), u.map((x) => x * sa))), dl = norm(sub(sub(l, a), u.map((x) => x * la)));
  const t = sa + ((la - sa) * ds) / (ds + dl);
  return t > 0 && t < len ? Math.hypot(la - sa, ds + dl) : null;
}

/// Samples the page for `samples` frames; returns the counts and the largest differences.
export async function checkEdges(page, source, samples = 60) {
  const { v, f } = readObj(path.join(source, 'scenes/shoebox-corner.obj'));
  const meshEdge = (p, q) => {
    const i = v.findIndex((x) => norm(sub(x, p)) < 1e-5), j = v.findIndex((x) => norm(sub(x, q)) < 1e-5);
    return i >= 0 && j >= 0 && f.some((t) => t.includes(i) && t.includes(j));
  };
  const seen = { shadow: 0, inView: 0, edgesDrawn: 0, worstLength: 0 };
  for (let n = 0; n < samples; ++n, await sleep(150)) {
    const { st, drawn } = await page.evaluate(() => ({ st: window.studio.state, drawn: window.studio.drawnEdges() }));
    // Drawn from float32 attributes: the engine's floats exactly.
    assert.deepEqual(drawn, st.edges, `frame ${st.frame}: drawn edges differ from the engine's`);
    for (const e of drawn) assert.ok(meshEdge(e.slice(0, 3), e.slice(3)), `frame ${st.frame}: ${e} is not a mesh edge`);
    seen.edgesDrawn += drawn.length;
    const s = st.sources[st.source], l = st.listeners[st.played];
    if (!f.some((t) => crosses(s, l, t.map((i) => v[i])))) {
      ++seen.inView;
      continue;
    }
    ++seen.shadow;
    assert.ok(drawn.length > 0, `frame ${st.frame}: in the shadow with no edge drawn`);
    const shortest = Math.min(...drawn.map((e) => edgePathLength(s, l, e.slice(0, 3), e.slice(3)) ?? Infinity));
    // The engine's lengths are floats of a 6-7 m path (1e-6 m); the listener's position in the
    // state is the frame's, to float precision too. 1e-4 m is a 0.3 us delay.
    seen.worstLength = Math.max(seen.worstLength, Math.abs(shortest - st.direct.distance));
    assert.ok(Math.abs(shortest - st.direct.distance) < 1e-4,
              `frame ${st.frame}: shortest drawn edge path ${shortest} m, engine's direct ${st.direct.distance} m`);
  }
  assert.ok(seen.shadow >= 5, `only ${seen.shadow} frames in the shadow`);
  return seen;
}

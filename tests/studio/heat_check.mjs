// The browser test's heat map (tests/studio/browser_test.mjs): with the page's switch on, every
// triangle of the scene is drawn at the ramp position its energy per square metre gives,
// computed here from /api/scene's vertices (areas by the cross product) and the surfaces of
// /api/state's frame the page drew, with none of the page's code: 10 log10 of the density
// re the densest over 30 dB (docs/studio.md), clamped to [0, 1]; the densest triangle drawn
// with viridis's top colour and a triangle without energy with its bottom (matplotlib 3.6's
// end stops); in the closed shoebox every wall sends energy to the listener. Switched off,
// the heat map is gone.
import assert from 'node:assert/strict';

const kRangeDb = 30;
const kTop = [0.993248, 0.906157, 0.143936], kBottom = [0.267004, 0.004874, 0.329415];
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

function areasOf(m) {
  const out = [], v = (i) => m.vertices.slice(3 * i, 3 * i + 3);
  for (let t = 0; t < m.triangles.length / 3; ++t) {
    const [a, b, c] = [0, 1, 2].map((k) => v(m.triangles[3 * t + k]));
    const u = b.map((x, k) => x - a[k]), w = c.map((x, k) => x - a[k]);
    const n = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]];
    out.push(0.5 * Math.hypot(...n));
  }
  return out;
}

/// The drawn heat map and the state it was drawn from, the same frame.
async function drawnFrame(page) {
  for (let i = 0; i < 600; ++i) {
    const r = await page.evaluate(() => ({ heat: window.studio.heat, st: window.studio.state }));
    if (r.heat && r.st && r.heat.frame === r.st.frame && r.st.surfaces.triangles.length) return r;
    await sleep(100);
  }
  throw new Error('heat map: no frame drawn with energy within 60 s');
}

export async function checkHeat(page, get) {
  const scene = JSON.parse((await get('/api/scene')).body);
  const areas = areasOf(scene);
  await page.click('#heat');
  const { heat, st } = await drawnFrame(page);
  const density = areas.map(() => 0);
  st.surfaces.triangles.forEach((t, i) => { if (t < areas.length) density[t] = st.surfaces.energy[i] / areas[t]; });
  const top = Math.max(...density), densest = density.indexOf(top);
  let worst = 0;
  density.forEach((d, t) => {
    const want = d > 0 ? Math.max(0, 1 + (10 * Math.log10(d / top)) / kRangeDb) : 0;
    worst = Math.max(worst, Math.abs(heat.positions[t] - want));
  });
  assert.ok(worst < 1e-9, `heat map: drawn ramp positions differ from the energy per m^2 by ${worst}`);
  const near = (a, b) => a.every((x, k) => Math.abs(x - b[k]) < 1e-6);
  assert.ok(near(heat.colours[densest], kTop), `densest triangle ${densest} drawn ${heat.colours[densest]}`);
  density.forEach((d, t) => d === 0 && assert.ok(near(heat.colours[t], kBottom), `triangle ${t} without energy drawn ${heat.colours[t]}`));
  const withEnergy = density.filter((d) => d > 0).length;
  assert.equal(withEnergy, areas.length, `heat map: ${withEnergy} of ${areas.length} walls send energy`);
  const sorted = density.filter((d) => d > 0).sort((a, b) => a - b);
  await page.click('#heat');
  await page.waitForFunction(() => window.studio.heat === null, { timeout: 120000 });
  return { frame: heat.frame, triangles: areas.length, withEnergy, spreadDb: 10 * Math.log10(top / sorted[0]), densest };
}

// The browser test's bake view (tests/studio/browser_test.mjs): dpc-demo --studio --bake on a
// small bake of the shoebox that dpc-bake makes here. Oracle: the bake file read by h5py
// (tests/studio/bake_oracle.py, none of dpc's code). /api/bake must hold the file's probe
// positions, done mask, parameters and STI exactly (the same float32 values: nlohmann::json
// and Python both print the shortest text that reads back as the same double, so no rounding
// enters); the page must draw one sphere per probe, show the map of the file's values for the
// selected parameter, band and source (C80 at 1 kHz first, then D50 and STI chosen in its
// select), colour the least and the greatest value with viridis's two ends, and name the
// probe under the mouse with its value. Without --bake, /api/bake is 404 and nothing is drawn.
// With the listener put on a probe, the decay panel's response (/api/response) must be the
// bake's there (bake_oracle.py --response), labelled as the bake's.
import assert from 'node:assert/strict';
import { execFileSync, spawnSync } from 'node:child_process';
import fs from 'node:fs';
import http from 'node:http';
import path from 'node:path';

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
/// The instance colours are stored as float32 in linear light and read back as sRGB: 1e-5 is
/// that round trip's error with room to spare, and 400 times below one 8-bit step.
const kColourTolerance = 1e-5;

/// A small bake of the shoebox (as tests/bake/bake_clarity_test.sh); null when this build has
/// no dpc-bake (no HDF5) or no Python with h5py was given.
export function makeBake(build, source, work, python) {
  const bake = path.join(build, 'apps/dpc-bake');
  if (!python || !fs.existsSync(bake)) return null;
  const file = path.join(work, 'studio-bake.h5');
  execFileSync(bake, [path.join(source, 'scenes/shoebox.json'), '--out', file, '--spacing', '2', '--rays', '500',
                      '--frames', '4', '--threads', '1', '--quiet'], { stdio: 'inherit' });
  const oracle = JSON.parse(execFileSync(python, [path.join(source, 'tests/studio/bake_oracle.py'), file],
                                         { encoding: 'utf8', maxBuffer: 1 << 28 }));
  return { file, oracle, python, source };
}

/// A bake that does not open: one line on stderr naming the file, a non-zero exit.
export function checkBadBake(demo, scene, work) {
  const file = path.join(work, 'not-a-bake.h5');
  fs.writeFileSync(file, 'not hdf5\n');
  const r = spawnSync(demo, [scene, '--studio', '--offline', path.join(work, 'never.wav'), '--bake', file],
                      { encoding: 'utf8' });
  assert.notEqual(r.status, 0, 'a bad bake accepted');
  const lines = r.stderr.trim().split('\n');
  assert.equal(lines.length, 1, r.stderr);
  assert.ok(lines[0].includes(file), lines[0]);
  assert.ok(!r.stdout.includes('studio:'), 'served a page with a bad bake');
}

/// Without --bake: /api/bake is 404, the page draws no probe and hides the bake panel.
export async function checkNoBake(page, get) {
  assert.equal((await get('/api/bake')).status, 404, '/api/bake without --bake');
  const seen = await page.evaluate(() => ({ probes: window.studio.probes, drawn: window.studio.drawnProbes(),
                                            hidden: document.getElementById('bake').hidden }));
  assert.deepEqual(seen, { probes: null, drawn: 0, hidden: true });
}

/// /api/bake against the file: every probe, done flag, parameter, band, source and STI.
function checkDocument(doc, o) {
  assert.deepEqual(doc.probes, o.positions.flat(), 'probe positions');
  assert.deepEqual(doc.done, o.done, 'done mask');
  assert.deepEqual(doc.parameters, [...o.columns, 'STI']);
  assert.deepEqual(doc.bands, [63, 125, 250, 500, 1000, 2000, 4000, 8000, 'broadband']);
  const S = doc.sources, R = doc.bands.length, K = doc.parameters.length;
  assert.equal(S, o.sti[0].length);
  for (let p = 0; p < o.done.length; ++p)
    for (let s = 0; s < S; ++s)
      for (let row = 0; row < R; ++row)
        for (let k = 0; k < K; ++k) {
          const want = !o.done[p] ? null : k < K - 1 ? o.parameters[p][s][row][k] : row === R - 1 ? o.sti[p][s] : null;
          const got = doc.values[((p * S + s) * R + row) * K + k];
          assert.equal(got, want, `probe ${p} source ${s} row ${row} ${doc.parameters[k]}`);
        }
}

/// The page's map against the file's values; its colour ends against viridis's.
function checkMap(drawn, want, viridis, what) {
  assert.deepEqual(drawn.values, want, `${what}: drawn values`);
  const finite = want.map((v, p) => [v, p]).filter(([v]) => v !== null);
  const [lo] = finite.reduce((a, b) => (b[0] < a[0] ? b : a)), [hi] = finite.reduce((a, b) => (b[0] > a[0] ? b : a));
  assert.ok(hi > lo, `${what}: every probe has the same value`);
  const pLo = want.indexOf(lo), pHi = want.indexOf(hi);
  const near = (c, e) => c.every((x, i) => Math.abs(x - e[i]) <= kColourTolerance);
  assert.ok(near(drawn.colours[pLo], viridis[0]), `${what}: least ${lo} drawn ${drawn.colours[pLo]}`);
  assert.ok(near(drawn.colours[pHi], viridis[1]), `${what}: greatest ${hi} drawn ${drawn.colours[pHi]}`);
  assert.equal(drawn.min, lo);
  assert.equal(drawn.max, hi);
  return { min: lo, max: hi, probes: finite.length };
}

/// Selects `parameter` in the panel and waits for the page to draw it.
async function choose(page, parameter, names) {
  await page.select('#probe-param', String(names.indexOf(parameter)));
  await page.waitForFunction((p) => window.studio.probes.parameter === p, { timeout: 60000 }, parameter);
  return page.evaluate(() => window.studio.probes);
}

/// The mouse on probe p's centre: the tooltip names a probe whose centre is within 10 px of
/// the mouse (p, or one in front of it) and gives its drawn value to the 3 digits shown (STI:
/// below 1, so toPrecision(3) as the page prints it).
async function checkHover(page, p, centre) {
  const at = await page.evaluate((x) => window.studio.screenOf(x), centre);
  await page.mouse.move(at.x, at.y);
  await page.waitForFunction(() => window.studio.probes.hovered !== null, { timeout: 60000 });
  const { hovered, value, text, where } = await page.evaluate(() => {
    const s = window.studio, h = s.probes.hovered;
    return { hovered: h, value: s.probes.values[h], text: document.getElementById('probe-tip').textContent,
             where: s.screenOf(s.probeCentres()[h]) };
  });
  assert.ok(Math.hypot(where.x - at.x, where.y - at.y) < 10, `hovered probe ${hovered} is not under the mouse`);
  const m = text.match(/^probe (\d+): STI (\S+) ± (\S+) ratio$/);
  assert.ok(m && Number(m[1]) === hovered, `tooltip "${text}"`);
  assert.equal(Number(m[2]), Number(value.toPrecision(3)), `tooltip "${text}", value ${value}`);
  return { probe: p, hovered, text };
}

/// The bake's document and the page's probes, maps and tooltip. Returns what it measured.
export async function checkBake(page, get, o) {
  const doc = JSON.parse((await get('/api/bake')).body);
  checkDocument(doc, o);
  await page.waitForFunction(() => window.studio.probes, { timeout: 60000 });
  const P = o.done.length, first = await page.evaluate(() => window.studio.probes);
  assert.equal(first.count, P, 'instances');
  assert.equal(await page.evaluate(() => window.studio.drawnProbes()), P, 'probe spheres in the scene');
  assert.deepEqual((await page.evaluate(() => window.studio.probeCentres())).flat(), o.positions.flat(), 'drawn centres');
  assert.deepEqual([first.parameter, first.band, first.source, first.unit], ['C80', 1000, 0, 'dB']);
  const col = (name) => o.columns.indexOf(name), kBand1k = 4;
  const c80 = checkMap(first, o.parameters.map((p, i) => (o.done[i] ? p[0][kBand1k][col('C80')] : null)), o.viridis, 'C80');
  const d50Drawn = await choose(page, 'D50', doc.parameters);
  assert.deepEqual([d50Drawn.band, d50Drawn.unit], [1000, 'ratio']);
  const d50 = checkMap(d50Drawn, o.parameters.map((p, i) => (o.done[i] ? p[0][kBand1k][col('D50')] : null)), o.viridis, 'D50');
  const stiDrawn = await choose(page, 'STI', doc.parameters);
  assert.deepEqual([stiDrawn.band, stiDrawn.unit], ['broadband', 'ratio']);
  assert.ok(await page.$eval('#probe-band', (e) => e.disabled), 'STI has one row: the band select is disabled');
  const sti = checkMap(stiDrawn, o.sti.map((s, i) => (o.done[i] ? s[0] : null)), o.viridis, 'STI');
  const legend = await page.$eval('#probe-legend-text', (e) => e.textContent);
  assert.match(legend, /^STI, broadband, .*ratio/);
  const back = await choose(page, 'C80', doc.parameters);  // the band chosen before STI returns
  assert.deepEqual([back.band, back.values], [1000, first.values], 'C80 after STI');
  await choose(page, 'STI', doc.parameters);
  const pHi = stiDrawn.values.indexOf(sti.max);
  const hover = await checkHover(page, pHi, o.positions[pHi]);
  await sleep(100);
  return { probes: P, done: o.done.reduce((a, b) => a + b, 0), c80, d50, sti, hover, legend };
}

/// POST a JSON body with the token; resolves with the status.
function post(run, rawPath, body) {
  return new Promise((resolve, reject) => {
    const req = http.request({ host: '127.0.0.1', port: run.port, path: rawPath, method: 'POST',
                               headers: { 'X-Dpc-Token': run.token, 'Content-Type': 'application/json' } },
                             (res) => { res.resume(); res.on('end', () => resolve(res.statusCode)); });
    req.on('error', reject);
    req.end(JSON.stringify(body));
  });
}

/// The done probe farthest from `at` (the most reverberant place the bake has), and its distance.
function farthestProbe(o, at) {
  let best = { probe: -1, distance: -1 };
  o.positions.forEach((x, i) => {
    const d = Math.hypot(...x.map((v, k) => v - at[k]));
    if (o.done[i] && d > best.distance) best = { probe: i, distance: d };
  });
  return best;
}

/// Waits for the page's response of a frame whose direct sound was computed with the listener
/// on the probe (the engine's direct distance within 1 mm of the probe's, the radius within
/// which BakeInterpolator takes the probe alone); returns that frame's response and state.
async function responseAtProbe(page, get, distance) {
  for (let i = 0; i < 600; ++i) {
    await new Promise((r) => setTimeout(r, 100));
    const frame = await page.evaluate(() => window.studio.response?.frame);
    const s = await get(`/api/state?frame=${frame}`);
    if (s.status !== 200) continue;
    const st = JSON.parse(s.body);
    if (!st.direct.visible || Math.abs(st.direct.distance - distance) > 1e-3) continue;
    const response = await page.evaluate((f) => window.studio.response.frame === f && window.studio.response, frame);
    if (response) return { response, state: st };
  }
  throw new Error('no response with the listener on the probe within 60 s');
}

/// The page's response against the oracle's, bin by bin. Every bin without a live arrival is
/// the file's float32 value taken through the same float32 subtractions (the oracle's numpy and
/// the loader's C++ both round each IEEE operation the same way): equal exactly. The bins of
/// the live direct sound and exact paths (the frame's /api/state: what the player adds to the
/// late response, as for a traced pair) hold the oracle's value plus those paths; the direct
/// sound's bin already holds the bake's direct sound, computed from the same positions with the
/// same code as the live one. Float rounding of a few sums: 1e-5 relative. Returns the largest
/// relative difference in those bins.
function compareResponse(response, want, state) {
  assert.equal(response.bands[0].length, want.response.length, 'bins');
  const live = new Map([[want.directBin, new Array(8).fill(0)]]);
  for (const p of state.paths) {
    const k = Math.floor(p.delaySeconds / 1e-3);
    if (k >= want.response.length) continue;
    const sum = live.get(k) || new Array(8).fill(0);
    p.intensity.forEach((v, b) => (sum[b] += v));
    live.set(k, sum);
  }
  let worst = 0;
  response.bands.forEach((bins, b) => bins.forEach((v, k) => {
    if (!live.has(k)) return assert.equal(v, want.response[k][b], `band ${b} bin ${k}: page ${v}, bake ${want.response[k][b]}`);
    const w = want.response[k][b] + live.get(k)[b];
    worst = Math.max(worst, Math.abs(v - w) / w);
    assert.ok(Math.abs(v - w) <= 1e-5 * w, `band ${b}, bin ${k} with live arrivals: page ${v}, bake and paths ${w}`);
  }));
  return worst;
}

/// The decay panel with --bake: the listener put exactly on the farthest probe from the talker
/// (POST /api/listener with the file's float32 position: the engine's listener is that float),
/// where the bake's response is that probe's alone. The page's /api/response must equal the
/// oracle's (bake_oracle.py --response: the file read with h5py) plus the frame's live exact
/// paths, say "origin": "bake" and the
/// panel title "from the bake"; its D50 is below 1 in every band (the direct sound alone, what
/// a snapshot that ignored the bake showed, gives 1) and T30 exists in at least 4 bands.
export async function checkBakedDecay(page, run, bake) {
  const get = (p) => rawGet(run, p);
  const o = bake.oracle, st0 = JSON.parse((await get('/api/state')).body);
  const { probe, distance } = farthestProbe(o, st0.sources[st0.source]);
  assert.equal(await post(run, '/api/listener', { position: o.positions[probe], yaw: 0 }), 200);
  const want = JSON.parse(execFileSync(bake.python, [path.join(bake.source, 'tests/studio/bake_oracle.py'),
                                                     bake.file, '--response', String(probe), String(st0.source)],
                                       { encoding: 'utf8', maxBuffer: 1 << 28 }));
  const { response, state } = await responseAtProbe(page, get, distance);
  assert.deepEqual(state.listeners[state.played], o.positions[probe], 'the listener on the probe');
  const directWorst = compareResponse(response, want, state);
  assert.equal(response.origin, 'bake');
  assert.match(await page.$eval('#decay-title', (e) => e.textContent), /from the bake/);
  const params = await page.evaluate(() => window.studio.params.map((p) => ({ t30: p.t30, d50: p.d50 })));
  params.forEach((p, b) => assert.ok(p.d50 < 0.95, `band ${b}: D50 ${p.d50}`));
  const t30 = params.map((p) => (Number.isFinite(p.t30) ? p.t30 : null));
  assert.ok(t30.filter((v) => v !== null).length >= 4, `T30 ${t30}`);
  const fileT30 = o.parameters[probe][st0.source].slice(0, 8).map((row) => row[o.columns.indexOf('T30')]);
  return { probe, distance, frame: response.frame, directWorst, d50: params.map((p) => p.d50), t30, fileT30,
           earlyCount: want.earlyCount, earlyFound: want.earlyFound };
}

/// GET with the token -> {status, body}.
function rawGet(run, rawPath) {
  return new Promise((resolve, reject) => {
    http.get({ host: '127.0.0.1', port: run.port, path: rawPath, headers: { 'X-Dpc-Token': run.token } }, (res) => {
      let body = '';
      res.on('data', (d) => (body += d));
      res.on('end', () => resolve({ status: res.statusCode, body }));
    }).on('error', reject);
  });
}

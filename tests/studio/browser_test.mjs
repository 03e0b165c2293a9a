// dpc studio in a real browser (docs/studio.md "Tests"): dpc-demo --studio on the offline clock
// (no audio device), headless chromium through puppeteer-core. Checks: a bad --port is one
// line naming the flag; a wrong token, a foreign Origin and paths outside the studio's files
// are refused (403/404); the page loads with no console error and draws the scene; dragging
// the listener with the mouse moves the engine's listener, whose direct sound follows 1/r^2;
// the page's T30 per band equals dpc-analyze's on the same frame's energy response (labelled
// traced); the heat map draws each surface's energy per m^2 (heat_check.mjs); closing the page
// leaves the session running; with --bake, the probes and parameter
// maps equal the bake file's as h5py reads it, and with the listener on a probe the decay
// panel's response is the bake's there (bake_check.mjs). Prints what it measured.
// --live: the live clock through a JACK server already running (scripts/jack-headless.sh).
// --python PY: a Python with h5py for the bake's oracle; without it the bake view is not checked.
//   node browser_test.mjs --build B --source S --chromium PATH --npm DIR [--python PY]
//                         [--screenshot PNG] [--bake-screenshot PNG] [--live] [--bake-only]
import assert from 'node:assert/strict';
import { execFileSync, spawn, spawnSync } from 'node:child_process';
import fs from 'node:fs';
import http from 'node:http';
import { createRequire } from 'node:module';
import path from 'node:path';
import { checkBadBake, checkBake, checkBakedDecay, checkNoBake, makeBake } from './bake_check.mjs';
import { checkEdges } from './edges_check.mjs';
import { checkHeat } from './heat_check.mjs';
import { checkListen } from './listen_check.mjs';
import { sceneCopy } from './scene_copy.mjs';
import { checkDirectivity, checkMovingObjects, loopingDoorScene } from './moving_check.mjs';

const arg = (name) => { const i = process.argv.indexOf(name); return i > 0 ? process.argv[i + 1] : undefined; };
const build = path.resolve(arg('--build')), source = path.resolve(arg('--source')), work = path.join(build, 'tests/studio-work');
const puppeteer = createRequire(path.resolve(arg('--npm'), 'package.json'))('puppeteer-core');
const demo = path.join(build, 'apps/dpc-demo'), analyze = path.join(build, 'apps/dpc-analyze');
const live = process.argv.includes('--live');
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
fs.mkdirSync(work, { recursive: true });
// The shoebox, its talker's speech looping on the offline clock: the listen check hears it
// whenever it starts (tests/studio/listen_check.mjs).
const scene = live ? path.join(source, 'scenes/shoebox.json')
                   : sceneCopy(source, 'shoebox.json', work, (d) => { for (const s of d.sources) s.loop = true; });

/// A bad --port: exit 1 and one line naming the flag.
function checkBadPort() {
  for (const extra of [['--studio', '--port', '70000'], ['--port', '8080'], ['--studio', '--port', 'x']]) {
    const r = spawnSync(demo, [scene, ...extra, '--offline', path.join(work, 'never.wav')], { encoding: 'utf8' });
    assert.notEqual(r.status, 0, `${extra.join(' ')} accepted`);
    const lines = r.stderr.trim().split('\n');
    assert.equal(lines.length, 1, `${extra.join(' ')}: ${r.stderr}`);
    assert.match(lines[0], /--port/);
  }
}

/// dpc-demo --studio --offline (live: through a JACK server the caller started,
/// scripts/jack-headless.sh): resolves with {child, url, port, token} once the URL is printed.
function startDemo(sceneFile = scene, onLive = live, extra = []) {
  const clock = onLive ? ['--device', 'jack:system', '--duration', '900']
                       : ['--offline', path.join(work, 'render.wav'), '--duration', '0.5', '--quiet'];
  const child = spawn(demo, [sceneFile, '--studio', ...clock, '--rays', '2048', '--output', 'binaural', ...extra],
                      { stdio: ['ignore', 'pipe', 'inherit'] });
  child.out = '';
  return new Promise((resolve, reject) => {
    const timer = setTimeout(() => reject(new Error('no studio URL within 300 s')), 300000);
    child.on('exit', (code) => reject(new Error(`dpc-demo exited (${code}) before serving`)));
    child.stdout.on('data', (d) => {
      child.out += d;
      const m = child.out.match(/studio: (http:\/\/127\.0\.0\.1:(\d+)\/\?token=([0-9a-f]+))/);
      if (m) clearTimeout(timer), resolve({ child, url: m[1], port: Number(m[2]), token: m[3] });
    });
  });
}

/// One request with the raw path as given (no URL normalisation) -> {status, body}.
function rawGet(port, rawPath, headers = {}) {
  return new Promise((resolve, reject) => {
    http.get({ host: '127.0.0.1', port, path: rawPath, headers }, (res) => {
      let body = '';
      res.on('data', (d) => (body += d));
      res.on('end', () => resolve({ status: res.statusCode, body }));
    }).on('error', reject);
  });
}

async function checkRefusals({ port, token }) {
  const t = { 'X-Dpc-Token': token };
  for (let i = 0; i < 600 && (await rawGet(port, '/api/state', t)).status === 404; ++i) await sleep(100);
  assert.equal((await rawGet(port, '/api/state', t)).status, 200, 'no first frame within 60 s');
  assert.equal((await rawGet(port, `/?token=${token}`)).status, 200);
  assert.equal((await rawGet(port, '/api/state')).status, 403, 'no token');
  assert.equal((await rawGet(port, `/?token=${'0'.repeat(32)}`)).status, 403, 'wrong token');
  assert.equal((await rawGet(port, '/api/state', { 'X-Dpc-Token': token.slice(1) })).status, 403);
  assert.equal((await rawGet(port, '/api/state', { ...t, Origin: 'http://evil.example' })).status, 403, 'origin');
  assert.equal((await rawGet(port, '/api/state', { ...t, Origin: `http://127.0.0.1:${port}` })).status, 200);
  for (const p of ['/../../../../etc/passwd', '/%2e%2e/%2e%2e/etc/passwd', '/..%2f..%2fetc%2fpasswd',
                   '//etc/passwd', '/etc/passwd', '/vendor/../index.html', `/${path.resolve(source, 'README.md')}`]) {
    const r = await rawGet(port, `${p}?token=${token}`);
    assert.ok(r.status === 403 || r.status === 404, `${p}: HTTP ${r.status}`);
    assert.ok(!r.body.includes('root:'), p);
  }
}

/// Share of the WebGL canvas's pixels that differ from the empty background (#15181c).
const drawnShare = (page) => page.evaluate(() => {
  const c = document.querySelector('#view canvas'), g = document.createElement('canvas');
  [g.width, g.height] = [c.width, c.height];
  const x = g.getContext('2d');
  x.drawImage(c, 0, 0);
  const d = x.getImageData(0, 0, g.width, g.height).data;
  let n = 0;
  for (let i = 0; i < d.length; i += 4) n += Math.abs(d[i] - 0x15) + Math.abs(d[i + 1] - 0x18) + Math.abs(d[i + 2] - 0x1c) > 24;
  return n / (d.length / 4);
});

const state = (page) => page.evaluate(() => window.studio.state);

/// Drags the played listener with the mouse to `target` (world, m); waits for a frame whose
/// listener stands there (within 2 cm), whose direct sound was computed there (its distance
/// to the selected source within 2 cm of the target's: live, the newest pose can be ahead of
/// the newest response) and whose response the page has analysed.
async function dragListener(page, target) {
  const st = await state(page);
  const from = await page.evaluate((p) => window.studio.screenOf(p), st.listeners[st.played]);
  const to = await page.evaluate((p) => window.studio.screenOf(p), target);
  await page.mouse.move(from.x, from.y);
  await page.mouse.down();
  await page.mouse.move(to.x, to.y, { steps: 12 });
  await page.mouse.up();
  for (let i = 0; i < 300; ++i) {
    await sleep(100);
    const s = await state(page), l = s.listeners[s.played];
    const r = await page.evaluate(() => window.studio.response?.frame);
    const src = s.sources[s.source];
    const wanted = Math.hypot(...target.map((v, i) => v - src[i]));
    const computedThere = s.direct && Math.abs(s.direct.distance - wanted) < 0.02;
    if (Math.hypot(l[0] - target[0], l[2] - target[2]) < 0.02 && computedThere &&
        r >= s.frame - 1 && r > st.frame + 2) return s;
  }
  throw new Error(`the listener did not reach ${target}`);
}

/// The distance law: the direct sound's 1 kHz intensity at two distances along the line from
/// the source. Returns the measured and expected level differences, dB.
async function checkDistanceLaw(page) {
  // W first (the page's keys, as --interactive): the listener leaves its trajectory and stays.
  await page.keyboard.press('w');
  const pos = (x) => x.listeners[x.played];
  for (let i = 0, prev = await state(page); ; ++i) {
    await sleep(400);
    const now = await state(page);
    if (now.frame > prev.frame && Math.hypot(...pos(now).map((v, k) => v - pos(prev)[k])) < 1e-6) break;
    if (i > 100) throw new Error('the listener did not stop after W');
    prev = now;
  }
  const st = await state(page), s = st.sources[st.source], l = st.listeners[st.played];
  const d = Math.hypot(l[0] - s[0], l[2] - s[2]), u = [(l[0] - s[0]) / d, (l[2] - s[2]) / d];
  const at = (r) => [s[0] + u[0] * r, l[1], s[2] + u[1] * r];
  const near = await dragListener(page, at(2)), far = await dragListener(page, at(4));
  const dist = (x) => Math.hypot(...x.listeners[x.played].map((v, i) => v - x.sources[x.source][i]));
  const measured = 10 * Math.log10(near.direct.intensity[4] / far.direct.intensity[4]);
  // The frames' own distances (each within 2 cm of where the listener was dragged): live, the
  // pose read with a response may be a frame newer than the one that computed it.
  const expected = 20 * Math.log10(far.direct.distance / near.direct.distance);
  // 1/r^2 exactly, but for air absorption over the 2 m difference: 0.005 dB/m at 1 kHz, 20 C,
  // 50 % RH (ISO 9613-1), 0.01 dB; 0.05 dB leaves room for float rounding, nothing else.
  assert.ok(near.direct.visible && far.direct.visible, 'direct sound occluded');
  assert.ok(Math.abs(measured - expected) < 0.05, `direct ${measured} dB, 1/r^2 says ${expected} dB`);
  return { measured, expected, near: dist(near), far: dist(far) };
}

/// GET with the token; resolves with the body as a Buffer (404: null).
function getBytes(port, token, rawPath) {
  return new Promise((resolve, reject) => {
    http.get({ host: '127.0.0.1', port, path: rawPath, headers: { 'X-Dpc-Token': token } }, (res) => {
      const parts = [];
      res.on('data', (d) => parts.push(d));
      res.on('end', () => resolve(res.statusCode === 200 ? Buffer.concat(parts) : null));
    }).on('error', reject);
  });
}

/// The IR panel: the page's IACC against dpc-analyze --iacc on the same frame's IR exported as
/// a WAV (/api/ir.wav); the drawn waveform against the WAV's samples; the IR's onset against the
/// engine's direct sound of that frame.
async function checkIr(page, { port, token }) {
  await page.waitForFunction(() => window.studio.ir?.iacc, { timeout: 60000 });
  for (let attempt = 0; attempt < 5; ++attempt) {
    const ir = await page.evaluate(() => window.studio.ir);
    const wav = await getBytes(port, token, `/api/ir.wav?frame=${ir.frame}`);
    if (!wav) {  // the IR left the server's ring (8 kept): take a newer one
      console.log(`IR of frame ${ir.frame} no longer kept; trying a newer frame`);
      await sleep(1200);
      continue;
    }
    const file = path.join(work, 'studio-ir.wav');
    fs.writeFileSync(file, wav);
    const ref = JSON.parse(execFileSync(analyze, [file, '--iacc', '--json'], { encoding: 'utf8' })).pairs[0];
    // The frame's direct sound travels with its IR (the frame itself leaves the server's
    // 64-frame ring within about 4 s, less than an IACC takes on a loaded machine).
    const direct = ir.direct, late = ref.onsetSeconds - direct.delaySeconds;
    // The IR starts with the engine's direct sound of that frame: after it by the HRIR's own
    // onset (default.sofa: 0.35-0.6 ms measured), or before it by the zero-phase synthesis
    // band filters' leading ringing (synthesis/band_filters.h), which the 20 dB onset rule
    // meets when a reflection, not the direct sound, is the IR's peak: 1.2 ms measured, the
    // ringing falling about 13 dB per 0.25 ms ahead of that. Within [-3, +1.5] ms; another
    // pose's IR would be off by its path difference (the drag above moved the listener 2 m:
    // 5.8 ms), a time axis shifted by a block (512 samples) by 10.7 ms.
    assert.ok(direct.visible && late >= -3e-3 && late <= 1.5e-3,
              `IR onset ${ref.onsetSeconds} s, direct sound ${direct.delaySeconds} s`);
    return { frame: ir.frame, ...compareIacc(ir, ref), ...compareWaveform(ir, wav),
             onset: ref.onsetSeconds, direct };
  }
  throw new Error('no frame whose IR the server still held');
}

/// The page's IACC (early, late, whole; per band and broadband) against dpc-analyze's.
/// Both are analysis/interaural_correlation.cpp on the same float samples (a float WAV is
/// lossless) and both print doubles in full: they must agree to the last bit; 1e-12 only
/// allows for a decimal printing that does not round-trip. Returns the largest difference.
function compareIacc(ir, ref) {
  const keys = [['early', 'iaccE'], ['late', 'iaccL'], ['all', 'iaccA']];
  const rows = [...ir.iacc.bands.map((b, i) => [b, ref.bands[i]]), [ir.iacc.broadband, ref.broadband]];
  let worst = 0, finite = 0;
  for (const [mine, theirs] of rows)
    for (const [k, r] of keys) {
      assert.equal(mine[k] === null, theirs[r] === null, `IACC ${k}: page ${mine[k]}, dpc-analyze ${theirs[r]}`);
      if (mine[k] === null) continue;
      ++finite, worst = Math.max(worst, Math.abs(mine[k] - theirs[r]));
      assert.ok(mine[k] >= 0 && mine[k] <= 1 + 1e-9, `IACC ${k} ${mine[k]} outside [0, 1]`);
    }
  assert.ok(worst <= 1e-12, `IACC differs from dpc-analyze's by ${worst}`);
  assert.ok(finite >= 20, `only ${finite} IACC values`);
  return { iaccWorst: worst, iaccE: ir.iacc.broadband.early, iaccL: ir.iacc.broadband.late,
           refE: ref.broadband.iaccE, refL: ref.broadband.iaccL };
}

/// The drawn waveform's column extremes against the WAV's samples (float32 after a 44-byte
/// header, interleaved): the same floats, so equal exactly.
function compareWaveform(ir, wav) {
  const channels = wav.readUInt16LE(22), n = (wav.length - 44) / 4 / channels;
  assert.equal(channels, ir.channels);
  assert.equal(n, ir.samples);
  ir.min.forEach((lo, c) => lo.forEach((v, k) => {
    let mn = Infinity, mx = -Infinity;
    for (let i = k * ir.columnSamples; i < Math.min(n, (k + 1) * ir.columnSamples); ++i) {
      const x = wav.readFloatLE(44 + 4 * (i * channels + c));
      mn = Math.min(mn, x), mx = Math.max(mx, x);
    }
    assert.ok(v === mn && ir.max[c][k] === mx, `channel ${c} column ${k}: page ${v}..${ir.max[c][k]}, WAV ${mn}..${mx}`);
  }));
  return { columns: ir.min[0].length, samples: n };
}

/// The page's T30, EDT, C80 and D50 per band against dpc-analyze's on the same frame's energy
/// response, /api/energy.csv: the page's decay.js and dpc-analyze's room_parameters.cpp are two
/// implementations, and C80 and D50 start at the direct sound's arrival on both (the page from
/// /api/response's onsetSeconds, dpc-analyze from the file's direct row). Tolerances: the
/// file's 9 significant digits and the direct sound taken out of its bin and added back in
/// single precision (relative 1e-6 for T30 and EDT, 1e-4 dB for C80, 1e-6 for D50).
async function checkParameters(page, { port, token }) {
  for (let attempt = 0; attempt < 5; ++attempt) {
    const { frame, params } = await page.evaluate(() => ({
      frame: window.studio.response.frame,
      params: window.studio.params.map((p) => Object.fromEntries(['t30', 'edt', 'c80', 'd50'].map(
        (k) => [k, Number.isFinite(p[k]) ? p[k] : null]))) }));
    const csv = await rawGet(port, `/api/energy.csv?frame=${frame}`, { 'X-Dpc-Token': token });
    if (csv.status !== 200) {  // the frame left the server's ring: take a newer one
      console.log(`energy.csv of frame ${frame}: HTTP ${csv.status}; trying a newer frame`);
      await sleep(500);
      continue;
    }
    assert.match(csv.body, /\n0,direct,/, 'energy.csv has the direct sound on its own row');
    const file = path.join(work, 'studio-er.csv');
    fs.writeFileSync(file, csv.body);
    const ref = JSON.parse(execFileSync(analyze, [file, '--json'], { encoding: 'utf8' })).sources[0].bands;
    const tolerance = { t30: (r) => 1e-6 * r, edt: (r) => 1e-6 * r, c80: () => 1e-4, d50: () => 1e-6 };
    const finite = { t30: 0, edt: 0, c80: 0, d50: 0 };
    ref.forEach((r, b) => Object.keys(tolerance).forEach((k) => {
      const mine = params[b][k], theirs = r[k] ?? null;
      assert.equal(theirs === null, mine === null, `band ${b} ${k}: page ${mine}, dpc-analyze ${theirs}`);
      if (theirs !== null) {
        ++finite[k];
        assert.ok(Math.abs(theirs - mine) <= tolerance[k](theirs), `band ${b} ${k}: page ${mine}, dpc-analyze ${theirs}`);
      }
    }));
    Object.entries(finite).forEach(([k, n]) => assert.ok(n >= 4, `only ${n} bands with a ${k}`));
    const column = (k) => params.map((p) => p[k]);
    return { frame, t30: column('t30'), c80: column('c80'), d50: column('d50'), ref: ref.map((r) => r.t30) };
  }
  throw new Error('no frame whose energy response the server still held');
}

/// SIGINT to dpc-demo; its studio lines printed. Offline, Ctrl-C is the studio's normal end
/// (status 0); live, it interrupts playback (128 + SIGINT).
async function stopDemo(run, onLive) {
  run.child.removeAllListeners('exit');
  const exited = new Promise((r) => run.child.on('exit', (code) => r(code)));
  run.child.kill('SIGINT');
  const code = await exited;
  console.log(run.child.out.split('\n').filter((l) => l.startsWith('studio:')).join('\n'));
  if (process.exitCode !== 77) assert.equal(code, onLive ? 130 : 0, 'dpc-demo after SIGINT');
}

/// A page of the studio at `url`, loaded, with its first response analysed; `errors` collects
/// its console errors and page errors.
async function openPage(browser, url) {
  const page = await browser.newPage();
  await page.setViewport({ width: 1280, height: 800 });
  const errors = [];
  page.on('console', (m) => m.type() === 'error' && errors.push(m.text()));
  page.on('pageerror', (e) => errors.push(String(e)));
  await page.goto(url, { waitUntil: 'load', timeout: 120000 });
  await page.waitForFunction(() => window.studio?.ready && window.studio.params, { timeout: 120000 });
  return { page, errors };
}

/// The shoebox: refusals, drawing, the distance law, T30, the IR panel, the page closed.
async function shoeboxChecks(browser, run) {
  const { page, errors } = await openPage(browser, run.url);
  await sleep(500);
  const share = await drawnShare(page);
  assert.ok(share > 0.05, `the canvas is empty (${share} of its pixels drawn)`);
  await checkNoBake(page, (p) => rawGet(run.port, p, { 'X-Dpc-Token': run.token }));
  const law = await checkDistanceLaw(page);
  const t30 = await checkParameters(page, run);
  const heat = await checkHeat(page, (p) => rawGet(run.port, p, { 'X-Dpc-Token': run.token }));
  assert.equal(await page.evaluate(() => window.studio.response.origin), 'traced');
  assert.match(await page.$eval('#decay-title', (e) => e.textContent), /: traced$/);
  const ir = await checkIr(page, run);
  const heard = await checkListen(page, run, live);
  await page.screenshot({ path: arg('--screenshot') || path.join(work, 'studio.png') });
  assert.deepEqual(errors, [], 'console errors');
  const before = (await state(page)).frame;
  await page.close();
  await sleep(1500);
  const after = JSON.parse((await rawGet(run.port, '/api/state', { 'X-Dpc-Token': run.token })).body).frame;
  assert.ok(after > before, 'the session stopped with the page');
  console.log(`canvas drawn: ${(100 * share).toFixed(1)} % of pixels`);
  console.log(heard.live ? `listen (live clock): '${heard.note}'`
                         : `listen: ${heard.received} frames at ${heard.sampleRate} Hz in ${heard.chunks} chunks, AudioContext ` +
                           `${heard.state} at ${heard.clock.toFixed(2)} s, ${heard.late} late, ${heard.skipped} skipped, peak ` +
                           `${heard.peak.toFixed(4)}; ${heard.compared} frames equal to the server's`);
  console.log(`distance law: ${law.near.toFixed(3)} m -> ${law.far.toFixed(3)} m: direct 1 kHz ` +
              `${law.measured.toFixed(4)} dB, 1/r^2 ${law.expected.toFixed(4)} dB`);
  console.log(`IR frame ${ir.frame}: ${ir.samples} samples in ${ir.columns} columns equal to the WAV's; ` +
              `IACC broadband early ${ir.iaccE.toFixed(4)} (dpc-analyze ${ir.refE.toFixed(4)}), late ` +
              `${ir.iaccL.toFixed(4)} (${ir.refL.toFixed(4)}), largest difference ${ir.iaccWorst}; onset ` +
              `${(1e3 * ir.onset).toFixed(3)} ms, direct sound ${(1e3 * ir.direct.delaySeconds).toFixed(3)} ms`);
  console.log(`heat map frame ${heat.frame}: ${heat.withEnergy} of ${heat.triangles} triangles with energy, ` +
              `densest ${heat.densest}, spread ${heat.spreadDb.toFixed(2)} dB; every ramp position equals the ` +
              `energy per m^2 from /api/scene's areas, ends drawn as viridis's`);
  console.log(`T30 frame ${t30.frame}: page ${t30.t30.map((v) => v?.toFixed(4)).join(' ')}; ` +
              `dpc-analyze ${t30.ref.map((v) => v?.toFixed(4)).join(' ')}; EDT, C80 (page ` +
              `${t30.c80.map((v) => v?.toFixed(2)).join(' ')} dB) and D50 equal dpc-analyze's too`);
}

/// A scene on the offline clock (its motion happens at fixed scene times): body(page) on a
/// fresh page, no console errors, then SIGINT.
async function offlineScene(browser, file, body, extra = []) {
  const run = await startDemo(path.isAbsolute(file) ? file : path.join(source, 'scenes', file), false, extra);
  try {
    const { page, errors } = await openPage(browser, run.url);
    await body(page, run);
    assert.deepEqual(errors, [], 'console errors');
    await page.close();
  } finally {
    await stopDemo(run, false);
  }
}

/// two_rooms: the drawn door and the talker's balloon (tests/studio/moving_check.mjs).
async function twoRoomsChecks(page) {
  const dir = await checkDirectivity(page, source);
  const m = await checkMovingObjects(page, source);
  console.log(`door: ${m.samples} frames sampled (${m.swinging} mid-swing), drawn vs engine at most ` +
              `${m.drawnVsEngine.toExponential(2)} m, engine vs keyframes ${m.engineVsKeys.toExponential(2)} m; ` +
              `moved ${m.moved.toFixed(3)} m between ${m.closedT.toFixed(2)} s and ${m.openT.toFixed(2)} s`);
  console.log(`talker balloon: axis ${dir.axis.map((v) => v.toFixed(4))}, forward/back ${dir.ratio.toFixed(5)} ` +
              `against 1/|1 - 2a| = ${dir.expected.toFixed(5)} (a = ${dir.a} at 1 kHz)`);
}

/// shoebox-corner: the diffraction edges drawn (tests/studio/edges_check.mjs).
async function cornerChecks(page) {
  const e = await checkEdges(page, source);
  console.log(`edges: ${e.shadow} frames in the shadow, ${e.inView} in view, ${e.edgesDrawn} edges drawn, all ` +
              `the engine's and mesh edges; shortest drawn edge path vs the engine's direct distance at most ` +
              `${e.worstLength.toExponential(2)} m`);
}

/// shoebox --bake: the probes and maps against the bake file, the decay panel against the
/// bake's response at a probe (tests/studio/bake_check.mjs), and its T30 against dpc-analyze's.
async function bakeChecks(page, run, bake) {
  const b = await checkBake(page, (p) => rawGet(run.port, p, { 'X-Dpc-Token': run.token }), bake.oracle);
  const d = await checkBakedDecay(page, run, bake);
  const t30 = await checkParameters(page, run);
  if (arg('--bake-screenshot')) {
    await page.select('#probe-param', '4');  // C80, 1 kHz: the page's first map
    const p = await page.evaluate(() => window.studio.probes.values.indexOf(window.studio.probes.max));
    const at = await page.evaluate((i) => window.studio.screenOf(window.studio.probeCentres()[i]), p);
    await page.mouse.move(at.x, at.y);
    await sleep(300);
    await page.screenshot({ path: arg('--bake-screenshot') });
  }
  const range = (m, unit) => `${m.min.toPrecision(6)} .. ${m.max.toPrecision(6)}${unit} (${m.probes} probes)`;
  console.log(`bake: ${b.probes} probes (${b.done} done) drawn, positions and every value of /api/bake equal ` +
              `the file's (h5py); C80 1 kHz ${range(b.c80, ' dB')}, D50 1 kHz ${range(b.d50, '')}, STI ` +
              `${range(b.sti, '')}, ends drawn as viridis's; mouse on probe ${b.hover.probe}: "${b.hover.text}"`);
  const list = (v, n) => v.map((x) => (x === null ? 'NaN' : x.toFixed(n))).join(' ');
  console.log(`bake decay: listener on probe ${d.probe} (${d.distance.toFixed(3)} m from the talker), frame ` +
              `${d.frame}: /api/response equals the file's (h5py) in every bin, the bins of the live direct sound and exact paths (the file's plus those paths) within ` +
              `${d.directWorst.toExponential(2)} relative; early paths stored ${d.earlyCount} of ${d.earlyFound} found; ` +
              `D50 ${list(d.d50, 3)}; T30 page ${list(d.t30, 4)}, dpc-analyze on /api/energy.csv ` +
              `${list(t30.ref, 4)}, the bake's own parameters ${list(d.fileT30, 4)}`);
}

/// Headless chromium, or null (exit status 77: skipped) when it cannot start here.
async function launchBrowser() {
  try {
    return await puppeteer.launch({ executablePath: arg('--chromium'), headless: true,
      args: ['--no-sandbox', '--enable-unsafe-swiftshader', '--use-angle=swiftshader', '--window-size=1280,800'] });
  } catch (e) {
    console.error(`browser_test: chromium cannot start: ${e.message}: skipped`);
    process.exitCode = 77;
    return null;
  }
}

/// The shoebox's session (the clock chosen): refusals, then the page's checks.
async function shoeboxRun() {
  checkBadPort();
  const run = await startDemo();
  try {
    await checkRefusals(run);
    const browser = await launchBrowser();
    if (browser) await shoeboxChecks(browser, run).catch(async (e) => { await browser.close(); throw e; });
    return browser;
  } finally {
    await stopDemo(run, live);
  }
}

/// The bake view (needs dpc-bake in the build and --python with h5py).
async function bakeScene(browser) {
  const bake = makeBake(build, source, work, arg('--python'));
  if (!bake) return console.log('bake view not checked: no dpc-bake in this build or no --python with h5py');
  checkBadBake(demo, scene, work);
  await offlineScene(browser, 'shoebox.json', (page, run) => bakeChecks(page, run, bake), ['--bake', bake.file]);
}

// --bake-only: the bake view's checks alone (offline clock), for work on that view.
async function main() {
  const bakeOnly = process.argv.includes('--bake-only');
  const browser = bakeOnly ? await launchBrowser() : await shoeboxRun();
  if (!browser) return;
  try {
    // The door's and the walk's times are scene times: the offline clock only (live runs
    // check the shoebox).
    if (!live && !bakeOnly) {
      await offlineScene(browser, loopingDoorScene(source, work), twoRoomsChecks);
      await offlineScene(browser, 'shoebox-corner.json', cornerChecks);
    }
    if (!live) await bakeScene(browser);
  } finally {
    await browser.close();
  }
  console.log('browser_test: passed');
}
main().catch((e) => { console.error(`browser_test: ${e.stack || e}`); process.exit(1); });

// dpc studio in a real browser (docs/studio.md "Tests"): dpc-demo --studio on the offline clock
// (no audio device), headless chromium through puppeteer-core. Checks: a bad --port is one
// line naming the flag; a wrong token, a foreign Origin and paths outside the studio's files
// are refused (403/404); the page loads with no console error and draws the scene; dragging
// the listener with the mouse moves the engine's listener, whose direct sound follows 1/r^2;
// the page's T30 per band equals dpc-analyze's on the same frame's energy response; closing
// the page leaves the session running. Prints what it measured.
// --live: the live clock through a JACK server already running (scripts/jack-headless.sh).
//   node browser_test.mjs --build B --source S --chromium PATH --npm DIR [--screenshot PNG] [--live]
import assert from 'node:assert/strict';
import { execFileSync, spawn, spawnSync } from 'node:child_process';
import fs from 'node:fs';
import http from 'node:http';
import { createRequire } from 'node:module';
import path from 'node:path';

const arg = (name) => { const i = process.argv.indexOf(name); return i > 0 ? process.argv[i + 1] : undefined; };
const build = path.resolve(arg('--build')), source = path.resolve(arg('--source')), work = path.join(build, 'tests/studio-work');
const puppeteer = createRequire(path.resolve(arg('--npm'), 'package.json'))('puppeteer-core');
const demo = path.join(build, 'apps/dpc-demo'), analyze = path.join(build, 'apps/dpc-analyze');
const scene = path.join(source, 'scenes/shoebox.json'), live = process.argv.includes('--live');
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
fs.mkdirSync(work, { recursive: true });

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

/// dpc-demo --studio --offline: resolves with {child, url, port, token} once the URL is printed.
function startDemo() {
  // --live: through a JACK server (the caller starts one: scripts/jack-headless.sh).
  const clock = live ? ['--device', 'jack:system', '--duration', '900']
                     : ['--offline', path.join(work, 'render.wav'), '--duration', '0.5', '--quiet'];
  const child = spawn(demo, [scene, '--studio', ...clock, '--rays', '2048'], { stdio: ['ignore', 'pipe', 'inherit'] });
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

/// The page's T30 per band against dpc-analyze's on the same frame's energy response.
async function checkT30(page, { port, token }) {
  for (let attempt = 0; attempt < 5; ++attempt) {
    const { frame, t30 } = await page.evaluate(() => ({
      frame: window.studio.response.frame, t30: window.studio.params.map((p) => (Number.isFinite(p.t30) ? p.t30 : null)) }));
    const csv = await rawGet(port, `/api/energy.csv?frame=${frame}`, { 'X-Dpc-Token': token });
    if (csv.status !== 200) {  // the frame left the server's ring: take a newer one
      console.log(`energy.csv of frame ${frame}: HTTP ${csv.status}; trying a newer frame`);
      await sleep(500);
      continue;
    }
    const file = path.join(work, 'studio-er.csv');
    fs.writeFileSync(file, csv.body);
    const ref = JSON.parse(execFileSync(analyze, [file, '--json'], { encoding: 'utf8' })).sources[0].bands.map((b) => b.t30);
    let finite = 0;
    ref.forEach((r, b) => {
      assert.equal(r === null, t30[b] === null, `band ${b}: page ${t30[b]}, dpc-analyze ${r}`);
      if (r !== null) ++finite, assert.ok(Math.abs(r - t30[b]) <= 1e-6 * r, `band ${b}: page ${t30[b]}, dpc-analyze ${r}`);
    });
    assert.ok(finite >= 4, `only ${finite} bands with a T30`);
    return { frame, t30, ref };
  }
  throw new Error('no frame whose energy response the server still held');
}

async function main() {
  checkBadPort();
  const run = await startDemo();
  let browser;
  try {
    await checkRefusals(run);
    try {
      browser = await puppeteer.launch({ executablePath: arg('--chromium'), headless: true,
        args: ['--no-sandbox', '--enable-unsafe-swiftshader', '--use-angle=swiftshader', '--window-size=1280,800'] });
    } catch (e) {
      console.error(`browser_test: chromium cannot start: ${e.message}: skipped`);
      process.exitCode = 77;
      return;
    }
    const page = await browser.newPage();
    await page.setViewport({ width: 1280, height: 800 });
    const errors = [];
    page.on('console', (m) => m.type() === 'error' && errors.push(m.text()));
    page.on('pageerror', (e) => errors.push(String(e)));
    await page.goto(run.url, { waitUntil: 'load', timeout: 120000 });
    await page.waitForFunction(() => window.studio?.ready && window.studio.params, { timeout: 120000 });
    await sleep(500);
    const share = await drawnShare(page);
    assert.ok(share > 0.05, `the canvas is empty (${share} of its pixels drawn)`);
    const law = await checkDistanceLaw(page);
    const t30 = await checkT30(page, run);
    await page.screenshot({ path: arg('--screenshot') || path.join(work, 'studio.png') });
    assert.deepEqual(errors, [], 'console errors');
    const before = (await state(page)).frame;
    await page.close();
    await sleep(1500);
    const after = JSON.parse((await rawGet(run.port, '/api/state', { 'X-Dpc-Token': run.token })).body).frame;
    assert.ok(after > before, 'the session stopped with the page');
    console.log(`canvas drawn: ${(100 * share).toFixed(1)} % of pixels`);
    console.log(`distance law: ${law.near.toFixed(3)} m -> ${law.far.toFixed(3)} m: direct 1 kHz ` +
                `${law.measured.toFixed(4)} dB, 1/r^2 ${law.expected.toFixed(4)} dB`);
    console.log(`T30 frame ${t30.frame}: page ${t30.t30.map((v) => v?.toFixed(4)).join(' ')}; ` +
                `dpc-analyze ${t30.ref.map((v) => v?.toFixed(4)).join(' ')}`);
  } finally {
    if (browser) await browser.close();
    run.child.removeAllListeners('exit');
    const exited = new Promise((r) => run.child.on('exit', (code) => r(code)));
    run.child.kill('SIGINT');
    const code = await exited;
    console.log(run.child.out.split('\n').filter((l) => l.startsWith('studio:')).join('\n'));
    // Offline, Ctrl-C is the studio's normal end; live, it interrupts playback (128 + SIGINT).
    if (process.exitCode !== 77) assert.equal(code, live ? 130 : 0, 'dpc-demo after SIGINT');
  }
  console.log('browser_test: passed');
}
main().catch((e) => { console.error(`browser_test: ${e.stack || e}`); process.exit(1); });

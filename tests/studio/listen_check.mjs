// The browser test's "listen in the page" (tests/studio/browser_test.mjs, studio/web/listen.js).
// Offline clock: switched on with a real click (the user gesture browsers ask for), the page
// receives the session's sound from GET /api/audio and plays it through Web Audio: its
// AudioContext, made within the click (no autoplay exemption), runs and its clock advances,
// the frames it received are
// the server's, bit for bit (fetched again here for the same frame numbers), contiguous
// (nothing skipped) and not silent. That the server's sound is the render's is checked apart,
// against the offline renderer's WAV (tests/studio/page_sound_test.py). Live clock: the device
// plays, and the switch says so and turns itself off.
import assert from 'node:assert/strict';
import http from 'node:http';

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

/// GET with the session's token: status, headers and the body's bytes.
function getBytes(port, rawPath, token) {
  return new Promise((resolve, reject) => {
    http.get({ host: '127.0.0.1', port, path: rawPath, headers: { 'X-Dpc-Token': token } }, (res) => {
      const parts = [];
      res.on('data', (d) => parts.push(d));
      res.on('end', () => resolve({ status: res.statusCode, headers: res.headers, body: Buffer.concat(parts) }));
    }).on('error', reject);
  });
}

const listen = (page) => page.evaluate(() => ({ ...window.studio.listen, tap: null }));

export async function checkListen(page, run, live) {
  await page.click('#listen');
  if (live) {
    let note = '';
    for (let i = 0; i < 100 && !note; ++i) (note = await page.$eval('#listen-note', (e) => e.textContent)), await sleep(100);
    assert.match(note, /audio device plays/, `live clock: the listen switch said '${note}'`);
    assert.equal(await page.$eval('#listen', (e) => e.checked), false, 'live clock: the switch stayed on');
    return { live: true, note };
  }
  // Two seconds of sound received (a bound of 120 s for a loaded machine).
  let s = await listen(page);
  for (let i = 0; i < 1200 && !(s.sampleRate && s.received >= 2 * s.sampleRate); ++i) (s = await listen(page)), await sleep(100);
  assert.ok(s.sampleRate && s.received >= 2 * s.sampleRate, `the page received ${s.received} frames in 120 s`);
  assert.equal(s.state, 'running', `the AudioContext is ${s.state}`);
  assert.ok(s.clock > 1.0, `the AudioContext's clock stands at ${s.clock} s after 2 s of sound`);
  assert.equal(s.skipped, 0, `${s.skipped} frames skipped: the page fell more than the server's 8 s behind`);
  assert.ok(s.peak > 1e-4, `the sound is silent (peak ${s.peak})`);
  // The frames the page kept are the server's for the same frame numbers, bit for bit.
  const { tap, tapFirst, channels } = await page.evaluate(() => ({ tap: window.studio.listen.tap, tapFirst: window.studio.listen.tapFirst,
                                                                    channels: window.studio.listen.channels }));
  const r = await getBytes(run.port, `/api/audio?from=${tapFirst}`, run.token);
  assert.equal(r.status, 200);
  assert.equal(Number(r.headers['x-dpc-first']), tapFirst, 'the server no longer holds the frames the page kept');
  const server = new Float32Array(r.body.buffer, r.body.byteOffset, r.body.length / 4);
  const frames = Math.min(tap[0].length, server.length / channels);
  assert.ok(frames >= s.sampleRate, `only ${frames} frames to compare`);
  for (let c = 0; c < channels; ++c)
    for (let i = 0; i < frames; ++i)
      if (tap[c][i] !== server[i * channels + c]) assert.fail(`channel ${c} frame ${tapFirst + i}: page ${tap[c][i]}, server ${server[i * channels + c]}`);
  await page.click('#listen');
  assert.equal((await listen(page)).state, 'off', 'switched off, the page still plays');
  return { live: false, ...s, compared: frames };
}

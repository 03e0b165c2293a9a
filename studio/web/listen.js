// dpc studio's "listen" switch: on the offline clock, where no audio device plays the session,
// the page plays the session's sound through Web Audio (docs/studio.md, "Listening in the
// page"). GET /api/audio gives the frames not fetched yet as float32 (headers: the first
// frame's number, the channels, the sample rate); each chunk becomes an AudioBuffer at that
// rate (Web Audio resamples it to the context's, the device's), scheduled
// right after the previous one, kLeadSeconds ahead of the context's clock. A chunk that comes
// after its time starts late (counted: late), frames the server no longer held are counted
// (skipped). Browsers start sound only after a user gesture: switching it on is that gesture.
// window.studio.listen holds what the browser test reads: counts, and the first kTapSeconds
// received (tap) with the frame number they start at.

/// How far ahead of the context's clock chunks are scheduled, s: a few polls' worth.
export const kLeadSeconds = 0.3;
/// Poll interval, ms.
const kPollMs = 100;
/// Seconds of the received sound kept in studio.listen.tap.
const kTapSeconds = 4;

export function listenSwitch({ studio, token }) {
  const box = document.getElementById('listen'), note = document.getElementById('listen-note');
  const s = (studio.listen = { state: 'off', received: 0, chunks: 0, late: 0, skipped: 0, next: null,
                               sampleRate: 0, contextRate: 0, channels: 0, tap: null, tapFirst: null, peak: 0, clock: 0 });
  let ctx = null, playAt = 0, running = false;

  /// Keeps the first kTapSeconds of channel 0 (and 1) for the test.
  function keep(first, data, C, frames) {
    if (!s.tap) (s.tap = [...Array(C)].map(() => [])), (s.tapFirst = first);
    const room = Math.max(0, Math.floor(kTapSeconds * s.sampleRate) - s.tap[0].length);
    for (let c = 0; c < C; ++c)
      for (let i = 0; i < Math.min(frames, room); ++i) s.tap[c].push(data[i * C + c]);
  }

  /// Schedules `frames` interleaved frames right after the previous chunk.
  function play(data, C, frames) {
    const buffer = ctx.createBuffer(C, frames, s.sampleRate);
    for (let c = 0; c < C; ++c) {
      const ch = buffer.getChannelData(c);
      for (let i = 0; i < frames; ++i) ch[i] = data[i * C + c];
    }
    const node = ctx.createBufferSource();
    node.buffer = buffer;
    node.connect(ctx.destination);
    if (playAt < ctx.currentTime) (s.late += s.chunks > 0 ? 1 : 0), (playAt = ctx.currentTime + kLeadSeconds);
    node.start(playAt);
    playAt += frames / s.sampleRate;
  }

  async function fetchChunk() {
    const r = await fetch(s.next === null ? '/api/audio' : `/api/audio?from=${s.next}`, { headers: { 'X-Dpc-Token': token } });
    if (r.status === 409) return { refused: await r.text() };
    if (!r.ok) throw new Error(`/api/audio: HTTP ${r.status}`);
    const data = new Float32Array(await r.arrayBuffer());
    return { data, first: Number(r.headers.get('X-Dpc-First')), skipped: Number(r.headers.get('X-Dpc-Skipped')),
             C: Number(r.headers.get('X-Dpc-Channels')), rate: Number(r.headers.get('X-Dpc-Sample-Rate')) };
  }

  async function poll() {
    const c = await fetchChunk();
    if (c.refused) return stop(c.refused.trim());
    if (!ctx) return;  // switched off meanwhile
    s.sampleRate = c.rate;
    s.channels = c.C;
    s.state = ctx.state;
    s.contextRate = ctx.sampleRate;
    s.clock = ctx.currentTime;
    s.skipped += c.skipped;
    const frames = c.data.length / c.C;
    s.next = c.first + frames;
    if (!frames) return;
    keep(c.first, c.data, c.C, frames);
    for (const v of c.data) s.peak = Math.max(s.peak, Math.abs(v));
    play(c.data, c.C, frames);
    s.received += frames;
    ++s.chunks;
  }

  function loop() {
    if (!running) return;
    poll().catch((e) => console.warn(String(e))).finally(() => setTimeout(loop, kPollMs));
  }
  function stop(why) {
    running = false;
    box.checked = false;
    if (ctx) ctx.close();
    ctx = null;
    s.state = 'off';
    s.next = null;
    note.textContent = why || '';
  }
  box.onchange = () => {
    if (!box.checked) return stop();
    // The live clock's sound is the audio device's: nothing to fetch.
    if (studio.state?.figures?.clock === 'live') return stop('the audio device plays this session (live clock)');
    note.textContent = '';
    // Made and resumed within the click (browsers let sound start only there), at the device's
    // own rate: buffers at the session's rate are resampled by Web Audio.
    ctx = new AudioContext();
    ctx.resume();
    running = true;
    loop();
  };
}

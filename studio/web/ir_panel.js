// The IR panel of dpc studio: the selected pair's pressure IR (GET /api/ir) as a waveform
// (each column's least and greatest sample) above its energy envelope in dB, and the IACC
// table the server computed with dpc-analyze --iacc's code (null when the IR is not binaural).

const kChannelColours = ['#5fa8ff', '#ff9f40'];
const kEnvelopeFloorDb = -80;

/// Waveform in the upper half, dB envelope (0 to kEnvelopeFloorDb) in the lower half.
export function drawIr(canvas, ir) {
  const g = canvas.getContext('2d'), w = canvas.width, h = canvas.height, left = 30;
  g.clearRect(0, 0, w, h);
  const seconds = ir.samples / ir.sampleRate || 1, half = (h - 14) / 2;
  const peak = Math.max(1e-30, ...ir.min.flat().map(Math.abs), ...ir.max.flat());
  g.fillStyle = '#889'; g.font = '10px sans-serif'; g.strokeStyle = '#445';
  for (let db = 0; db >= kEnvelopeFloorDb; db -= 20) {
    const y = half + 4 + (db / kEnvelopeFloorDb) * (half - 4);
    g.beginPath(); g.moveTo(left, y); g.lineTo(w - 4, y); g.stroke();
    g.fillText(String(db), 2, y + 3);
  }
  g.fillText(`${seconds.toFixed(2)} s`, w - 40, h - 2);
  g.fillText(`frame ${ir.frame}, ${ir.channels} channel(s), peak ${peak.toExponential(2)}`, 2, 10);
  ir.min.forEach((lo, c) => {
    g.strokeStyle = kChannelColours[c];
    g.globalAlpha = 0.7;
    const x = (k) => left + (k / lo.length) * (w - left - 4), y = (v) => half / 2 - (v / peak) * (half / 2 - 2);
    g.beginPath();
    lo.forEach((v, k) => { g.moveTo(x(k), y(ir.max[c][k])); g.lineTo(x(k), y(v) + 0.5); });
    g.stroke();
    const env = ir.envelopeDb[c], ex = (k) => left + (k / env.length) * (w - left - 4);
    const ey = (db) => half + 4 + (Math.max(db, kEnvelopeFloorDb) / kEnvelopeFloorDb) * (half - 4);
    g.beginPath();
    env.forEach((db, k) => (k ? g.lineTo(ex(k), ey(db ?? kEnvelopeFloorDb)) : g.moveTo(ex(k), ey(db ?? kEnvelopeFloorDb))));
    g.stroke();
    g.globalAlpha = 1;
  });
}

/// The IACC table: early, late and whole windows per band and broadband; or why there is none.
export function fillIacc(table, ir, centres) {
  if (!ir.iacc) {
    table.innerHTML = `<tr><td class="note">IACC needs a binaural IR (dpc-demo --output binaural); ` +
                      `this one has ${ir.channels} channel(s)</td></tr>`;
    return;
  }
  const fmt = (v) => (v === null ? '–' : v.toFixed(2));
  const cells = (key) => ir.iacc.bands.map((b) => `<td>${fmt(b[key])}</td>`).join('') +
                         `<td>${fmt(ir.iacc.broadband[key])}</td>`;
  table.innerHTML =
    `<tr><th>IACC</th>${centres.map((c) => `<th>${c >= 1000 ? c / 1000 + 'k' : c}</th>`).join('')}<th>broad</th></tr>` +
    `<tr><th>early</th>${cells('early')}</tr><tr><th>late</th>${cells('late')}</tr>` +
    `<tr><th>whole</th>${cells('all')}</tr>`;
}

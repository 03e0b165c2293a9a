// The side panels of dpc studio: per-band decay curves with T30/EDT/C80/D50, the status
// figures, the materials' colours.
import { roomParameters } from './decay.js';

const kBandColours = ['#8c564b', '#e377c2', '#d62728', '#ff7f0e', '#bcbd22', '#2ca02c', '#17becf', '#1f77b4'];
const kFloorDb = -60;

/// Parameters of every band of a /api/response document.
export function analyse(response) {
  return response.bands.map((e) => roomParameters(e, response.binSeconds, response.onsetSeconds ?? null));
}

/// The decay panel's title: whether the response was traced this session or is the bake's at
/// the listener (a static source played from --bake is not traced).
export function decayTitle(response) {
  const origin = response.origin === 'bake' ? 'from the bake at the listener' : 'traced';
  return `decay curves (Schroeder), selected pair: ${origin}`;
}

const fmt = (v, digits) => (Number.isFinite(v) ? v.toFixed(digits) : '–');

/// Draws the bands' Schroeder curves (dB against seconds from each band's onset).
export function drawDecay(canvas, params, binSeconds, centres) {
  const g = canvas.getContext('2d'), w = canvas.width, h = canvas.height;
  g.clearRect(0, 0, w, h);
  const longest = Math.max(...params.map((p) => p.curveDb.length)) * binSeconds || 1;
  const x = (t) => 30 + (t / longest) * (w - 40), y = (db) => 10 + (db / kFloorDb) * (h - 30);
  g.strokeStyle = '#445'; g.fillStyle = '#889'; g.font = '10px sans-serif';
  for (let db = 0; db >= kFloorDb; db -= 10) {
    g.beginPath(); g.moveTo(30, y(db)); g.lineTo(w - 10, y(db)); g.stroke();
    g.fillText(String(db), 2, y(db) + 3);
  }
  g.fillText(`${longest.toFixed(2)} s`, w - 40, h - 4);
  params.forEach((p, b) => {
    g.strokeStyle = kBandColours[b]; g.beginPath();
    p.curveDb.forEach((db, k) => {
      const px = x(k * binSeconds), py = y(Math.max(db, kFloorDb));
      k ? g.lineTo(px, py) : g.moveTo(px, py);
    });
    g.stroke();
    g.fillStyle = kBandColours[b];
    g.fillText(`${centres[b] >= 1000 ? centres[b] / 1000 + 'k' : centres[b]}`, 40 + b * 40, h - 4);
  });
}

/// The parameters table: one column per band.
export function fillParams(table, params, centres) {
  const row = (name, f) => `<tr><th>${name}</th>${params.map((p) => `<td>${f(p)}</td>`).join('')}</tr>`;
  table.innerHTML =
    `<tr><th>Hz</th>${centres.map((c) => `<th>${c}</th>`).join('')}</tr>` +
    row('T30 s', (p) => fmt(p.t30, 2)) + row('EDT s', (p) => fmt(p.edt, 2)) +
    row('C80 dB', (p) => fmt(p.c80, 1)) + row('D50', (p) => fmt(p.d50, 2));
}

/// The live status line's figures (null: not known on this clock).
export function statusText(state) {
  const f = state.figures, n = (v, d) => (v === null ? '–' : v.toFixed(d));
  const direct = state.direct.visible
    ? `direct ${state.direct.distance.toFixed(2)} m, ${(state.direct.delaySeconds * 1e3).toFixed(1)} ms`
    : 'direct sound occluded';
  return [
    `clock ${f.clock}  frame ${state.frame}  t ${state.sceneSeconds.toFixed(1)} s`,
    `frame ${n(f.frameMs, 1)} ms  rays ${f.raysPerFrame}/${f.raysPerFrameScene}  ${n(f.raysPerSecond / 1e3, 0)}k rays/s`,
    `cache ${f.cacheEntries} entries ${n(f.cacheMb, 1)}/${n(f.cacheBudgetMb, 0)} MB`,
    `IR age ${n(f.irAgeMs, 1)} ms  latency ${n(f.latencyMedianMs, 1)}/${n(f.latencyP95Ms, 1)} ms`,
    `load ${n(f.loadPercent, 1)} %  xruns ${f.xruns === null ? '–' : f.xruns}`,
    `${direct}  exact paths ${state.paths.length}`,
  ].join('\n');
}

/// A distinct colour per material index (golden-angle hues).
export function materialColour(index) {
  return `hsl(${(index * 137.5) % 360}, 45%, 55%)`;
}

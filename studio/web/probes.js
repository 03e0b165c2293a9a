// dpc studio's bake view (docs/studio.md "In the page"): the probes of the bake dpc-demo plays
// from (GET /api/bake), one small sphere each in one InstancedMesh, coloured by a parameter
// map on matplotlib's viridis (perceptually uniform, readable in grey); the side panel picks
// the parameter, band and source and shows the legend; the mouse over a probe shows its index,
// value and 95 % half-width. window.studio.probes holds what was drawn, for the browser test.
import * as THREE from 'three';

/// matplotlib 3.6's viridis at 17 evenly spaced stops (sRGB, 0..1), linear between them.
export const kViridis = [
  [0.267004, 0.004874, 0.329415], [0.282327, 0.094955, 0.417331], [0.278826, 0.175490, 0.483397],
  [0.258965, 0.251537, 0.524736], [0.229739, 0.322361, 0.545706], [0.199430, 0.387607, 0.554642],
  [0.172719, 0.448791, 0.557885], [0.149039, 0.508051, 0.557250], [0.127568, 0.566949, 0.550556],
  [0.120638, 0.625828, 0.533488], [0.157851, 0.683765, 0.501686], [0.246070, 0.738910, 0.452024],
  [0.369214, 0.788888, 0.382914], [0.515992, 0.831158, 0.294279], [0.678489, 0.863742, 0.189503],
  [0.845561, 0.887322, 0.099702], [0.993248, 0.906157, 0.143936]];
/// A probe the bake has not stored (its rows are zeros), and a stored one whose value the
/// response cannot give (null: e.g. T30 of a decay recorded too short).
const kNotDone = [0.5, 0.5, 0.5], kNoValue = [0.2, 0.2, 0.2];
const kUnits = { T20: 's', T30: 's', EDT: 's', C50: 'dB', C80: 'dB', D50: 'ratio', G: 'dB', STI: 'ratio' };

/// viridis at t in [0, 1] (clamped), sRGB; its ends exactly the table's.
export function viridis(t) {
  const last = kViridis.length - 1, x = Math.min(Math.max(t, 0), 1) * last, i = Math.floor(x);
  if (i >= last) return [...kViridis[last]];
  const f = x - i;
  return kViridis[i].map((a, k) => a + f * (kViridis[i + 1][k] - a));
}

/// A sphere radius for the probes: 15 % of the smallest distance between a few probes and all
/// others (the grid's spacing), within 3-30 cm.
function probeRadius(xyz) {
  const n = xyz.length / 3, samples = Math.min(n, 64);
  let best = Infinity;
  for (let s = 0; s < samples; ++s) {
    const a = Math.floor((s * n) / samples);
    for (let b = 0; b < n; ++b)
      if (b !== a) best = Math.min(best, Math.hypot(xyz[3 * a] - xyz[3 * b], xyz[3 * a + 1] - xyz[3 * b + 1],
                                                    xyz[3 * a + 2] - xyz[3 * b + 2]));
  }
  return Number.isFinite(best) && best > 0 ? Math.min(Math.max(0.15 * best, 0.03), 0.3) : 0.1;
}

/// One InstancedMesh of unlit spheres at the probes (unlit: the drawn colour is the map's).
/// Drawn after the translucent walls (which write no depth), so no wall tints them.
function buildMesh(scene3, bake) {
  const n = bake.done.length, r = probeRadius(bake.probes), m = new THREE.Matrix4();
  const material = new THREE.MeshBasicMaterial({ transparent: true, opacity: 1 });
  const mesh = new THREE.InstancedMesh(new THREE.SphereGeometry(r, 12, 8), material, n);
  mesh.renderOrder = 1;
  for (let p = 0; p < n; ++p)
    mesh.setMatrixAt(p, m.makeTranslation(bake.probes[3 * p], bake.probes[3 * p + 1], bake.probes[3 * p + 2]));
  mesh.instanceMatrix.needsUpdate = true;
  mesh.computeBoundingSphere();
  mesh.name = 'probes';
  scene3.add(mesh);
  return mesh;
}

/// One map: each probe's value and half-width for parameter k, band row, source s.
export function mapOf(bake, k, row, s) {
  const S = bake.sources, R = bake.bands.length, K = bake.parameters.length, values = [], ci95 = [];
  for (let p = 0; p < bake.done.length; ++p) {
    const i = ((p * S + s) * R + row) * K + k;
    values.push(bake.values[i]), ci95.push(bake.ci95[i]);
  }
  return { values, ci95 };
}

/// Colours the instances by `values` on viridis from their least to their greatest (the done
/// probes with a value); returns that range (null, null when no probe has one).
function colourMesh(mesh, done, values) {
  let min = Infinity, max = -Infinity;
  values.forEach((v, p) => done[p] && v !== null && ((min = Math.min(min, v)), (max = Math.max(max, v))));
  const c = new THREE.Color();
  values.forEach((v, p) => {
    const rgb = !done[p] ? kNotDone : v === null ? kNoValue : viridis(max > min ? (v - min) / (max - min) : 0.5);
    mesh.setColorAt(p, c.setRGB(rgb[0], rgb[1], rgb[2], THREE.SRGBColorSpace));
  });
  mesh.instanceColor.needsUpdate = true;
  return min <= max ? { min, max } : { min: null, max: null };
}

/// The drawn instance colours, back in sRGB (three.js keeps them linear).
function drawnColours(mesh) {
  const c = new THREE.Color(), out = [];
  for (let p = 0; p < mesh.count; ++p) {
    const rgb = {};
    mesh.getColorAt(p, c).getRGB(rgb, THREE.SRGBColorSpace);
    out.push([rgb.r, rgb.g, rgb.b]);
  }
  return out;
}

/// The drawn spheres' centres, [[x, y, z], ...] (m, float32 as drawn).
function centres(mesh) {
  const m = new THREE.Matrix4(), v = new THREE.Vector3(), out = [];
  for (let p = 0; p < mesh.count; ++p) mesh.getMatrixAt(p, m), out.push(v.setFromMatrixPosition(m).toArray());
  return out;
}

const fmt = (v) => (v === null ? '–' : Math.abs(v) >= 100 ? v.toFixed(1) : v.toPrecision(3));

/// The legend: the scale, its least and greatest value and the unit.
function drawLegend(canvas, text, what, range, unit) {
  const g = canvas.getContext('2d'), w = canvas.width, h = canvas.height;
  for (let x = 0; x < w; ++x) {
    const [r, gr, b] = viridis(x / (w - 1));
    g.fillStyle = `rgb(${255 * r}, ${255 * gr}, ${255 * b})`;
    g.fillRect(x, 0, 1, h);
  }
  text.textContent = range.min === null ? `${what}: no probe has a value`
    : `${what}: ${fmt(range.min)} … ${fmt(range.max)} ${unit}  (grey: not baked; dark: no value)`;
}

/// Fills the panel's selects: parameters (C80 first shown), bands (1 kHz), sources by name.
function fillSelects(ui, bake, sourceNames) {
  bake.parameters.forEach((name, k) => ui.param.add(new Option(name, k, false, name === 'C80')));
  bake.bands.forEach((b, row) => ui.band.add(new Option(b === 'broadband' ? b : `${b} Hz`, row, false, b === 1000)));
  for (let s = 0; s < bake.sources; ++s) ui.source.add(new Option(sourceNames[s] ?? `source ${s}`, s));
}

/// The probe under the mouse (the nearest hit instance) as a tooltip beside it.
function hover(ev, ui, mesh, view, ray) {
  const hit = ray(ev).intersectObject(mesh)[0], probes = view.studio.probes;
  probes.hovered = hit ? hit.instanceId : null;
  if (!hit) return void (ui.tip.hidden = true);
  const p = hit.instanceId, v = probes.values[p];
  const name = probes.parameter === 'STI' ? 'STI' : `${probes.parameter} ${probes.band === 'broadband' ? 'broadband' : probes.band + ' Hz'}`;
  ui.tip.textContent = !view.bake.done[p] ? `probe ${p}: not baked`
    : `probe ${p}: ${name} ${fmt(v)}${v === null ? '' : ` ± ${fmt(probes.ci95[p])} ${probes.unit}`}`;
  const r = view.element.getBoundingClientRect();
  ui.tip.style.left = `${ev.clientX - r.left + 12}px`;
  ui.tip.style.top = `${ev.clientY - r.top + 12}px`;
  ui.tip.hidden = false;
}

/// Draws the selected map and records it in studio.probes.
function redraw(ui, mesh, view) {
  const { bake, studio } = view, k = Number(ui.param.value), sti = bake.parameters[k] === 'STI';
  ui.tip.hidden = true;  // it named the previous map's value
  // STI has the broadband row only; the band chosen before comes back with another parameter.
  if (sti && !ui.band.disabled) (ui.keptBand = ui.band.value), (ui.band.value = String(bake.bands.length - 1));
  if (!sti && ui.band.disabled) ui.band.value = ui.keptBand;
  ui.band.disabled = sti;
  const row = Number(ui.band.value), s = Number(ui.source.value), { values, ci95 } = mapOf(bake, k, row, s);
  const range = colourMesh(mesh, bake.done, values), parameter = bake.parameters[k], unit = kUnits[parameter] ?? '';
  const band = bake.bands[row] === 'broadband' ? 'broadband' : `${bake.bands[row]} Hz`;
  drawLegend(ui.legend, ui.legendText, `${parameter}, ${band}, ${ui.source.selectedOptions[0].text}`, range, unit);
  studio.probes = { count: mesh.count, colours: drawnColours(mesh), values, ci95, parameter, band: bake.bands[row],
                    source: s, unit, ...range, hovered: null };
}

/// Asks for the bake's maps and draws them. `view`: {scene3, element (the view's box), ray (a
/// pointer event -> THREE.Raycaster), studio (window.studio), sourceNames}.
export async function showProbes(api, view) {
  const bake = await api('/api/bake'), $ = (id) => document.getElementById(id);
  const ui = { param: $('probe-param'), band: $('probe-band'), source: $('probe-source'),
               legend: $('probe-legend'), legendText: $('probe-legend-text'), tip: $('probe-tip') };
  view.bake = bake;
  $('bake-file').textContent = bake.file;
  fillSelects(ui, bake, view.sourceNames);
  const mesh = buildMesh(view.scene3, bake);
  for (const el of [ui.param, ui.band, ui.source]) el.onchange = () => redraw(ui, mesh, view);
  redraw(ui, mesh, view);
  $('bake').hidden = false;
  view.studio.probeCentres = () => centres(mesh);
  view.element.addEventListener('pointermove', (ev) => hover(ev, ui, mesh, view, view.ray));
  view.element.addEventListener('pointerleave', () => (ui.tip.hidden = true));
}

// dpc studio's heat map: each surface coloured by the energy that reaches the selected pair's
// listener from it last (GET /api/state's `surfaces`: the DPC's window average per triangle,
// 1/m^2 relative to the source's power), per square metre of surface, on viridis over the
// kHeatRangeDb below the densest triangle. Triangles without energy take the ramp's bottom.
// window.studio.heat holds what was drawn, for the browser test.
import { materialColour } from './panels.js';
import { viridis } from './probes.js';

/// dB below the densest surface that the ramp spans.
export const kHeatRangeDb = 30;

/// Area (m^2) of each triangle of a mesh ({vertices, triangles} flat arrays).
export function triangleAreas(m) {
  const out = [], v = (i) => [m.vertices[3 * i], m.vertices[3 * i + 1], m.vertices[3 * i + 2]];
  for (let t = 0; t < m.triangles.length / 3; ++t) {
    const [a, b, c] = [0, 1, 2].map((k) => v(m.triangles[3 * t + k]));
    const u = [0, 1, 2].map((k) => b[k] - a[k]), w = [0, 1, 2].map((k) => c[k] - a[k]);
    out.push(0.5 * Math.hypot(u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]));
  }
  return out;
}

/// Ramp position (0..1) per triangle: 10 log10 of its energy per m^2 re the densest, over
/// kHeatRangeDb, clamped; 0 without energy.
export function heatPositions(surfaces, areas) {
  const density = new Array(areas.length).fill(0);
  surfaces.triangles.forEach((t, i) => { if (t < areas.length && areas[t] > 0) density[t] = surfaces.energy[i] / areas[t]; });
  const top = Math.max(0, ...density);
  return density.map((d) => (d > 0 && top > 0 ? Math.max(0, 1 + (10 * Math.log10(d / top)) / kHeatRangeDb) : 0));
}

/// Sets a meshGeometry's colours (three corners per triangle) from ramp positions, or back to
/// the materials' colours when `positions` is null.
export function paintTriangles(geo, materialIndex, positions, colourOf) {
  const col = geo.attributes.color;
  for (let t = 0; t < col.count / 3; ++t) {
    const rgb = positions ? viridis(positions[t]) : colourOf(materialIndex[t]);
    for (let k = 0; k < 3; ++k) col.setXYZ(3 * t + k, rgb[0], rgb[1], rgb[2]);
  }
  col.needsUpdate = true;
}

/// The heat map's switch and legend: paints the scene's mesh and objects each new frame while on.
export function heatMap({ sc, mesh, objectGroups, studio, THREE }) {
  const box = document.getElementById('heat'), meshes = [mesh, ...objectGroups.map((g) => g.children[0])];
  const parts = [sc, ...sc.objects], areas = parts.map(triangleAreas);
  const colourOf = (i) => new THREE.Color().setStyle(materialColour(i)).toArray();
  let frame = null;
  return (st) => {
    if (!box.checked) {
      if (frame !== null) meshes.forEach((m, p) => paintTriangles(m.geometry, parts[p].materialIndex, null, colourOf));
      frame = null;
      studio.heat = null;
      return;
    }
    if (st.frame === frame) return;
    frame = st.frame;
    const all = heatPositions(st.surfaces, areas.flat());
    let first = 0;
    meshes.forEach((m, p) => {
      paintTriangles(m.geometry, parts[p].materialIndex, all.slice(first, first + areas[p].length), colourOf);
      first += areas[p].length;
    });
    studio.heat = { frame, positions: all, colours: meshColours(mesh.geometry) };
  };
}

/// The drawn colour of each triangle of a meshGeometry (its first corner's), [r, g, b] in 0..1.
function meshColours(geo) {
  const col = geo.attributes.color, out = [];
  for (let t = 0; t < col.count / 3; ++t) out.push([col.getX(3 * t), col.getY(3 * t), col.getZ(3 * t)]);
  return out;
}

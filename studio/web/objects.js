// dpc studio's moving things: the scene's rigid objects (their own meshes, placed each frame
// by the pose the engine traced) and the sources' directivity balloons (the first-order
// pattern of scene/directivity.h about the forward axis, turned by the engine's rotation).
import * as THREE from 'three';
import { materialColour } from './panels.js';

/// The directivity band drawn: 1 kHz (index as dpc::Bands).
export const kLobeBand = 4;
/// Length of a balloon on its axis, m.
export const kLobeMetres = 0.6;

/// A triangle mesh ({vertices, triangles, materialIndex}, flat arrays) as a geometry with a
/// colour per material, each triangle's corners their own vertices.
export function meshGeometry(m) {
  const pos = [], col = [], c = new THREE.Color();
  for (let t = 0; t < m.triangles.length / 3; ++t) {
    c.setStyle(materialColour(m.materialIndex[t]));
    for (let k = 0; k < 3; ++k) {
      const v = m.triangles[3 * t + k];
      pos.push(m.vertices[3 * v], m.vertices[3 * v + 1], m.vertices[3 * v + 2]);
      col.push(c.r, c.g, c.b);
    }
  }
  const geo = new THREE.BufferGeometry();
  geo.setAttribute('position', new THREE.Float32BufferAttribute(pos, 3));
  geo.setAttribute('color', new THREE.Float32BufferAttribute(col, 3));
  geo.computeVertexNormals();
  return geo;
}

/// One group per scene object, its mesh in local coordinates (placed by placeObjects).
export function buildObjects(scene3, objects) {
  return objects.map((o) => {
    const g = new THREE.Group();
    g.add(new THREE.Mesh(meshGeometry(o), new THREE.MeshLambertMaterial(
      { vertexColors: true, side: THREE.DoubleSide, transparent: true, opacity: 0.8 })));
    g.name = o.name;
    scene3.add(g);
    return g;
  });
}

/// Each object where the frame's world put it: world = R(rotation) * local + position.
export function placeObjects(groups, state) {
  groups.forEach((g, i) => {
    const p = state.objects[i];
    g.position.set(...p.position);
    g.quaternion.set(...p.rotation);  // [x, y, z, w], as three.js
  });
}

/// The balloon of a first-order pattern a: radius |(1 - a) + a cos(theta)| * kLobeMetres at
/// the angle theta from +x (the pressure pattern, whose square is the energy gain), with an
/// arrow along +x for the forward axis. Null for omni (a = 0).
export function lobe(a) {
  if (!(a > 0)) return null;
  const points = [];
  for (let k = 0; k <= 48; ++k) {
    const th = (k / 48) * Math.PI, r = Math.abs(1 - a + a * Math.cos(th)) * kLobeMetres;
    points.push(new THREE.Vector2(r * Math.sin(th), r * Math.cos(th)));
  }
  const geo = new THREE.LatheGeometry(points, 32);
  geo.rotateZ(-Math.PI / 2);  // the lathe's axis +y onto +x, the source's forward
  const g = new THREE.Group();
  g.add(new THREE.Mesh(geo, new THREE.MeshLambertMaterial(
    { color: 0xff8080, transparent: true, opacity: 0.35, depthWrite: false, side: THREE.DoubleSide })));
  g.add(new THREE.ArrowHelper(new THREE.Vector3(1, 0, 0), new THREE.Vector3(), kLobeMetres * 1.3, 0xff4040));
  g.name = 'directivity';
  return g;
}

/// World positions of a group's first mesh's vertices (for the browser test).
export function worldVertices(group) {
  group.updateMatrixWorld(true);
  const mesh = group.children[0], a = mesh.geometry.attributes.position, out = [];
  for (let i = 0; i < a.count; ++i) out.push(new THREE.Vector3().fromBufferAttribute(a, i).applyMatrix4(mesh.matrixWorld).toArray());
  return out;
}

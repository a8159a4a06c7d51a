// The shapes both 3D views draw (the milling machine's in view3d.js, the lathe's in view3d_lathe.js):
// colours, materials, lines, cylinders, extruded bodies, rings and circles, in MCS mm.
import * as THREE from './vendor/three-0.187.0/build/three.module.js';

export { THREE };

export const COLOR = {
  block: 0x8fa3b8, hole: 0x2b3640, spigot: 0x6f8aa6, pocket: 0x2b3640, boss: 0x6f8aa6, prism: 0x8fa3b8,
  sphere: 0x9db0c4, ring: 0xc9a227, tool_probe: 0x7a5fa8, probe: 0xf39200, shank: 0x9aa3ab,
  move: 0x35506b, probing: 0xd32f2f, contact: 0xd32f2f, touch: 0x2e7d32, measured: 0x0057b8,
  table: 0xd7dde3, grid: 0xb5bec7, refused: 0xff00c8, chuck: 0x5d6a77, groove: 0xc9a227, axis: 0x1d2731,
};

export function webglAvailable() {
  try {
    const c = document.createElement('canvas');
    return !!(c.getContext('webgl2') || c.getContext('webgl'));
  } catch (e) {
    return false;
  }
}

export const v3 = (p) => new THREE.Vector3(p[0], p[1], p[2]);

export function lineMaterial(color, dashed) {
  return dashed ? new THREE.LineDashedMaterial({ color, dashSize: 4, gapSize: 3 })
    : new THREE.LineBasicMaterial({ color });
}

export function polyline(points, color, { dashed = false, closed = false } = {}) {
  const geometry = new THREE.BufferGeometry().setFromPoints(points);
  const line = closed ? new THREE.LineLoop(geometry, lineMaterial(color, dashed))
    : new THREE.Line(geometry, lineMaterial(color, dashed));
  if (dashed) line.computeLineDistances();
  return line;
}

export function solidMaterial(color, opacity = 1) {
  return new THREE.MeshStandardMaterial({
    color, roughness: 0.7, metalness: 0.1, transparent: opacity < 1, opacity,
    depthWrite: opacity >= 1, side: THREE.DoubleSide,
  });
}

// a cylinder whose top face centre is `top`, standing along -axis for `height`
export function cylinder(top, axis, radius, height, material, open = false) {
  const geometry = new THREE.CylinderGeometry(radius, radius, height, 48, 1, open);
  const mesh = new THREE.Mesh(geometry, material);
  const a = v3(axis).normalize();
  mesh.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), a);
  mesh.position.copy(v3(top).addScaledVector(a, -height / 2));
  return mesh;
}

// a closed body from a top and a bottom ring of vertices (block corners, prism polygon)
export function extruded(top, bottom, material) {
  const n = top.length;
  const verts = [...top, ...bottom].map(v3);
  const axis = new THREE.Vector3().subVectors(verts[0], verts[n]).normalize();
  const u = new THREE.Vector3().subVectors(verts[1], verts[0]).normalize();
  const w = new THREE.Vector3().crossVectors(axis, u);
  const flat = top.map((p) => new THREE.Vector2(v3(p).dot(u), v3(p).dot(w)));
  const caps = THREE.ShapeUtils.triangulateShape(flat, []);
  const index = [];
  caps.forEach(([a, b, c]) => { index.push(a, b, c, n + c, n + b, n + a); });
  for (let i = 0; i < n; i += 1) {
    const j = (i + 1) % n;
    index.push(i, n + i, n + j, i, n + j, j);
  }
  const geometry = new THREE.BufferGeometry().setFromPoints(verts);
  geometry.setIndex(index);
  geometry.computeVertexNormals();
  const group = new THREE.Group();
  group.add(new THREE.Mesh(geometry, material));
  const edges = [];
  for (let i = 0; i < n; i += 1) {
    const j = (i + 1) % n;
    edges.push(verts[i], verts[j], verts[n + i], verts[n + j], verts[i], verts[n + i]);
  }
  group.add(new THREE.LineSegments(new THREE.BufferGeometry().setFromPoints(edges),
    new THREE.LineBasicMaterial({ color: 0x33475b })));
  return group;
}

export function circlePoints(centre, normal, radius, segments = 64) {
  const n = v3(normal).normalize();
  const u = new THREE.Vector3(1, 0, 0);
  if (Math.abs(n.dot(u)) > 0.9) u.set(0, 1, 0);
  u.addScaledVector(n, -u.dot(n)).normalize();
  const w = new THREE.Vector3().crossVectors(n, u);
  const c = v3(centre);
  const out = [];
  for (let i = 0; i < segments; i += 1) {
    const t = (2 * Math.PI * i) / segments;
    out.push(c.clone().addScaledVector(u, radius * Math.cos(t)).addScaledVector(w, radius * Math.sin(t)));
  }
  return out;
}

export function dispose(group) {
  group.traverse((o) => {
    if (o.geometry) o.geometry.dispose();
    if (o.material) o.material.dispose();
  });
  group.clear();
}

// a ring (a tube: outer and inner wall, both end faces) whose top face centre is `top`, along -axis
export function ringBody(top, axis, inner, outer, height, material) {
  const group = new THREE.Group();
  group.add(cylinder(top, axis, outer, height, material, true));
  if (inner > 0) group.add(cylinder(top, axis, inner, height, material, true));
  const a = v3(axis).normalize();
  [0, height].forEach((depth) => {
    const face = new THREE.Mesh(new THREE.RingGeometry(inner, outer, 48), material);
    face.quaternion.setFromUnitVectors(new THREE.Vector3(0, 0, 1), a);
    face.position.copy(v3(top).addScaledVector(a, -depth));
    group.add(face);
  });
  return group;
}


// The lathe in the 3D machine view (view3d.js draws it; data from app/web/scene3d.py build_lathe):
// MCS, mm, X a radius and up, Z along the spindle (right), Y towards the operator. The turned part is
// a body of revolution about the spindle axis (its cylinders, its bores cut open), the chuck behind
// the chuck face, the reference grooves' rings, the tool probe's cube, the X/Z axes and the spindle
// axis; the probe (or the turning tool) sits on the turret: the ball or the nose at the tip, the
// holder to F, the turret reference.
import {
  THREE, COLOR, polyline, solidMaterial, cylinder, ringBody,
} from './view3d_parts.js';

const Z_AXIS = [0, 0, 1];
const AXIS_LENGTH = 60;           // mm, the X and Z arrows at machine zero

function box(x0, x1, y0, y1, z0, z1, material) {
  const mesh = new THREE.Mesh(new THREE.BoxGeometry(Math.abs(x1 - x0), Math.abs(y1 - y0), Math.abs(z1 - z0)), material);
  mesh.position.set((x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2);
  return mesh;
}

export const LATHE = {
  up: [1, 0, 0],
  view: [0.35, 0.9, 0.3],             // from the operator's side (+Y), a little above: the chuck left, Z right
  distance: 1.8,                      // × the milling view's: the grooves and the turret around the part
  corners: (lim) => [[lim.X[0], -50, lim.Z[0]], [lim.X[1], 50, lim.Z[1]]],
  // the NC's tool reference: F − (L1, 0, L2)
  ncTip(status) {
    const lengths = status.tool_lengths || {};
    return [Number(status.mcs.X) - Number(lengths.L1 || 0), 0, Number(status.mcs.Z) - Number(lengths.L2 || 0)];
  },
  sceneStatus: (p) => ({ mcs: { X: p.f[0], Y: 0, Z: p.f[2] }, tool_lengths: { L1: p.lengths[0], L2: p.lengths[1] } }),
  probeText: (nc) => `X ${nc[0].toFixed(3)} (Ø ${(2 * nc[0]).toFixed(3)}) · Z ${nc[2].toFixed(3)}`,
  probeShape: (p) => [p.diameter, p.is_probe, p.sl, p.lengths, p.offset],
  orient() {},                      // the turret does not swivel
  // what the screen's tests and the service engineer read off the figure
  summary: (data) => ({
    chuck: data.solids.chuck ? '1' : '0',
    grooves: String((data.solids.grooves || []).length),
    toolProbe: data.solids.tool_probe ? '1' : '0',
  }),

  // at the true tip (the group's origin): the ball or the nose, the holder to F, F
  buildProbe(p) {
    const group = new THREE.Group();
    const r = Math.max(p.diameter / 2, 0.5);
    const f = new THREE.Vector3(p.lengths[0] - p.offset[0], 0, p.lengths[1] - p.offset[2]);   // F − tip
    const tip = new THREE.Mesh(new THREE.SphereGeometry(r, 32, 16), solidMaterial(COLOR.probe, p.is_probe ? 1 : 0.6));
    group.add(tip);
    const stem = Math.max(r * 0.35, 0.6);
    // the holder: from the tip up in X to F's height, then along Z to F (as the SL of a probe points)
    const corner = new THREE.Vector3(f.x, 0, 0);
    if (corner.length() > r) group.add(cylinder([corner.x, 0, 0], [Math.sign(corner.x) || 1, 0, 0], stem, Math.abs(corner.x) - r, solidMaterial(COLOR.shank)));
    if (Math.abs(f.z) > 1e-6) group.add(cylinder([f.x, 0, f.z], [0, 0, Math.sign(f.z)], Math.max(stem, 4), Math.abs(f.z), solidMaterial(COLOR.shank)));
    group.add(box(f.x, f.x + 40, -25, 25, f.z - 20, f.z + 20, solidMaterial(COLOR.shank, 0.5)));   // the turret
    const fPoint = new THREE.Mesh(new THREE.SphereGeometry(3, 16, 8), solidMaterial(COLOR.axis));
    fPoint.position.copy(f);
    group.add(fPoint);
    return group;
  },

  // the turned part, the chuck, the grooves, the tool probe, the axes; returns the part's count
  buildSolids(layers, data) {
    const { solids } = data;
    let part = 0;
    (solids.part || []).forEach((item) => {
      const r = item.diameter / 2;
      const top = [item.axis_x, 0, item.z[1]];
      const height = item.z[1] - item.z[0];
      if (item.type === 'bore') {
        layers.solids.add(cylinder(top, Z_AXIS, r, height, solidMaterial(COLOR.hole, 0.8), true));
        layers.solids.add(polyline(
          Array.from({ length: 64 }, (_, i) => {
            const t = (2 * Math.PI * i) / 64;
            return new THREE.Vector3(item.axis_x + r * Math.cos(t), r * Math.sin(t), item.z[1]);
          }), COLOR.hole, { closed: true }));
      } else {
        layers.solids.add(cylinder(top, Z_AXIS, r, height, solidMaterial(COLOR.spigot, 0.55)));
      }
      part += 1;
    });
    const { chuck } = solids;
    if (chuck) {
      const material = solidMaterial(COLOR.chuck);
      layers.solids.add(cylinder([0, 0, chuck.face_z], Z_AXIS, chuck.diameter / 2, chuck.length, material));
      [0, 120, 240].forEach((deg) => {          // three jaws on the face
        const a = THREE.MathUtils.degToRad(deg);
        const r0 = chuck.diameter / 4;
        const jaw = box(-6, 6, -r0 / 2, r0 / 2, chuck.face_z, chuck.face_z + 8, material);
        jaw.position.set(Math.cos(a) * chuck.diameter * 0.36, Math.sin(a) * chuck.diameter * 0.36, chuck.face_z + 4);
        jaw.rotation.z = a;
        layers.solids.add(jaw);
      });
    }
    // the door's first picture: the chuck, the part and the probe (the tool probe lies far off)
    layers.solids.userData.focus = new THREE.Box3().setFromObject(layers.solids);
    (solids.grooves || []).forEach((g) => {
      g.rings.forEach(([r0, r1, z0, z1]) => {
        layers.solids.add(ringBody([0, 0, Math.max(z0, z1)], Z_AXIS, Math.min(r0, r1), Math.max(r0, r1), Math.abs(z1 - z0),
          solidMaterial(COLOR.groove, 0.35)));
      });
    });
    const tp = solids.tool_probe;
    if (tp) {
      const size = Math.min(Math.abs(tp['X-'] - tp['X+']), Math.abs(tp['Z-'] - tp['Z+']));
      layers.solids.add(box(tp['X+'], tp['X-'], -size / 2, size / 2, tp['Z+'], tp['Z-'], solidMaterial(COLOR.tool_probe)));
    }
    this.buildAxes(layers, data);
    return part;
  },

  // machine zero's X (up) and Z (along the spindle) arrows, the spindle axis dash-dotted
  buildAxes(layers, data) {
    const origin = new THREE.Vector3(0, 0, 0);
    layers.table.add(new THREE.ArrowHelper(new THREE.Vector3(1, 0, 0), origin, AXIS_LENGTH, 0xd32f2f, 8, 4));
    layers.table.add(new THREE.ArrowHelper(new THREE.Vector3(0, 0, 1), origin, AXIS_LENGTH, 0x1565c0, 8, 4));
    const lim = data.limits;
    layers.table.add(polyline([new THREE.Vector3(0, 0, lim.Z[0]), new THREE.Vector3(0, 0, lim.Z[1])], COLOR.axis, { dashed: true }));
  },
};

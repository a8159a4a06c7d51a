// The machine view in 3D (three.js, vendored: static/VENDORED.md). An ES module: it imports only
// files under /static and takes every URL from the page (data-scene-url, data-machine-url,
// data-events-url). The scene (MCS, mm, Z up) comes from app/web/scene3d.py; the probe follows
// GET /api/machine (or the server-sent events when the page names a stream). Drawn on demand only:
// nothing is rendered while nothing changes (the panel PC's CPU is shared with the simulator).
import * as THREE from './vendor/three-0.187.0/build/three.module.js';
import { OrbitControls } from './vendor/three-0.187.0/examples/jsm/controls/OrbitControls.js';

const COLOR = {
  block: 0x8fa3b8, hole: 0x2b3640, spigot: 0x6f8aa6, pocket: 0x2b3640, boss: 0x6f8aa6, prism: 0x8fa3b8,
  sphere: 0x9db0c4, ring: 0xc9a227, tool_probe: 0x7a5fa8, probe: 0xf39200, shank: 0x9aa3ab,
  move: 0x35506b, probing: 0xd32f2f, contact: 0xd32f2f, touch: 0x2e7d32, measured: 0x0057b8,
  table: 0xd7dde3, grid: 0xb5bec7, refused: 0xff00c8,
};
const PROBE_POLL_MS = 150;        // as the position display
const SCENE_POLL_MS = 1000;
const EVENT_FRESH_MS = 600;       // events newer than this replace the probe polling

function webglAvailable() {
  try {
    const c = document.createElement('canvas');
    return !!(c.getContext('webgl2') || c.getContext('webgl'));
  } catch (e) {
    return false;
  }
}

const v3 = (p) => new THREE.Vector3(p[0], p[1], p[2]);

function lineMaterial(color, dashed) {
  return dashed ? new THREE.LineDashedMaterial({ color, dashSize: 4, gapSize: 3 })
    : new THREE.LineBasicMaterial({ color });
}

function polyline(points, color, { dashed = false, closed = false } = {}) {
  const geometry = new THREE.BufferGeometry().setFromPoints(points);
  const line = closed ? new THREE.LineLoop(geometry, lineMaterial(color, dashed))
    : new THREE.Line(geometry, lineMaterial(color, dashed));
  if (dashed) line.computeLineDistances();
  return line;
}

function solidMaterial(color, opacity = 1) {
  return new THREE.MeshStandardMaterial({
    color, roughness: 0.7, metalness: 0.1, transparent: opacity < 1, opacity,
    depthWrite: opacity >= 1, side: THREE.DoubleSide,
  });
}

// a cylinder whose top face centre is `top`, standing along -axis for `height`
function cylinder(top, axis, radius, height, material, open = false) {
  const geometry = new THREE.CylinderGeometry(radius, radius, height, 48, 1, open);
  const mesh = new THREE.Mesh(geometry, material);
  const a = v3(axis).normalize();
  mesh.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), a);
  mesh.position.copy(v3(top).addScaledVector(a, -height / 2));
  return mesh;
}

// a closed body from a top and a bottom ring of vertices (block corners, prism polygon)
function extruded(top, bottom, material) {
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

function circlePoints(centre, normal, radius, segments = 64) {
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

function dispose(group) {
  group.traverse((o) => {
    if (o.geometry) o.geometry.dispose();
    if (o.material) o.material.dispose();
  });
  group.clear();
}

class View3D {
  constructor(el) {
    this.el = el;
    this.canvas = el.querySelector('canvas');
    this.out = (name) => el.querySelector(`[data-out="${name}"]`);
    this.keys = {};
    this.timers = [];
    this.lastEvent = 0;
    if (!this.canvas || !webglAvailable()) {
      el.dataset.state = 'nogl';
      const note = this.out('nogl');
      if (note) note.hidden = false;
      return;
    }
    this.renderer = new THREE.WebGLRenderer({ canvas: this.canvas, antialias: true });
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color(0xf4f6f8);
    this.camera = new THREE.PerspectiveCamera(35, 1, 1, 50000);
    this.camera.up.set(0, 0, 1);
    this.controls = new OrbitControls(this.camera, this.canvas);
    this.controls.addEventListener('change', () => this.requestRender());
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x8090a0, 1.6));
    const sun = new THREE.DirectionalLight(0xffffff, 1.4);
    sun.position.set(-0.4, -0.8, 1.0);
    this.scene.add(sun);
    this.layers = {};
    ['table', 'solids', 'wcs', 'measured', 'touches', 'plan', 'probe'].forEach((name) => {
      this.layers[name] = new THREE.Group();
      this.scene.add(this.layers[name]);
    });
    this.probeOffset = [0, 0, 0];
    new ResizeObserver(() => this.resize()).observe(this.canvas);
    this.resize();
    this.connectEvents();
    this.tick('scene', SCENE_POLL_MS, () => this.refreshScene());
    this.tick('probe', PROBE_POLL_MS, () => this.refreshProbe());
  }

  // --- loop -------------------------------------------------------------------------------------
  alive() {
    if (this.el.isConnected) return true;
    this.timers.forEach(clearTimeout);
    if (this.events) this.events.close();
    Object.values(this.layers).forEach(dispose);
    this.controls.dispose();
    this.renderer.dispose();
    return false;
  }

  tick(name, period, work) {
    const run = async () => {
      if (!this.alive()) return;
      try {
        await work();
      } catch (e) {
        // the header's connection note tells the operator; the view keeps its last picture
      }
      this.timers.push(setTimeout(run, period));
      if (this.timers.length > 8) this.timers.splice(0, this.timers.length - 8);
    };
    run();
  }

  requestRender() {
    if (this.pending) return;
    this.pending = true;
    requestAnimationFrame(() => {
      this.pending = false;
      this.renderer.render(this.scene, this.camera);
      // for the tests and the service engineer: what the last frame drew
      let objects = 0;
      this.scene.traverse((o) => { if (o.isMesh || o.isLine) objects += 1; });
      this.el.dataset.objects = String(objects);
      this.el.dataset.drawCalls = String(this.renderer.info.render.calls);
      this.el.dataset.frames = String(this.renderer.info.render.frame);
    });
  }

  resize() {
    const w = this.canvas.clientWidth || 300;
    const h = this.canvas.clientHeight || 200;
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.requestRender();
  }

  async getJson(url) {
    const response = await fetch(url, { headers: { Accept: 'application/json' }, cache: 'no-store' });
    if (!response.ok) throw new Error(String(response.status));
    return response.json();
  }

  // --- live probe ---------------------------------------------------------------------------
  connectEvents() {
    const url = this.el.dataset.eventsUrl;
    if (!url || !window.EventSource) return;
    this.events = new EventSource(url);
    const take = (event) => {
      try {
        const data = JSON.parse(event.data);
        const status = data && data.mcs ? data : (data && data.machine);
        if (status && status.mcs) {
          this.lastEvent = Date.now();
          this.showProbe(status);
        }
      } catch (e) {
        // not a machine state: other events are for other panels
      }
    };
    this.events.addEventListener('machine', take);
    this.events.onmessage = take;
  }

  async refreshProbe() {
    if (Date.now() - this.lastEvent < EVENT_FRESH_MS) return;
    this.showProbe(await this.getJson(this.el.dataset.machineUrl));
  }

  showProbe(status) {
    const axis = status.tool_axis || [0, 0, 1];
    const length = Number(status.tool_length || 0);
    const axes = ['X', 'Y', 'Z'].map((a) => Number(status.mcs[a]));
    const nc = axes.map((v, i) => v - length * axis[i]);
    const tip = nc.map((v, i) => v + this.probeOffset[i]);
    const key = tip.map((v) => v.toFixed(3)).join(' ');
    if (key === this.keys.probePos) return;
    this.keys.probePos = key;
    this.el.dataset.probe = nc.map((v) => v.toFixed(3)).join(' ');
    const out = this.out('probe');
    if (out) out.textContent = `X ${nc[0].toFixed(3)} · Y ${nc[1].toFixed(3)} · Z ${nc[2].toFixed(3)}`;
    if (this.probe) {
      this.probe.position.copy(v3(tip));
      this.probe.quaternion.setFromUnitVectors(new THREE.Vector3(0, 0, 1), v3(axis).normalize());
      this.requestRender();
    }
  }

  buildProbe(p) {
    dispose(this.layers.probe);
    const group = new THREE.Group();
    const r = Math.max(p.diameter / 2, 0.5);
    const length = Math.max(p.tool_length, 10);
    if (p.is_probe) {
      group.add(new THREE.Mesh(new THREE.SphereGeometry(r, 32, 16), solidMaterial(COLOR.probe)));
      group.add(cylinder([0, 0, length], [0, 0, 1], Math.max(r * 0.35, 0.6), length - r, solidMaterial(COLOR.shank)));
    } else {
      group.add(cylinder([0, 0, Math.min(length, 60)], [0, 0, 1], r, Math.min(length, 60), solidMaterial(COLOR.probe)));
      group.add(cylinder([0, 0, length], [0, 0, 1], Math.max(r, 6), Math.max(length - 60, 1), solidMaterial(COLOR.shank)));
    }
    group.add(cylinder([0, 0, length + 30], [0, 0, 1], 30, 30, solidMaterial(COLOR.shank, 0.5)));   // spindle nose
    this.probe = group;
    this.layers.probe.add(group);
  }

  // --- the scene ----------------------------------------------------------------------------
  async refreshScene() {
    const data = await this.getJson(this.el.dataset.sceneUrl);
    this.probeOffset = data.probe.offset || [0, 0, 0];
    const changed = (name, value) => {
      const text = JSON.stringify(value);
      if (this.keys[name] === text) return false;
      this.keys[name] = text;
      return true;
    };
    if (changed('solids', [data.solids, data.limits])) this.buildSolids(data);
    if (changed('probeShape', [data.probe.diameter, data.probe.is_probe, data.probe.tool_length])) {
      this.buildProbe(data.probe);
      this.keys.probePos = '';
    }
    if (changed('wcs', data.wcs)) this.buildWcs(data.wcs);
    if (changed('plan', data.plan)) this.buildPlan(data.plan);
    if (changed('touches', [data.touches, data.probe.diameter])) this.buildTouches(data.touches, data.probe.diameter / 2);
    if (changed('measured', data.measured)) this.buildMeasured(data.measured);
    this.showProbe({ mcs: { X: data.probe.tip[0], Y: data.probe.tip[1], Z: data.probe.tip[2] }, tool_length: 0, tool_axis: data.probe.axis });
    if (!this.framed) this.frame(data);
    this.el.dataset.hidden = String(!!data.hidden);
    this.el.dataset.state = 'ready';
    this.requestRender();
  }

  buildSolids(data) {
    const { solids } = data;
    dispose(this.layers.solids);
    dispose(this.layers.table);
    let part = 0;
    const partMaterial = (kind) => solidMaterial(COLOR[kind] || COLOR.block, 0.55);
    if (solids.block) {
      const c = solids.block.corners;
      this.layers.solids.add(extruded(c.slice(0, 4), c.slice(4, 8), partMaterial('block')));
      part += 1;
    }
    if (solids.prism) {
      this.layers.solids.add(extruded(solids.prism.top, solids.prism.bottom, partMaterial('prism')));
      part += 1;
    }
    const rings = {};
    (solids.circles || []).forEach((c) => {
      const r = c.diameter / 2;
      if (c.kind === 'ring_bore' || c.kind === 'ring_outer') {
        rings[c.center.join(',')] = { ...(rings[c.center.join(',')] || {}), [c.kind]: c };
      } else if (c.kind === 'tool_probe') {
        this.layers.solids.add(cylinder(c.center, c.axis, r, c.height, solidMaterial(COLOR.tool_probe)));
      } else {
        this.layers.solids.add(cylinder(c.center, c.axis, r, c.height, partMaterial(c.kind), c.kind === 'hole'));
        if (c.kind === 'hole') this.layers.solids.add(polyline(circlePoints(c.center, c.axis, r), COLOR.hole, { closed: true }));
        part += 1;
      }
    });
    Object.values(rings).forEach(({ ring_bore: bore, ring_outer: outer }) => {
      const ring = outer || bore;
      const material = solidMaterial(COLOR.ring);
      this.layers.solids.add(cylinder(ring.center, ring.axis, outer.diameter / 2, ring.height, material, true));
      if (bore) {
        this.layers.solids.add(cylinder(ring.center, ring.axis, bore.diameter / 2, ring.height, material, true));
        const top = new THREE.Mesh(new THREE.RingGeometry(bore.diameter / 2, outer.diameter / 2, 48), material);
        top.quaternion.setFromUnitVectors(new THREE.Vector3(0, 0, 1), v3(ring.axis).normalize());
        top.position.copy(v3(ring.center));
        this.layers.solids.add(top);
      }
    });
    (solids.rects || []).forEach((rect) => {
      const pts = rect.corners.map(v3);
      this.layers.solids.add(polyline(pts, COLOR[rect.kind] || COLOR.block, { closed: true }));
      const geometry = new THREE.BufferGeometry().setFromPoints(pts);
      geometry.setIndex([0, 1, 2, 0, 2, 3]);
      geometry.computeVertexNormals();
      this.layers.solids.add(new THREE.Mesh(geometry, partMaterial(rect.kind)));
      part += 1;
    });
    (solids.spheres || []).forEach((s) => {
      const mesh = new THREE.Mesh(new THREE.SphereGeometry(s.diameter / 2, 32, 16), partMaterial('sphere'));
      mesh.position.copy(v3(s.center));
      this.layers.solids.add(mesh);
      part += 1;
    });
    this.el.dataset.part = String(part);
    this.buildTable(data);
  }

  buildTable(data) {
    const box = new THREE.Box3().setFromObject(this.layers.solids);
    const lim = data.limits;
    const z = box.isEmpty() ? lim.Z[0] : box.min.z - 0.5;
    const sx = lim.X[1] - lim.X[0];
    const sy = lim.Y[1] - lim.Y[0];
    const size = Math.max(sx, sy);
    const grid = new THREE.GridHelper(size, Math.round(size / 50), COLOR.grid, COLOR.grid);
    grid.rotation.x = Math.PI / 2;
    grid.position.set(lim.X[0] + size / 2, lim.Y[0] + size / 2, z);
    this.layers.table.add(grid);
    const table = new THREE.Mesh(new THREE.PlaneGeometry(sx, sy), solidMaterial(COLOR.table));
    table.position.set(lim.X[0] + sx / 2, lim.Y[0] + sy / 2, z - 0.2);
    this.layers.table.add(table);
  }

  buildWcs(wcs) {
    dispose(this.layers.wcs);
    const out = this.out('wcs');
    if (out) out.textContent = wcs ? wcs.name : '–';
    if (!wcs) return;
    const origin = v3(wcs.origin);
    [0xd32f2f, 0x2e7d32, 0x1565c0].forEach((color, i) => {
      this.layers.wcs.add(new THREE.ArrowHelper(v3(wcs.axes[i]).normalize(), origin, 40, color, 8, 4));
    });
  }

  buildPlan(plan) {
    dispose(this.layers.plan);
    const segments = plan ? plan.segments : [];
    segments.forEach((s) => {
      const probing = s.kind === 'probe';
      const refused = s.verdict === 'collision' || s.verdict === 'limit';     // the start guard's refusal
      const color = refused ? COLOR.refused : (probing ? COLOR.probing : COLOR.move);
      this.layers.plan.add(polyline([v3(s.from), v3(s.to)], color, { dashed: !probing && !refused }));
      if (probing) {
        const dot = new THREE.Mesh(new THREE.SphereGeometry(0.8, 12, 8), solidMaterial(COLOR.contact));
        dot.position.copy(v3(s.to));
        this.layers.plan.add(dot);
      }
    });
    this.el.dataset.plan = String(segments.length);
    this.el.dataset.planRefused = plan && plan.refused_step ? String(plan.refused_step) : '';
    const out = this.out('plan');
    if (out) out.textContent = plan && segments.length ? `P${plan.point}${plan.refused_step ? ' ✕ ' + plan.refused_step : ''}` : '–';
  }

  buildTouches(touches, radius) {
    dispose(this.layers.touches);
    const material = solidMaterial(COLOR.touch, 0.45);
    touches.forEach((t) => {
      const ball = new THREE.Mesh(new THREE.SphereGeometry(Math.max(radius, 0.5), 20, 12), material.clone());
      ball.position.copy(v3(t.at));
      this.layers.touches.add(ball);
    });
    material.dispose();
    this.el.dataset.touches = String(touches.length);
    const out = this.out('touches');
    if (out) out.textContent = String(touches.length);
  }

  buildMeasured(shapes) {
    dispose(this.layers.measured);
    const add = (o) => this.layers.measured.add(o);
    shapes.forEach((s) => {
      if (s.kind === 'point') {
        const dot = new THREE.Mesh(new THREE.SphereGeometry(0.7, 12, 8), solidMaterial(COLOR.measured));
        dot.position.copy(v3(s.at));
        add(dot);
      } else if (s.kind === 'corner') {
        s.dirs.forEach((d) => add(polyline([v3(s.at), v3(s.at).addScaledVector(v3(d), 60)], COLOR.measured)));
      } else if (s.kind === 'circle') {
        add(polyline(circlePoints(s.at, s.normal, s.diameter / 2), COLOR.measured, { closed: true }));
      } else if (s.kind === 'rect') {
        const c = v3(s.at);
        const [u, w] = s.dirs.map(v3);
        const [a, b] = [s.size[0] / 2, s.size[1] / 2];
        add(polyline([[a, b], [-a, b], [-a, -b], [a, -b]].map(([x, y]) => c.clone().addScaledVector(u, x).addScaledVector(w, y)),
          COLOR.measured, { closed: true }));
      } else if (s.kind === 'face') {
        const face = new THREE.Mesh(new THREE.PlaneGeometry(30, 30), solidMaterial(COLOR.measured, 0.25));
        face.quaternion.setFromUnitVectors(new THREE.Vector3(0, 0, 1), v3(s.normal).normalize());
        face.position.copy(v3(s.at));
        add(face);
      } else if (s.kind === 'line') {
        add(polyline([v3(s.from), v3(s.to)], COLOR.measured));
      }
    });
    this.el.dataset.measured = String(shapes.length);
    const out = this.out('measured');
    if (out) out.textContent = String(shapes.filter((s) => s.kind !== 'point').length);
  }

  // the door's view: from the front (−Y), above, the solids and the probe in the picture
  frame(data) {
    const box = new THREE.Box3().setFromObject(this.layers.solids);
    box.expandByPoint(v3(data.probe.tip));
    if (box.isEmpty()) box.setFromPoints([v3([data.limits.X[0], data.limits.Y[0], data.limits.Z[0]]), v3([data.limits.X[1], data.limits.Y[1], data.limits.Z[1]])]);
    const centre = box.getCenter(new THREE.Vector3());
    const radius = Math.max(box.getSize(new THREE.Vector3()).length() / 2, 50);
    const distance = radius / Math.sin(THREE.MathUtils.degToRad(this.camera.fov / 2)) * 0.9;
    this.camera.position.copy(centre).add(new THREE.Vector3(0.25, -0.85, 0.55).normalize().multiplyScalar(distance));
    this.camera.near = Math.max(distance / 200, 0.5);
    this.camera.far = distance * 20;
    this.camera.updateProjectionMatrix();
    this.controls.target.copy(centre);
    this.controls.update();
    this.framed = true;
  }
}

function mountAll() {
  document.querySelectorAll('[data-view3d]').forEach((el) => {
    if (!el.view3d) el.view3d = new View3D(el);
  });
}

mountAll();
document.addEventListener('htmx:afterSettle', mountAll);

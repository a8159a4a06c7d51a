// The machine view in 3D (three.js, vendored: static/VENDORED.md). An ES module: it imports only
// files under /static and takes every URL from the page (data-scene-url, data-machine-url,
// data-events-url, data-kind). The scene (MCS, mm; a milling machine Z up here, a lathe in view3d_lathe.js)
// comes from app/web/scene3d.py; the probe follows
// GET /api/machine (or the server-sent events when the page names a stream). Drawn on demand only:
// nothing is rendered while nothing changes (the panel PC's CPU is shared with the simulator).
import {
  THREE, COLOR, webglAvailable, v3, polyline, solidMaterial, cylinder, extruded, circlePoints, dispose, ringBody,
} from './view3d_parts.js';
import { LATHE } from './view3d_lathe.js';
import { OrbitControls } from './vendor/three-0.187.0/examples/jsm/controls/OrbitControls.js';

const PROBE_POLL_MS = 150;        // as the position display
const SCENE_POLL_MS = 1000;
const EVENT_FRESH_MS = 600;       // events newer than this replace the probe polling

// --- the milling machine (Z up, the tool along its axis) ---------------------------------------
const MILL = {
  up: [0, 0, 1],
  view: [0.25, -0.85, 0.55],          // from the front (−Y), above
  corners: (lim) => [[lim.X[0], lim.Y[0], lim.Z[0]], [lim.X[1], lim.Y[1], lim.Z[1]]],
  // the NC's tool reference: axes − L·tool axis
  ncTip(status) {
    const axis = status.tool_axis || [0, 0, 1];
    const length = Number(status.tool_length || 0);
    return ['X', 'Y', 'Z'].map((a, i) => Number(status.mcs[a]) - length * axis[i]);
  },
  sceneStatus: (p) => ({ mcs: { X: p.tip[0], Y: p.tip[1], Z: p.tip[2] }, tool_length: 0, tool_axis: p.axis }),
  probeText: (nc) => `X ${nc[0].toFixed(3)} · Y ${nc[1].toFixed(3)} · Z ${nc[2].toFixed(3)}`,
  probeShape: (p) => [p.diameter, p.is_probe, p.tool_length],
  orient(probe, status) {
    probe.quaternion.setFromUnitVectors(new THREE.Vector3(0, 0, 1), v3(status.tool_axis || [0, 0, 1]).normalize());
  },

  buildProbe(p) {
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
    return group;
  },

  buildSolids(layers, data) {
    const { solids } = data;
    let part = 0;
    const partMaterial = (kind) => solidMaterial(COLOR[kind] || COLOR.block, 0.55);
    if (solids.block) {
      const c = solids.block.corners;
      layers.solids.add(extruded(c.slice(0, 4), c.slice(4, 8), partMaterial('block')));
      part += 1;
    }
    if (solids.prism) {
      layers.solids.add(extruded(solids.prism.top, solids.prism.bottom, partMaterial('prism')));
      part += 1;
    }
    const rings = {};
    (solids.circles || []).forEach((c) => {
      const r = c.diameter / 2;
      if (c.kind === 'ring_bore' || c.kind === 'ring_outer') {
        rings[c.center.join(',')] = { ...(rings[c.center.join(',')] || {}), [c.kind]: c };
      } else if (c.kind === 'tool_probe') {
        layers.solids.add(cylinder(c.center, c.axis, r, c.height, solidMaterial(COLOR.tool_probe)));
      } else {
        layers.solids.add(cylinder(c.center, c.axis, r, c.height, partMaterial(c.kind), c.kind === 'hole'));
        if (c.kind === 'hole') layers.solids.add(polyline(circlePoints(c.center, c.axis, r), COLOR.hole, { closed: true }));
        part += 1;
      }
    });
    Object.values(rings).forEach(({ ring_bore: bore, ring_outer: outer }) => {
      const ring = outer || bore;
      layers.solids.add(ringBody(ring.center, ring.axis, bore ? bore.diameter / 2 : 0, outer.diameter / 2, ring.height,
        solidMaterial(COLOR.ring)));
    });
    (solids.rects || []).forEach((rect) => {
      const pts = rect.corners.map(v3);
      layers.solids.add(polyline(pts, COLOR[rect.kind] || COLOR.block, { closed: true }));
      const geometry = new THREE.BufferGeometry().setFromPoints(pts);
      geometry.setIndex([0, 1, 2, 0, 2, 3]);
      geometry.computeVertexNormals();
      layers.solids.add(new THREE.Mesh(geometry, partMaterial(rect.kind)));
      part += 1;
    });
    (solids.spheres || []).forEach((s) => {
      const mesh = new THREE.Mesh(new THREE.SphereGeometry(s.diameter / 2, 32, 16), partMaterial('sphere'));
      mesh.position.copy(v3(s.center));
      layers.solids.add(mesh);
      part += 1;
    });
    this.buildTable(layers, data);
    return part;
  },

  buildTable(layers, data) {
    const box = new THREE.Box3().setFromObject(layers.solids);
    const lim = data.limits;
    const z = box.isEmpty() ? lim.Z[0] : box.min.z - 0.5;
    const sx = lim.X[1] - lim.X[0];
    const sy = lim.Y[1] - lim.Y[0];
    const size = Math.max(sx, sy);
    const grid = new THREE.GridHelper(size, Math.round(size / 50), COLOR.grid, COLOR.grid);
    grid.rotation.x = Math.PI / 2;
    grid.position.set(lim.X[0] + size / 2, lim.Y[0] + size / 2, z);
    layers.table.add(grid);
    const table = new THREE.Mesh(new THREE.PlaneGeometry(sx, sy), solidMaterial(COLOR.table));
    table.position.set(lim.X[0] + sx / 2, lim.Y[0] + sy / 2, z - 0.2);
    layers.table.add(table);
  },
};

const KINDS = { mill: MILL, lathe: LATHE };

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
    this.kind = KINDS[el.dataset.kind] || MILL;
    this.camera = new THREE.PerspectiveCamera(35, 1, 1, 50000);
    this.camera.up.copy(v3(this.kind.up));
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
    const nc = this.kind.ncTip(status);
    const tip = nc.map((v, i) => v + this.probeOffset[i]);
    const key = tip.map((v) => v.toFixed(3)).join(' ');
    if (key === this.keys.probePos) return;
    this.keys.probePos = key;
    this.el.dataset.probe = nc.map((v) => v.toFixed(3)).join(' ');
    const out = this.out('probe');
    if (out) out.textContent = this.kind.probeText(nc);
    if (this.probe) {
      this.probe.position.copy(v3(tip));
      this.kind.orient(this.probe, status);
      this.requestRender();
    }
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
    if (changed('solids', [data.solids, data.limits])) {
      dispose(this.layers.solids);
      dispose(this.layers.table);
      this.el.dataset.part = String(this.kind.buildSolids(this.layers, data));
      if (this.kind.summary) Object.assign(this.el.dataset, this.kind.summary(data));
    }
    if (changed('probeShape', this.kind.probeShape(data.probe))) {
      dispose(this.layers.probe);
      this.probe = this.kind.buildProbe(data.probe);
      this.layers.probe.add(this.probe);
      this.keys.probePos = '';
    }
    if (changed('wcs', data.wcs)) this.buildWcs(data.wcs);
    if (changed('plan', data.plan)) this.buildPlan(data.plan);
    if (changed('touches', [data.touches, data.probe.diameter])) this.buildTouches(data.touches, data.probe.diameter / 2);
    if (changed('measured', data.measured)) this.buildMeasured(data.measured);
    this.showProbe(this.kind.sceneStatus(data.probe));
    if (!this.framed) this.frame(data);
    this.el.dataset.hidden = String(!!data.hidden);
    this.el.dataset.sceneKind = data.kind || 'mill';
    this.el.dataset.state = 'ready';
    this.requestRender();
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

  // the door's view (the kind's `view` direction), the solids and the probe in the picture
  frame(data) {
    const { focus } = this.layers.solids.userData;      // a kind's bodies to frame (else all)
    const box = focus ? focus.clone() : new THREE.Box3().setFromObject(this.layers.solids);
    box.expandByPoint(v3(data.probe.tip));
    if (box.isEmpty()) box.setFromPoints(this.kind.corners(data.limits).map(v3));
    const centre = box.getCenter(new THREE.Vector3());
    const radius = Math.max(box.getSize(new THREE.Vector3()).length() / 2, 50);
    const distance = radius / Math.sin(THREE.MathUtils.degToRad(this.camera.fov / 2)) * 0.9 * (this.kind.distance || 1);
    this.camera.position.copy(centre).add(v3(this.kind.view).normalize().multiplyScalar(distance));
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

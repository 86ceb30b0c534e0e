// The 3D view: the body surface (lit, smooth normals), field colours, design overlays (strokes,
// control-point frames, cuts), Langer glyphs and streamlines, the scale bar and the legend.
// Everything is in model millimetres; the view knows nothing of the network.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/OrbitControls.js';
import { rampColor, rampCss } from './colormap.js';

/// three.js takes plain index arrays but wants typed ones (the server's packed triangles) wrapped.
const indexAttribute = (triangles) => (ArrayBuffer.isView(triangles) ? new THREE.BufferAttribute(triangles, 1) : triangles);

const BODY_COLOR = [0.93, 0.78, 0.70];
const STROKE_COLOR = 0xff3b30;
const CUT_COLOR = 0x111111;
const ARROW_COLORS = { normal: 0x3d8bfd, langer: 0xe5534b, cross: 0x3fb950 };

export class Viewer {
  constructor(canvas) {
    this.canvas = canvas;
    this.renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(window.devicePixelRatio || 1);
    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color(0x20242b);
    this.camera = new THREE.PerspectiveCamera(35, 1, 1, 1e5);
    this.controls = new OrbitControls(this.camera, canvas);
    this.controls.enableDamping = false;
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x404050, 1.4));
    this.keyLight = new THREE.DirectionalLight(0xffffff, 1.6);
    this.scene.add(this.keyLight);
    this.scene.add(this.keyLight.target);
    this.material = new THREE.MeshStandardMaterial({ vertexColors: true, roughness: 0.65, metalness: 0.0, side: THREE.DoubleSide });
    this.mesh = null;
    this.overlays = new THREE.Group();
    this.scene.add(this.overlays);
    this.fieldOverlay = new THREE.Group();
    this.scene.add(this.fieldOverlay);
    this.raycaster = new THREE.Raycaster();
    this.display = 'plain';
    this.result = null;
    this.size = 100;
    // Rendering on demand: the scene is drawn in the animation frame after something changed (the
    // camera, a result, a simulation frame, the design, the display, the size), not in every
    // frame. A continuous loop kept a core busy: in software rendering (headless Chromium) it
    // took seconds per frame and doubled the server's edit times on this 2-core machine.
    this.renderPending = false;
    for (const name of ['resize', 'setResult', 'showFrame', 'resetView', 'setDisplay', 'setDesign']) {
      const method = this[name].bind(this);
      this[name] = (...args) => { const r = method(...args); this.requestRender(); return r; };
    }
    this.controls.addEventListener('change', () => this.requestRender());
    new ResizeObserver(() => this.resize()).observe(canvas.parentElement);
    this.resize();
  }

  /// Draws the scene in the next animation frame (once, however often it is asked for before).
  requestRender() {
    if (this.renderPending) return;
    this.renderPending = true;
    requestAnimationFrame(() => { this.renderPending = false; this.render(); });
  }

  resize() {
    const el = this.canvas.parentElement;
    const w = Math.max(1, el.clientWidth), h = Math.max(1, el.clientHeight);
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
  }

  render() {
    this.controls.update();
    this.keyLight.position.copy(this.camera.position).add(this.camera.up.clone().multiplyScalar(this.size));
    this.keyLight.target.position.copy(this.controls.target);
    this.renderer.render(this.scene, this.camera);
    this.updateScaleBar();
  }

  /// A result message from the server: new surface (positions, triangles) and fields.
  setResult(result) {
    const first = !this.result;
    this.result = result;
    const s = result.surface;
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.Float32BufferAttribute(s.positions_mm, 3));
    geometry.setIndex(indexAttribute(s.triangles));
    geometry.computeVertexNormals();
    geometry.setAttribute('color', new THREE.Float32BufferAttribute(new Float32Array(s.positions_mm.length), 3));
    if (this.mesh) { this.scene.remove(this.mesh); this.mesh.geometry.dispose(); }
    this.mesh = new THREE.Mesh(geometry, this.material);
    this.scene.add(this.mesh);
    const [lo, hi] = result.bounding_box_mm;
    this.bounds = { lo: new THREE.Vector3(...lo), hi: new THREE.Vector3(...hi) };
    this.size = this.bounds.hi.clone().sub(this.bounds.lo).length();
    this.overlayScale = this.size / 250;
    if (first) this.resetView();
    this.applyDisplay();
  }

  /// A simulation frame of the wound opening: new positions (and, on the first frame, the
  /// triangles of the cut surface). The body colour is shown until the result arrives.
  showFrame(positions, triangles) {
    if (!this.mesh) return;
    if (triangles) {
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.Float32BufferAttribute(positions, 3));
      g.setIndex(indexAttribute(triangles));
      const colors = new Float32Array(positions.length);
      for (let i = 0; i < colors.length; i += 3) colors.set(BODY_COLOR, i);
      g.setAttribute('color', new THREE.Float32BufferAttribute(colors, 3));
      g.computeVertexNormals();
      this.scene.remove(this.mesh);
      this.mesh.geometry.dispose();
      this.mesh = new THREE.Mesh(g, this.material);
      this.scene.add(this.mesh);
      this.fieldOverlay.clear();
      return;
    }
    const attr = this.mesh.geometry.attributes.position;
    if (attr.array.length !== positions.length) return;
    attr.array.set(positions);
    attr.needsUpdate = true;
    this.mesh.geometry.computeVertexNormals();
  }

  resetView() {
    if (!this.bounds) return;
    const centre = this.bounds.lo.clone().add(this.bounds.hi).multiplyScalar(0.5);
    const extent = this.bounds.hi.clone().sub(this.bounds.lo);
    // Look at the largest face of the bounding box (the abdomen's skin), slightly from above.
    const axes = [0, 1, 2].sort((a, b) => extent.getComponent(b) - extent.getComponent(a));
    const view = new THREE.Vector3(); view.setComponent(3 - axes[0] - axes[1], 1);
    const up = new THREE.Vector3(); up.setComponent(axes[1], 1);
    this.camera.up.copy(up);
    const distance = (1.35 * Math.max(extent.getComponent(axes[0]), extent.getComponent(axes[1]))) / (2 * Math.tan((this.camera.fov * Math.PI) / 360));
    this.camera.position.copy(centre).add(view.multiplyScalar(distance)).add(up.clone().multiplyScalar(0.25 * distance));
    this.camera.near = distance / 100; this.camera.far = distance * 20;
    this.camera.updateProjectionMatrix();
    this.controls.target.copy(centre);
    this.controls.update();
  }

  /// The surface point under canvas pixel (x, y): {point, normal, vertex} or null.
  pick(x, y) {
    if (!this.mesh) return null;
    const rect = this.canvas.getBoundingClientRect();
    const ndc = new THREE.Vector2((x / rect.width) * 2 - 1, -(y / rect.height) * 2 + 1);
    this.raycaster.setFromCamera(ndc, this.camera);
    const hit = this.raycaster.intersectObject(this.mesh, false)[0];
    if (!hit) return null;
    const normal = hit.face.normal.clone();
    if (normal.dot(this.raycaster.ray.direction) > 0) normal.negate();
    const f = hit.face;
    const pos = this.mesh.geometry.attributes.position;
    let vertex = f.a, best = Infinity;
    for (const v of [f.a, f.b, f.c]) {
      const d = new THREE.Vector3().fromBufferAttribute(pos, v).distanceTo(hit.point);
      if (d < best) { best = d; vertex = v; }
    }
    return { point: hit.point.clone(), normal, vertex };
  }

  /// Canvas pixel of a model point.
  screenOf(p) {
    const v = new THREE.Vector3(...p).project(this.camera);
    const rect = this.canvas.getBoundingClientRect();
    return [((v.x + 1) / 2) * rect.width, ((1 - v.y) / 2) * rect.height];
  }

  setDisplay(mode) { this.display = mode; this.applyDisplay(); }

  /// Colours the surface and builds glyphs / streamlines for the current display mode.
  applyDisplay() {
    if (!this.mesh) return;
    const fields = (this.result && this.result.fields) || {};
    const colors = this.mesh.geometry.attributes.color;
    const n = colors.count;
    const legend = document.getElementById('legend');
    this.fieldOverlay.clear();
    // [field, title, unit, ramp]; negative values of the cut-face fields mark vertices off the cut faces.
    const scalar = { langer: ['langer_kPa', 'Eigenvalue along Langer', 'kPa', 'tension'],
                     cross: ['cross_kPa', 'Eigenvalue across Langer', 'kPa', 'tension'],
                     residual: ['residual_kPa', 'Equilibrium residual |Tσ|/h²', 'kPa', 'tension'],
                     displacement: ['displacement_mm', 'Displacement', 'mm', 'tension'],
                     depth: ['cut_depth', 'Cut faces by depth (0 skin, 1 inner layer)', 'relative', 'depth', true],
                     traction: ['traction_kPa', 'Cut faces by released traction', 'kPa', 'tension', true] }[this.display];
    const values = scalar ? fields[scalar[0]] : null;
    const shown = values && values.length === n;
    const onCut = (v) => !scalar[4] || v >= 0;
    let lo = Infinity, hi = -Infinity;
    if (shown) for (const v of values) if (onCut(v)) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
    // A uniform field (e.g. the residual of an exactly equilibrated design): one colour, and the
    // legend says so instead of inventing a range.
    const uniform = !(hi > lo);
    if (uniform) { lo = Number.isFinite(lo) ? lo : 0; hi = lo + 1; }
    for (let i = 0; i < n; i++) {
      const c = shown && onCut(values[i]) ? rampColor(scalar[3], (values[i] - lo) / (hi - lo)) : BODY_COLOR;
      colors.setXYZ(i, c[0], c[1], c[2]);
    }
    colors.needsUpdate = true;
    if (scalar) {
      legend.hidden = false;
      legend.querySelector('.title').textContent = !shown ? `${scalar[1]}: not computed yet`
        : uniform ? `${scalar[1]} (${scalar[2]}): uniform ${lo.toFixed(2)}` : `${scalar[1]} (${scalar[2]})`;
      legend.querySelector('.ramp').style.background = rampCss(scalar[3]);
      // Fields travel as float32 without rounding: a range of 1e-12 kPa (an equilibrated design's
      // residual) is shown as such, not as 0.0000 .. 0.0000.
      const span = hi - lo;
      const digits = Math.min(8, Math.max(3, Math.ceil(Math.log10(Math.max(Math.abs(lo), Math.abs(hi)) / span)) + 2));
      const label = (v) => (uniform || span >= 0.1 ? v.toFixed(2) : v.toPrecision(digits));
      legend.querySelector('.lo').textContent = shown ? label(lo) : '';
      legend.querySelector('.hi').textContent = shown ? label(uniform ? lo : hi) : '';
    } else {
      legend.hidden = true;
    }
    if (this.display === 'glyphs') this.buildGlyphs(fields.direction);
    if (this.display === 'streamlines') this.buildStreamlines(this.result.streamlines_mm);
  }

  buildGlyphs(direction) {
    if (!direction) return;
    const pos = this.mesh.geometry.attributes.position;
    const nrm = this.mesh.geometry.attributes.normal;
    const spacing = Math.max(1, this.result.cell_size_mm || 1);
    const half = 0.8 * spacing;
    const seen = new Set();
    const pts = [];
    for (let i = 0; i < pos.count; i++) {
      const key = [0, 1, 2].map((k) => Math.floor(pos.array[3 * i + k] / (2 * spacing))).join(',');
      if (seen.has(key)) continue;
      seen.add(key);
      const d = new THREE.Vector3(direction[3 * i], direction[3 * i + 1], direction[3 * i + 2]);
      if (d.lengthSq() < 1e-12) continue;
      d.normalize().multiplyScalar(half);
      const p = new THREE.Vector3().fromBufferAttribute(pos, i).add(new THREE.Vector3().fromBufferAttribute(nrm, i).multiplyScalar(0.05 * spacing));
      pts.push(p.x - d.x, p.y - d.y, p.z - d.z, p.x + d.x, p.y + d.y, p.z + d.z);
    }
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.Float32BufferAttribute(pts, 3));
    this.fieldOverlay.add(new THREE.LineSegments(g, new THREE.LineBasicMaterial({ color: 0xffd400 })));
  }

  buildStreamlines(lines) {
    if (!lines) return;
    // Each line is a flat [x, y, z, x, y, z, ...] array (mm), traced through the volume's cells:
    // inside a thin wall it would hide under the skin, so each point is drawn on the surface
    // nearest to it, lifted slightly along the normal (paper fig. 6 shows them on the skin).
    // Drawn as one set of segments.
    const onSurface = this.surfaceProjector();
    const pts = [];
    for (const line of lines) {
      let prev = null;
      for (let i = 0; i < line.length; i += 3) {
        const p = onSurface(line[i], line[i + 1], line[i + 2]);
        if (prev && p) pts.push(...prev, ...p);
        prev = p;
      }
    }
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.Float32BufferAttribute(pts, 3));
    this.fieldOverlay.add(new THREE.LineSegments(g, new THREE.LineBasicMaterial({ color: 0xffd400 })));
  }

  /// (x, y, z) -> its projection onto the tangent plane of the nearest surface vertex (within 1.5
  /// cells), lifted by 0.15 cell along that vertex's normal, or null; a hash of the vertices by
  /// cell keeps it linear.
  surfaceProjector() {
    const pos = this.mesh.geometry.attributes.position, nrm = this.mesh.geometry.attributes.normal;
    const h = Math.max(1e-3, this.result.cell_size_mm || 1);
    const key = (i, j, k) => `${i},${j},${k}`;
    const grid = new Map();
    for (let v = 0; v < pos.count; v++) {
      const k = key(Math.floor(pos.array[3 * v] / h), Math.floor(pos.array[3 * v + 1] / h), Math.floor(pos.array[3 * v + 2] / h));
      if (!grid.has(k)) grid.set(k, []);
      grid.get(k).push(v);
    }
    return (x, y, z) => {
      const ci = Math.floor(x / h), cj = Math.floor(y / h), ck = Math.floor(z / h);
      let best = -1, bestD = (1.5 * h) ** 2;
      for (let a = -1; a <= 1; a++) for (let b = -1; b <= 1; b++) for (let c = -1; c <= 1; c++)
        for (const v of grid.get(key(ci + a, cj + b, ck + c)) || []) {
          const d = (pos.array[3 * v] - x) ** 2 + (pos.array[3 * v + 1] - y) ** 2 + (pos.array[3 * v + 2] - z) ** 2;
          if (d < bestD) { bestD = d; best = v; }
        }
      if (best < 0) return null;
      // Along the vertex normal onto the vertex's tangent plane (keeps the line smooth), then lifted.
      const n = [0, 1, 2].map((k) => nrm.array[3 * best + k]);
      const along = n[0] * (pos.array[3 * best] - x) + n[1] * (pos.array[3 * best + 1] - y) + n[2] * (pos.array[3 * best + 2] - z);
      return [x, y, z].map((c, k) => c + (along + 0.15 * h) * n[k]);
    };
  }

  /// Draws the design: strokes (red), cut paths (dark), control points with their tensor frame.
  setDesign(design, selected, frames) {
    this.overlays.clear();
    const lift = (p) => p;
    const line = (points, color, width) => {
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.Float32BufferAttribute(points.map(lift).flat(), 3));
      const m = new THREE.LineBasicMaterial({ color, linewidth: width, depthTest: false, transparent: true });
      const l = new THREE.Line(g, m);
      l.renderOrder = 2;
      return l;
    };
    for (const s of design.strokes) {
      const l = line(s.points_mm, s.id === selected ? 0xffffff : STROKE_COLOR, 3);
      l.userData = { kind: 'stroke', id: s.id };
      this.overlays.add(l);
      this.overlays.add(this.arrowHead(s.points_mm, s.id === selected ? 0xffffff : STROKE_COLOR));
    }
    for (const c of design.cuts) this.overlays.add(line(c.kind === 'flap' ? [...c.path_mm, c.path_mm[0]] : c.path_mm, CUT_COLOR, 2));
    for (const p of design.control_points) {
      const frame = frames(p);
      const origin = new THREE.Vector3(...p.position_mm);
      const scale = this.overlayScale || 1;
      const arrows = [['normal', frame.normal, Math.max(2, 0.2 * Math.abs(p.langer_kPa))],
                      ['langer', frame.langer, Math.abs(p.langer_kPa)], ['cross', frame.cross, Math.abs(p.cross_kPa)]];
      for (const [name, dir, value] of arrows) {
        const length = Math.max(0.5, value) * scale;
        const a = new THREE.ArrowHelper(new THREE.Vector3(...dir).normalize(), origin, length, ARROW_COLORS[name], 0.25 * length, 0.12 * length);
        a.userData = { kind: 'arrow', id: p.id, axis: name };
        a.renderOrder = 3;
        a.traverse((o) => { if (o.material) { o.material.depthTest = false; o.material.transparent = true; } });
        this.overlays.add(a);
      }
      const dot = new THREE.Mesh(new THREE.SphereGeometry(0.4 * scale * 3, 12, 8),
        new THREE.MeshBasicMaterial({ color: p.id === selected ? 0xffffff : 0xffd400, depthTest: false, transparent: true }));
      dot.position.copy(origin);
      dot.renderOrder = 3;
      this.overlays.add(dot);
    }
  }

  arrowHead(points, color) {
    const n = points.length;
    const a = new THREE.Vector3(...points[n - 2]), b = new THREE.Vector3(...points[n - 1]);
    const dir = b.clone().sub(a);
    const len = (this.overlayScale || 1) * 6;
    const h = new THREE.ArrowHelper(dir.normalize(), b, len, color, len, 0.5 * len);
    h.line.visible = false;
    h.traverse((o) => { if (o.material) { o.material.depthTest = false; o.material.transparent = true; } });
    h.renderOrder = 2;
    return h;
  }

  /// Screen length of `mm` at the orbit target, in CSS pixels.
  pixelsPerMm() {
    const distance = this.camera.position.distanceTo(this.controls.target);
    const visible = 2 * distance * Math.tan((this.camera.fov * Math.PI) / 360);
    return this.canvas.getBoundingClientRect().height / visible;
  }

  updateScaleBar() {
    const ppm = this.pixelsPerMm();
    if (!Number.isFinite(ppm) || ppm <= 0) return;
    const target = 120 / ppm;
    const p10 = Math.pow(10, Math.floor(Math.log10(target)));
    const nice = [1, 2, 5, 10].map((f) => f * p10).filter((v) => v <= target).pop() || p10;
    const bar = document.querySelector('#scale-bar .bar');
    bar.style.width = `${(nice * ppm).toFixed(0)}px`;
    document.querySelector('#scale-bar .label').textContent = `${nice} mm`;
  }

  screenshot() { this.render(); return this.canvas.toDataURL('image/png'); }
}

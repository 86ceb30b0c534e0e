// The studio page: wires the connection, the view and the tools. window.studio exposes the
// state for the end-to-end tests (tests/browser).
import * as THREE from 'three';
import { Connection } from './connection.js';
import { Viewer } from './viewer.js';

const $ = (id) => document.getElementById(id);
const viewer = new Viewer($('canvas'));
const app = {
  state: null,          // last "state" message (design, seq, can_undo, can_redo)
  result: null,         // last "result" message (surface, fields, timings)
  resultCount: 0,
  finalCount: 0,        // "design_final" messages applied (an equilibration completed after its picture)
  tool: 'orbit',
  selected: { kind: null, id: null },
  wound: null,
  lastError: null,
  frames: 0,
  resultSeqs: [],       // the edit (seq) of every result received, in order
  progressCount: 0,     // progress messages seen (work longer than 0.25 s)
  lastProgress: null,
  pictureMs: [],        // per edit sent from this page: send to the frame that shows its result (ms)
};
/// The edit whose picture this page waits for: sent at t0 (performance.now()), acknowledged as seq.
const pictureClock = { t0: null, seq: null };
window.studio = { app, viewer, pickAt: (x, y) => viewer.pick(x, y), screenOf: (p) => viewer.screenOf(p) };

function setMessage(text, isError = false) {
  $('message').textContent = text;
  $('message').className = isError ? 'error' : '';
  if (isError) app.lastError = text;
}

/// The server leaves a result's triangles and cut-face depths out when its surface (surface.id)
/// is the one it sent before; they are taken from the last result that had them. A result for a
/// surface this page never got (it connected in between) is skipped and the full latest result
/// asked for (hello).
const surfaceCache = { id: null, triangles: null, cutDepth: null };
function withSurfaceParts(m) {
  const s = m.surface;
  if (s.triangles) {
    surfaceCache.id = s.id;
    surfaceCache.triangles = s.triangles;
    surfaceCache.cutDepth = (m.fields && m.fields.cut_depth) || null;
    return true;
  }
  if (s.id !== undefined && s.id === surfaceCache.id) {
    s.triangles = surfaceCache.triangles;
    if (surfaceCache.cutDepth && m.fields && !m.fields.cut_depth) m.fields.cut_depth = surfaceCache.cutDepth;
    return true;
  }
  connection.request('hello').catch(() => {});
  return false;
}

function onMessage(m) {
  if (m.type === 'state') {
    app.state = m;
    refreshDesign();
  } else if (m.type === 'result') {
    if (!withSurfaceParts(m)) return;
    app.result = m;
    app.resultCount++;
    app.resultSeqs.push(m.seq);
    viewer.setResult(m);
    refreshDesign();
    showTimings(m.timings_ms || {});
    notePicture(m);
    showNotes(m);
    $('progress').hidden = true;
    showPreview(m.incisions || []);
    if (m.flaps && m.flaps.length) {
      const f = m.flaps[m.flaps.length - 1];
      $('flap-change').textContent = `${f.skin_area_change_percent.toFixed(1)} % of ${f.skin_area_mm2.toFixed(0)} mm² (volume ${f.volume_change_percent.toFixed(1)} %)`;
    } else {
      $('flap-change').textContent = '–';
    }
    if (m.wounds && m.wounds.length) {
      app.wound = m.wounds[m.wounds.length - 1];
      $('wound-width').textContent = `${app.wound.width_mm.toFixed(1)} mm (max), ${app.wound.mean_width_mm.toFixed(2)} mm (mean)`;
    } else {
      app.wound = null;
      $('wound-width').textContent = '–';
    }
    $('model-info').textContent = `${app.state ? app.state.model.source : ''} · ${m.cells} cells · ${m.cell_size_mm.toFixed(2)} mm`;
  } else if (m.type === 'design_final') {
    // The picture came from the equilibration's provisional stress (1e-6 of the designed forces);
    // this completes that edit's design: its residual display, cut-face tractions and residual.
    const r = app.result;
    if (!r || r.seq !== m.seq || r.generation !== m.generation) return;
    app.finalCount++;
    Object.assign(r.fields, m.fields);
    r.equilibrium_residual = m.equilibrium_residual;
    Object.assign(r.timings_ms, m.timings_ms);
    viewer.setDisplay(viewer.display);
    renderTimings(r.timings_ms);
    showNotes(r);
    $('progress').hidden = true;
  } else if (m.type === 'frame') {
    // The wound opening, streamed step by step before the final result.
    app.frames++;
    app.lastFrame = { index: m.index, time_s: m.time_s, width_mm: m.width_mm, step_ms: m.step_ms,
      step_iterations: m.step_iterations, step_residual: m.step_residual };
    viewer.showFrame(m.positions_mm, m.triangles);
    const width = m.width_mm !== undefined ? `${m.width_mm.toFixed(2)} mm` : '–';
    $('wound-width').textContent = `${width} (t = ${(m.time_s * 1000).toFixed(0)} ms)`;
    $('progress').hidden = false;
    $('progress').querySelector('.fill').style.width = `${((100 * m.index) / m.frames).toFixed(0)}%`;
    const budget = m.step_residual !== undefined ? ` (${m.step_iterations} iterations, residual ${m.step_residual.toExponential(0)} of the step's)` : '';
    $('progress').querySelector('.text').textContent = `opening the wound: frame ${m.index}/${m.frames} · ${m.step_ms.toFixed(0)} ms per step${budget}`;
  } else if (m.type === 'progress') {
    app.progressCount++;
    app.lastProgress = m;
    $('progress').hidden = false;
    $('progress').querySelector('.fill').style.width = `${(100 * m.fraction).toFixed(0)}%`;
    $('progress').querySelector('.text').textContent = `${m.stage}…`;
  } else if (m.type === 'error') {
    // A computation that failed (e.g. a non-finite value, naming its stage) keeps the last picture.
    if (m.stage) $('progress').hidden = true;
    setMessage(m.message, true);
  }
}

const STAGES = { directions: 'directions', eigenvalues: 'eigenvalues', equilibration: 'equilibration', cuts: 'cut model', opening: 'wound opening (frames)',
  equilibration_completion: 'equilibration completed (after the picture)', frame: 'one simulation frame', incisions: 'incisions open (statics)', surface: 'surface and fields', streamlines: 'streamlines', measurements: 'incision and wound measurements', total: 'computed (server)' };
/// Rows the page measures itself, after the server's stages.
const PAGE_ROWS = { decode: 'received and decoded (page)', picture: 'edit to picture (page)' };
const pageTimes = {};

function timingRow(label, ms) {
  const tr = document.createElement('tr');
  tr.innerHTML = `<td>${label}</td><td>${ms.toFixed(0)} ms</td>`;
  return tr;
}
function showTimings(t) {
  pageTimes.decode = connection.lastDecodeMs;
  delete pageTimes.picture;  // until this result's picture is drawn (edits sent from this page)
  renderTimings(t);
  $('timings').textContent = Object.entries(t).map(([k, v]) => `${k} ${v.toFixed(0)} ms`).join(' · ');
}

function renderTimings(t) {
  const rows = Object.keys(STAGES).filter((k) => t[k] !== undefined).map((k) => timingRow(STAGES[k], t[k]));
  for (const [k, label] of Object.entries(PAGE_ROWS)) if (pageTimes[k] !== undefined) rows.push(timingRow(label, pageTimes[k]));
  $('timing-table').replaceChildren(...rows);
  const headline = pageTimes.picture !== undefined ? pageTimes.picture : t.total;
  $('timing-total').textContent = headline !== undefined ? `${headline.toFixed(0)} ms` : '–';
}

/// The time from sending an edit to the frame that shows its result, for the edits this page sent:
/// taken in the animation frame after the result reached the viewer (network, the server's work,
/// the transfer, decoding and the geometry upload included).
function notePicture(m) {
  if (pictureClock.seq === null || m.seq === undefined || m.seq < pictureClock.seq) return;
  const t0 = pictureClock.t0;
  pictureClock.seq = null;
  requestAnimationFrame(() => {
    const ms = performance.now() - t0;
    app.pictureMs.push(ms);
    pageTimes.picture = ms;
    if (app.result === m) renderTimings(m.timings_ms || {});
  });
}

/// The round-incision preview in numbers: how far the margins open and how elliptic they become.
function showPreview(incisions) {
  $('incision-count').textContent = incisions.length;
  if (!incisions.length) { $('preview-info').textContent = '–'; return; }
  const mean = (key) => incisions.reduce((a, i) => a + i[key], 0) / incisions.length;
  const min = Math.min(...incisions.map((i) => i.opening_mm)), max = Math.max(...incisions.map((i) => i.opening_mm));
  $('preview-info').textContent = `opening ${min.toFixed(2)} to ${max.toFixed(2)} mm (mean ${mean('opening_mm').toFixed(2)} mm) · axis ratio ${mean('axis_ratio').toFixed(3)}`;
}

/// What the last result could not compute, shown in the page (the rest of the result still is).
function showNotes(m) {
  const notes = [];
  if (m.eigenvalue_note) notes.push(['note', m.eigenvalue_note]);
  for (const key of ['design_error', 'cut_error']) if (m[key]) notes.push(['error', m[key]]);
  if (m.equilibrium_residual) {
    const provisional = m.equilibrium_residual.provisional ? ' (provisional: the equilibration completes after the picture)' : '';
    notes.push(['note', `equilibrium residual ||T σ|| / (||T|| ||σ||) = ${m.equilibrium_residual.final.toExponential(2)}${provisional}`]);
  }
  if (m.statics_solver === 'multigrid' && !m.statics_note) notes.push(['note', 'incisions solved by the multigrid while the direct factor of this cut body is prepared (later edits: faster)']);
  if (m.statics_note) notes.push(['error', m.statics_note]);
  $('notes').replaceChildren(...notes.map(([cls, text]) => { const d = document.createElement('div'); d.className = cls; d.textContent = text; return d; }));
}

const connection = new Connection(`ws://${location.host}/ws`, onMessage, (up) => {
  $('conn').textContent = up ? 'connected' : 'offline';
  $('conn').className = up ? 'good' : 'bad';
});
window.studio.connection = connection;

async function send(cmd, fields = {}) {
  try {
    const t0 = performance.now();
    const reply = await connection.request(cmd, fields);
    if (reply.type === 'ack') Object.assign(pictureClock, { t0, seq: reply.seq });
    setMessage(reply.type === 'ack' ? `${cmd}: done (edit ${reply.seq})` : `${cmd}: ${reply.type}`);
    return reply;
  } catch (e) {
    setMessage(e.message, true);
    throw e;
  }
}
window.studio.send = send;

// --- design list and overlays --------------------------------------------------------------
/// The local tensor frame at a surface point: normal, Langer direction, cross direction.
function frameAt(position) {
  let normal = [0, 0, 1], langer = [1, 0, 0];
  if (viewer.mesh && app.result) {
    const pos = viewer.mesh.geometry.attributes.position, nrm = viewer.mesh.geometry.attributes.normal;
    let best = 0, bestD = Infinity;
    for (let i = 0; i < pos.count; i++) {
      const dx = pos.array[3 * i] - position[0], dy = pos.array[3 * i + 1] - position[1], dz = pos.array[3 * i + 2] - position[2];
      const d = dx * dx + dy * dy + dz * dz;
      if (d < bestD) { bestD = d; best = i; }
    }
    normal = [nrm.array[3 * best], nrm.array[3 * best + 1], nrm.array[3 * best + 2]];
    const dir = app.result.fields && app.result.fields.direction;
    if (dir) langer = [dir[3 * best], dir[3 * best + 1], dir[3 * best + 2]];
  }
  const n = new THREE.Vector3(...normal).normalize();
  let l = new THREE.Vector3(...langer);
  l.addScaledVector(n, -l.dot(n));
  if (l.lengthSq() < 1e-8) l = new THREE.Vector3(1, 0, 0).cross(n).lengthSq() > 1e-4 ? new THREE.Vector3(1, 0, 0).cross(n) : new THREE.Vector3(0, 1, 0).cross(n);
  l.normalize();
  const c = n.clone().cross(l).normalize();
  return { normal: n.toArray(), langer: l.toArray(), cross: c.toArray() };
}
window.studio.frameAt = frameAt;

function refreshDesign() {
  if (!app.state) return;
  const d = app.state.design;
  $('seq').textContent = `edits ${app.state.seq}`;
  $('undo').disabled = !app.state.can_undo;
  $('redo').disabled = !app.state.can_redo;
  const list = (el, items, kind, label) => {
    $(el).replaceChildren(...items.map((item) => {
      const li = document.createElement('li');
      li.dataset.id = item.id;
      li.className = app.selected.kind === kind && app.selected.id === item.id ? 'selected' : '';
      li.append(label(item));
      const del = document.createElement('button');
      del.textContent = '×';
      del.title = 'delete';
      del.onclick = (e) => { e.stopPropagation(); send(`delete_${kind}`, { id: item.id }); };
      li.append(del);
      li.onclick = () => select(kind, item.id);
      return li;
    }));
  };
  list('stroke-list', d.strokes, 'stroke', (s) => `Stroke ${s.id} · ${s.points_mm.length} pts`);
  list('point-list', d.control_points, 'control_point', (p) => `Point ${p.id} · ${p.langer_kPa} / ${p.cross_kPa} kPa`);
  list('cut-list', d.cuts, 'cut', (c) => `${c.kind === 'flap' ? 'Flap' : 'Cut'} ${c.id} · ${c.depth_mm} mm deep`);
  $('stroke-count').textContent = d.strokes.length;
  $('point-count').textContent = d.control_points.length;
  $('cut-count').textContent = d.cuts.length;
  const point = d.control_points.find((p) => app.selected.kind === 'control_point' && p.id === app.selected.id);
  $('point-editor').hidden = !point;
  if (point && document.activeElement !== $('langer-kpa') && document.activeElement !== $('cross-kpa')) {
    $('langer-kpa').value = point.langer_kPa;
    $('cross-kpa').value = point.cross_kPa;
  }
  viewer.setDesign(d, app.selected.id, (p) => frameAt(p.position_mm));
}

function select(kind, id) {
  app.selected = { kind, id };
  refreshDesign();
}

// --- tools -----------------------------------------------------------------------------------
function setTool(tool) {
  app.tool = tool;
  for (const b of document.querySelectorAll('button.tool')) b.classList.toggle('active', b.dataset.tool === tool);
  viewer.controls.enabled = tool === 'orbit';
  $('hint').textContent = {
    orbit: 'drag: orbit · right-drag: pan · wheel: zoom',
    stroke: 'press and drag on the surface to draw a Langer stroke · drag a stroke with Shift to move it',
    magnitude: 'click on the surface to place a control point · drag an arrow tip to change its eigenvalue',
    cut: 'press and drag on the surface to cut · a flap: drag from its hinge to its tip (width and depth on the right)',
  }[tool];
}
for (const b of document.querySelectorAll('button.tool')) b.onclick = () => setTool(b.dataset.tool);
setTool('orbit');

const canvas = $('canvas');
let drag = null;
const local = (e) => { const r = canvas.getBoundingClientRect(); return [e.clientX - r.left, e.clientY - r.top]; };

/// A U-shaped flap of the panel's width around the drawn line (its hinge at the start, its tip at
/// the end): [hinge left, tip left, tip right, hinge right], each corner put back on the surface
/// under it. Null for a line too short to give a direction.
function flapOutline(points, width) {
  const a = new THREE.Vector3(...points[0]), b = new THREE.Vector3(...points[points.length - 1]);
  const along = b.clone().sub(a);
  if (along.length() < 1e-3 || !(width > 0)) return null;
  const n = new THREE.Vector3(...frameAt(a.clone().add(b).multiplyScalar(0.5).toArray()).normal);
  const side = n.clone().cross(along).normalize().multiplyScalar(0.5 * width);
  if (!Number.isFinite(side.x)) return null;
  return [a.clone().add(side), b.clone().add(side), b.clone().sub(side), a.clone().sub(side)].map((p) => {
    const [x, y] = viewer.screenOf(p.toArray());
    const hit = viewer.pick(x, y);
    return hit ? hit.point.toArray() : p.toArray();
  });
}

/// The path sent for the drawn points: a scalpel follows the pointer; a flap is the U around it.
function cutPath(points) {
  if ($('cut-kind').value !== 'flap') return points;
  return flapOutline(points, Number($('flap-width').value));
}
window.studio.flapOutline = flapOutline;

function nearestStroke(point) {
  let best = null, bestD = Infinity;
  for (const s of app.state.design.strokes)
    for (const p of s.points_mm) {
      const d = Math.hypot(p[0] - point.x, p[1] - point.y, p[2] - point.z);
      if (d < bestD) { bestD = d; best = s; }
    }
  return bestD < 3 * ((app.result && app.result.cell_size_mm) || 1) ? best : null;
}

function arrowUnder(x, y) {
  // The tip of a control-point arrow within 12 px of (x, y).
  for (const p of app.state.design.control_points) {
    const f = frameAt(p.position_mm);
    for (const axis of ['langer', 'cross']) {
      const value = Math.max(0.5, Math.abs(axis === 'langer' ? p.langer_kPa : p.cross_kPa));
      const tip = p.position_mm.map((v, k) => v + f[axis][k] * value * viewer.overlayScale);
      const [sx, sy] = viewer.screenOf(tip);
      if (Math.hypot(sx - x, sy - y) < 12) return { point: p, axis, frame: f };
    }
  }
  return null;
}

canvas.addEventListener('pointerdown', (e) => {
  if (app.tool === 'orbit' || e.button !== 0 || !app.state) return;
  const [x, y] = local(e);
  if (app.tool === 'magnitude') {
    const arrow = arrowUnder(x, y);
    if (arrow) { drag = { kind: 'arrow', ...arrow }; canvas.setPointerCapture(e.pointerId); return; }
  }
  const hit = viewer.pick(x, y);
  if (!hit) return;
  if (app.tool === 'stroke' && e.shiftKey) {
    const s = nearestStroke(hit.point);
    if (s) { select('stroke', s.id); drag = { kind: 'move', stroke: s, start: hit.point }; canvas.setPointerCapture(e.pointerId); }
    return;
  }
  if (app.tool === 'magnitude') {
    send('add_control_point', { position_mm: hit.point.toArray(), langer_kPa: 20, cross_kPa: 10 })
      .then(() => { const pts = app.state.design.control_points; if (pts.length) select('control_point', pts[pts.length - 1].id); })
      .catch(() => {});
    return;
  }
  drag = { kind: app.tool, points: [hit.point.toArray()] };
  canvas.setPointerCapture(e.pointerId);
});

canvas.addEventListener('pointermove', (e) => {
  if (!drag) return;
  const [x, y] = local(e);
  if (drag.kind === 'arrow') {
    // Project the pointer onto the arrow's line on screen: the eigenvalue is the tip's distance.
    const p = drag.point.position_mm, dir = drag.frame[drag.axis];
    const [ox, oy] = viewer.screenOf(p);
    const [tx, ty] = viewer.screenOf(p.map((v, k) => v + dir[k] * viewer.overlayScale));
    const ux = tx - ox, uy = ty - oy, len2 = ux * ux + uy * uy;
    if (len2 > 1e-6) drag.value = Math.max(0, Math.round((((x - ox) * ux + (y - oy) * uy) / len2) * 2) / 2);
    return;
  }
  const hit = viewer.pick(x, y);
  if (!hit) return;
  if (drag.kind === 'move') { drag.end = hit.point; return; }
  const last = drag.points[drag.points.length - 1];
  const spacing = 0.5 * ((app.result && app.result.cell_size_mm) || 1);
  if (Math.hypot(hit.point.x - last[0], hit.point.y - last[1], hit.point.z - last[2]) >= spacing) {
    drag.points.push(hit.point.toArray());
    viewer.setDesign({ ...app.state.design, strokes: [...app.state.design.strokes, ...(drag.kind === 'stroke' ? [{ id: -1, points_mm: drag.points.length > 1 ? drag.points : [last, last] }] : [])],
      cuts: [...app.state.design.cuts, ...(drag.kind === 'cut' && drag.points.length > 1 ? [{ id: -1, kind: $('cut-kind').value, path_mm: cutPath(drag.points) || drag.points }] : [])] },
      app.selected.id, (p) => frameAt(p.position_mm));
  }
});

canvas.addEventListener('pointerup', () => {
  const d = drag;
  drag = null;
  if (!d) return;
  if (d.kind === 'arrow') {
    if (d.value !== undefined) send('set_control_point', { id: d.point.id, [d.axis === 'langer' ? 'langer_kPa' : 'cross_kPa']: d.value }).catch(() => {});
    return;
  }
  if (d.kind === 'move') {
    if (d.end) send('move_stroke', { id: d.stroke.id, offset_mm: [d.end.x - d.start.x, d.end.y - d.start.y, d.end.z - d.start.z] }).catch(() => {});
    return;
  }
  if (d.points.length < 2) { refreshDesign(); return; }
  if (d.kind === 'stroke') send('add_stroke', { points_mm: d.points }).catch(() => {});
  if (d.kind === 'cut') {
    const path = cutPath(d.points);
    if (!path) { refreshDesign(); return; }
    send('add_cut', { kind: $('cut-kind').value, path_mm: path, depth_mm: Number($('cut-depth').value) }).catch(() => {});
  }
});

// --- panel and toolbar ------------------------------------------------------------------------
const setValue = (key) => () => {
  if (app.selected.kind !== 'control_point') return;
  const v = Number($(key === 'langer_kPa' ? 'langer-kpa' : 'cross-kpa').value);
  if (Number.isFinite(v)) send('set_control_point', { id: app.selected.id, [key]: v }).catch(() => {});
};
$('langer-kpa').addEventListener('change', setValue('langer_kPa'));
$('cross-kpa').addEventListener('change', setValue('cross_kPa'));
$('undo').onclick = () => send('undo').catch(() => {});
$('redo').onclick = () => send('redo').catch(() => {});
$('reset-view').onclick = () => viewer.resetView();
$('reset-cuts').onclick = () => send('reset_cuts').catch(() => {});
$('display').onchange = () => viewer.setDisplay($('display').value);
$('cut-kind').onchange = () => { $('flap-width-label').hidden = $('cut-kind').value !== 'flap'; };
$('save').onclick = () => send('save', { file: $('file-name').value }).then(() => { $('files-note').innerHTML = `saved <a href="/session/${encodeURIComponent($('file-name').value)}">${$('file-name').value}</a>`; }).catch(() => {});
$('load').onclick = () => send('load', { file: $('file-name').value }).catch(() => {});
$('export').onchange = () => {
  const format = $('export').value;
  $('export').value = '';
  if (!format) return;
  const file = `export.${format}`;
  send('export', { format, file }).then(() => { $('files-note').innerHTML = `exported <a href="/session/${file}" download>${file}</a>`; }).catch(() => {});
};
$('screenshot').onclick = () => {
  const a = document.createElement('a');
  a.href = viewer.screenshot();
  a.download = 'cleave-studio.png';
  a.click();
};
window.addEventListener('keydown', (e) => {
  if (e.target.tagName === 'INPUT') return;
  if ((e.ctrlKey || e.metaKey) && e.key === 'z') { e.preventDefault(); $('undo').click(); return; }
  if ((e.ctrlKey || e.metaKey) && e.key === 'y') { e.preventDefault(); $('redo').click(); return; }
  if (e.key === 'Delete' && app.selected.id) { send(`delete_${app.selected.kind}`, { id: app.selected.id }).catch(() => {}); return; }
  const tools = { o: 'orbit', s: 'stroke', m: 'magnitude', c: 'cut' };
  if (tools[e.key]) setTool(tools[e.key]);
  if (e.key === 'r') viewer.resetView();
});

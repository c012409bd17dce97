// onestroke studio: the page. Plain JS, no build step; every computation is the server's
// (the library's), the page only draws, keeps the edits history and sends edits back.
"use strict";
import { $, busy, call, report } from "./api.js";
import { fieldNames, refreshPanel, setupPanels } from "./panels.js";

const PAIRINGS = ["crossing", "touching", "third"];
const COLORS = { crossing: "#1565c0", touching: "#ef6c00", third: "#8e24aa", other: "#757575", start: "#2e7d32",
                 passes: "#00838f", retrace: "rgba(255, 179, 0, 0.55)", gap: "#c2185b" };
// The three passes through a triple point, each in its own colour inside the marker.
const PASS_COLORS = ["#d81b60", "#43a047", "#1e88e5", "#6d4c41"];

const studio = {
  state: null,            // last answer of /api/state
  history: [],            // edits states (plain objects), for undo/redo
  at: -1,                 // index of the current state in history
  view: { scale: 1, x: 0, y: 0 },
  pen: 1,                 // play position, fraction of the total length
  playing: false,
  tool: "pairing",
  image: new Image(),
  requests: 0,            // answers to ignore when a newer request was sent
  shown: null,            // the edits of the state shown (what the panels and downloads use)
  rerunning: 0,           // pending requests that re-run from binarization
  holding: null,          // the slider the pointer holds ("threshold", "blur")
  // This page's id: the server skips a queued state request once the page sent a newer one.
  page: Math.random().toString(36).slice(2) + Date.now().toString(36),
};
window.studio = studio;

// ---------------------------------------------------------------- edits and history
function currentEdits() { return studio.history[studio.at]; }
const SETTINGS = ["threshold", "blur", "multi"];
// Only the answer to the latest request is shown: a slow re-run answered after a newer
// edit (or while a slider moves on) is dropped, so the page never shows a stale state.
async function apply(edits, push = true) {
  if (push) {
    studio.history = studio.history.slice(0, studio.at + 1);
    studio.history.push(edits);
    studio.at = studio.history.length - 1;
  }
  updateButtons();
  const ticket = ++studio.requests;
  const shown = studio.state ? studio.state.edits : null;
  const rerun = !shown || SETTINGS.some((k) => edits[k] !== shown[k]);
  busy(true);
  if (rerun) rerunning(1);
  const started = performance.now();
  try {
    const state = await call("api/state", { edits, page: studio.page });
    state.answered = (performance.now() - started) / 1000;
    if (ticket === studio.requests && !state.superseded) { studio.shown = edits; show(state); }
  } catch (error) {
    // A refused edits state (e.g. an opened file that is not an edits file) is no step.
    if (push && studio.history[studio.at] === edits) { studio.history.pop(); studio.at -= 1; updateButtons(); }
    if (ticket === studio.requests) report(error);
  } finally {
    busy(false);
    if (rerun) rerunning(-1);
  }
}

// The visible busy state of a re-run from binarization (threshold, blur, mode: ~0.5-1 s).
function rerunning(step) {
  studio.rerunning += step;
  $("rerun").hidden = studio.rerunning <= 0;
  $("tab-refine").classList.toggle("rerunning", studio.rerunning > 0);
}

function withEdit(edit, replaceNear) {
  const edits = JSON.parse(JSON.stringify(currentEdits()));
  if (replaceNear) {
    // One pairing per junction: a new choice replaces the old one instead of piling up.
    edits.edits = edits.edits.filter((e) => !(e.kind === edit.kind && dist(e.at, edit.at) <= edits.tolerance));
  }
  edits.edits.push(edit);
  return edits;
}

function undo() { if (studio.at > 0) { studio.at -= 1; apply(currentEdits(), false); } }
function redo() { if (studio.at < studio.history.length - 1) { studio.at += 1; apply(currentEdits(), false); } }

function updateButtons() {
  $("undo").disabled = studio.at <= 0;
  $("redo").disabled = studio.at >= studio.history.length - 1;
}

// ---------------------------------------------------------------- geometry helpers
function dist(a, b) { return Math.hypot(a[0] - b[0], a[1] - b[1]); }
function toScreen(x, y) { const v = studio.view; return [x * v.scale + v.x, y * v.scale + v.y]; }
function toImage(sx, sy) { const v = studio.view; return [(sx - v.x) / v.scale, (sy - v.y) / v.scale]; }
studio.toScreen = (x, y) => {
  const r = $("canvas").getBoundingClientRect();
  const [sx, sy] = toScreen(x, y);
  return [r.left + sx, r.top + sy];
};

// Fit the view to the drawing: the ink and the curve with a margin for the markers'
// labels (a small drawing on a large sheet fills the view), else the whole image.
function fit() {
  const s = studio.state, c = $("canvas");
  if (!s) return;
  const w = c.clientWidth, h = c.clientHeight;
  let box = [0, 0, s.width, s.height];
  const points = s.strokes.flatMap((k) => k.points).concat(s.graph.junctions.map((j) => j.at));
  if (points.length) {
    const ink = studio.ink || [Infinity, Infinity, -Infinity, -Infinity];
    box = [Math.min(ink[0], ...points.map((p) => p[0])), Math.min(ink[1], ...points.map((p) => p[1])),
           Math.max(ink[2], ...points.map((p) => p[0])), Math.max(ink[3], ...points.map((p) => p[1]))];
    const pad = Math.max(20, 0.06 * Math.max(box[2] - box[0], box[3] - box[1]));
    box = [box[0] - pad, box[1] - pad, box[2] + pad, box[3] + pad];
  }
  const bw = Math.max(1, box[2] - box[0]), bh = Math.max(1, box[3] - box[1]);
  const scale = Math.min(w / bw, h / bh);
  studio.view = { scale, x: (w - bw * scale) / 2 - box[0] * scale, y: (h - bh * scale) / 2 - box[1] * scale };
}

// The ink's bounding box in image px (dark or opaque pixels of the input, read once from a
// reduced copy), so that fitting also shows ink the line leaves out (pieces dropped).
function inkBox(image) {
  const k = Math.min(1, 600 / Math.max(image.naturalWidth, image.naturalHeight));
  const cw = Math.max(1, Math.round(image.naturalWidth * k)), ch = Math.max(1, Math.round(image.naturalHeight * k));
  const c = document.createElement("canvas");
  c.width = cw; c.height = ch;
  const g = c.getContext("2d", { willReadFrequently: true });
  g.fillStyle = "#fff"; g.fillRect(0, 0, cw, ch); g.drawImage(image, 0, 0, cw, ch);
  const d = g.getImageData(0, 0, cw, ch).data;
  let x0 = Infinity, y0 = Infinity, x1 = -Infinity, y1 = -Infinity;
  for (let y = 0; y < ch; y++) for (let x = 0; x < cw; x++) {
    const i = 4 * (y * cw + x);
    if (d[i] + d[i + 1] + d[i + 2] < 3 * 128) { x0 = Math.min(x0, x); x1 = Math.max(x1, x); y0 = Math.min(y0, y); y1 = Math.max(y1, y); }
  }
  if (x0 === Infinity) return null;
  const sx = (studio.state ? studio.state.width : image.naturalWidth) / cw;
  const sy = (studio.state ? studio.state.height : image.naturalHeight) / ch;
  return [x0 * sx, y0 * sy, (x1 + 1) * sx, (y1 + 1) * sy];
}

// Points of all strokes in drawing order with cumulative length, for colour and the pen.
function timeline() {
  const s = studio.state;
  const pts = [], cum = [];
  let total = 0;
  for (const stroke of s.strokes) {
    stroke.points.forEach((p, i) => {
      if (pts.length && i > 0) total += dist(pts[pts.length - 1], p);
      pts.push(p); cum.push(total);
      p.first = i === 0;
    });
  }
  return { pts, cum, total };
}

function hue(f) { return `hsl(${Math.round(240 - 240 * f)}, 85%, 45%)`; }

// ---------------------------------------------------------------- drawing view
function draw() {
  const c = $("canvas"), s = studio.state;
  const dpr = window.devicePixelRatio || 1;
  if (c.width !== Math.round(c.clientWidth * dpr) || c.height !== Math.round(c.clientHeight * dpr)) {
    c.width = Math.round(c.clientWidth * dpr); c.height = Math.round(c.clientHeight * dpr);
  }
  const g = c.getContext("2d");
  g.setTransform(dpr, 0, 0, dpr, 0, 0);
  studio.labels = [];  // the markers' texts, drawn after every marker
  g.clearRect(0, 0, c.clientWidth, c.clientHeight);
  if (!s) return;
  const v = studio.view;
  g.save();
  g.translate(v.x, v.y); g.scale(v.scale, v.scale);
  if (studio.image.complete && studio.image.naturalWidth) {
    g.globalAlpha = 0.3;
    g.drawImage(studio.image, 0, 0, s.width, s.height);
    g.globalAlpha = 1;
  }
  g.restore();
  retraces(g);
  const t = studio.line;
  const penAt = studio.pen * t.total;
  const width = Math.max(2, Math.min(6, s.stroke_width * v.scale * 0.45));
  g.lineCap = "round"; g.lineWidth = width;
  for (let i = 1; i < t.pts.length; i++) {
    if (t.pts[i].first) continue;
    const drawn = t.cum[i] <= penAt + 1e-9;
    g.strokeStyle = drawn ? hue(t.total ? t.cum[i] / t.total : 0) : "rgba(0,0,0,0.12)";
    const a = toScreen(...t.pts[i - 1]), b = toScreen(...t.pts[i]);
    g.beginPath(); g.moveTo(a[0], a[1]); g.lineTo(b[0], b[1]); g.stroke();
  }
  arrows(g, t);
  junctionMarkers(g);
  bridges(g);
  const starts = startPlaces();
  placeLabels(g, starts.map(([x, y]) => [x - 8, y - 8, 16, 16]));
  startMarkers(g, starts);
  if (studio.pen < 1 || studio.playing) penMarker(g, t, penAt);
  else $("where").textContent = `${Math.round(t.total)} px, ${s.strokes.length} stroke${s.strokes.length === 1 ? "" : "s"}`;
}

// Start markers: where each stroke begins. One that would hide a junction's marker (a line
// starting at a junction) sits just beyond it along its stroke.
function startPlaces() {
  const s = studio.state;
  const markers = s.graph.junctions.map((j) => ({ at: toScreen(...j.at), r: j.role === "triple" ? 24 : 11 }));
  return s.strokes.map((stroke) => {
    const start = toScreen(...stroke.points[0]);
    const under = markers.find((m) => Math.hypot(m.at[0] - start[0], m.at[1] - start[1]) < m.r + 6);
    if (!under) return start;
    return stroke.points.map((p) => toScreen(...p))
      .find(([px, py]) => Math.hypot(px - under.at[0], py - under.at[1]) > under.r + 9) || start;
  });
}

function startMarkers(g, starts) {
  starts.forEach(([x, y], k) => {
    g.fillStyle = COLORS.start; g.beginPath(); g.arc(x, y, k === 0 ? 7 : 5, 0, 2 * Math.PI); g.fill();
    g.fillStyle = "#fff"; g.font = "bold 9px sans-serif"; g.textAlign = "center"; g.textBaseline = "middle";
    g.fillText(String(k + 1), x, y + 0.5);
  });
}

function arrows(g, t) {
  const step = 90 / studio.view.scale;  // one arrow every ~90 screen px
  let next = step / 2;
  g.fillStyle = "rgba(20,20,20,0.75)";
  for (let i = 1; i < t.pts.length; i++) {
    if (t.pts[i].first || t.cum[i] < next) continue;
    next = t.cum[i] + step;
    const a = toScreen(...t.pts[i - 1]), b = toScreen(...t.pts[i]);
    const ang = Math.atan2(b[1] - a[1], b[0] - a[0]);
    g.save(); g.translate(b[0], b[1]); g.rotate(ang);
    g.beginPath(); g.moveTo(6, 0); g.lineTo(-4, -4.5); g.lineTo(-4, 4.5); g.closePath(); g.fill();
    g.restore();
  }
}

// Stretches the line draws twice (a stem down and back up, a path route inspection repeats):
// a wide amber band under the curve, "×2" at its middle.
function retraces(g) {
  const s = studio.state;
  g.save();
  g.lineCap = "round"; g.lineJoin = "round";
  g.lineWidth = Math.max(8, s.stroke_width * studio.view.scale * 1.6);
  g.strokeStyle = COLORS.retrace;
  for (const r of s.graph.retraces || []) {
    g.beginPath();
    r.points.forEach((p, i) => { const [x, y] = toScreen(...p); if (i) g.lineTo(x, y); else g.moveTo(x, y); });
    g.stroke();
  }
  g.fillStyle = "#6d4c00"; g.font = "bold 11px sans-serif"; g.textAlign = "center"; g.textBaseline = "middle";
  for (const r of s.graph.retraces || []) { const [x, y] = toScreen(...r.at); g.fillText("×2", x + 12, y - 12); }
  g.restore();
}

// Pen gaps the vectorizer bridged: the two ends joined, dashed, under the curve; gaps the
// user kept open (an "unbridge" edit): a grey circle struck through.
function bridges(g) {
  g.save();
  const ring = ([a, b]) => {
    const [ax, ay] = toScreen(...a), [bx, by] = toScreen(...b);
    return [(ax + bx) / 2, (ay + by) / 2, Math.max(9, Math.hypot(bx - ax, by - ay) / 2 + 5)];
  };
  for (const gap of studio.state.graph.bridges || []) {
    const [x, y, r] = ring(gap);
    g.strokeStyle = COLORS.gap; g.lineWidth = studio.tool === "gap" ? 3 : 2; g.setLineDash([4, 3]);
    g.beginPath(); g.arc(x, y, r, 0, 2 * Math.PI); g.stroke();
    g.setLineDash([]);
    label(g, "gap", x, y, r + 3);
  }
  for (const gap of studio.state.graph.unbridged || []) {
    const [x, y, r] = ring(gap);
    g.strokeStyle = COLORS.other; g.lineWidth = 2;
    g.beginPath(); g.arc(x, y, r, 0, 2 * Math.PI);
    g.moveTo(x - r * 0.7, y + r * 0.7); g.lineTo(x + r * 0.7, y - r * 0.7); g.stroke();
    label(g, "gap open", x, y, r + 3);
  }
  g.restore();
}

function middle([a, b]) { return { at: [(a[0] + b[0]) / 2, (a[1] + b[1]) / 2], ends: [a, b] }; }

// Distance from point p to the segment a-b (image px).
function toSegment(p, [a, b]) {
  const dx = b[0] - a[0], dy = b[1] - a[1], n = dx * dx + dy * dy;
  const t = n ? Math.max(0, Math.min(1, ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / n)) : 0;
  return dist(p, [a[0] + t * dx, a[1] + t * dy]);
}

function percent(p) { return p === null || p === undefined ? "" : p < 0.001 ? " <0.1%" : ` ${Math.round(100 * p)}%`; }

// The passes of a triple point in a circle of radius r at (x, y): each pass joins its two
// branch directions through the centre in its own colour, on a white halo; stub: px it
// runs on beyond the circle along the real branches, so that each branch shows its pass.
function drawPasses(g, x, y, r, passes, stub = 0) {
  const at = (deg, d) => [x + d * Math.cos((deg * Math.PI) / 180), y + d * Math.sin((deg * Math.PI) / 180)];
  const path = ([a, b]) => {
    g.beginPath(); g.moveTo(...at(a, r + stub)); g.lineTo(...at(a, r));
    const [qx, qy] = at(b, r);
    g.quadraticCurveTo(x, y, qx, qy); g.lineTo(...at(b, r + stub));
  };
  g.save();
  g.lineCap = "round"; g.lineJoin = "round";
  passes.forEach((pass, k) => {
    g.strokeStyle = "rgba(255,255,255,0.95)"; g.lineWidth = Math.max(4, r / 3.5); path(pass); g.stroke();
    g.strokeStyle = PASS_COLORS[k % PASS_COLORS.length]; g.lineWidth = Math.max(2, r / 7); path(pass); g.stroke();
  });
  g.restore();
}

// The place of the pairing drawn among the ones offered (likeliest first), 1-based.
function passRank(j) { return j.options.findIndex((o) => samePasses(o.passes, j.passes)) + 1; }

// A triple point: its three passes drawn through the marker and along each branch, so the
// pairing is seen, not read; a square when you chose it.
function tripleMarker(g, j) {
  const [x, y] = toScreen(...j.at), r = 20;
  g.lineWidth = 3; g.strokeStyle = COLORS.passes; g.fillStyle = "rgba(255,255,255,0.92)";
  g.beginPath();
  if (j.fixed) g.rect(x - r - 2, y - r - 2, 2 * r + 4, 2 * r + 4); else g.arc(x, y, r + 2, 0, 2 * Math.PI);
  g.fill(); g.stroke();
  drawPasses(g, x, y, r - 2, j.passes, 12);
  const scorer = j.confidence === null ? " (straightest)" : percent(j.confidence);
  label(g, `3 passes: pairing ${passRank(j)}/${j.options.length}${scorer}${j.fixed ? " · yours" : ""}`, x, y, r + 12);
}

// A marker's text, beside the marker at (x, y) of radius `gap`; drawn by `placeLabels`
// once every marker is drawn.
function label(g, text, x, y, gap) { studio.labels.push({ text, x, y, gap }); }

// Each text on a white box so that it reads over the curve, right of its marker, else
// left, below or above, wherever it stays on the canvas and covers no marker (nor `more`
// boxes: [x, y, w, h]) and no text placed before (junctions a few px apart would print
// over each other).
function placeLabels(g, more = []) {
  g.font = "11px sans-serif"; g.textAlign = "left"; g.textBaseline = "middle";
  const boxes = studio.labels.map(({ x, y, gap }) => [x - gap, y - gap, 2 * gap, 2 * gap]).concat(more);
  const h = 13, c = $("canvas");
  const placed = [];
  studio.placed = [];  // the texts drawn and their boxes (screen px)
  for (const { text, x, y, gap } of studio.labels) {
    // Two nodes a pixel or two apart (a split crossing) would print the same text twice.
    if (placed.some((q) => q.text === text && Math.hypot(q.x - x, q.y - y) < 12)) continue;
    placed.push({ text, x, y });
    const w = g.measureText(text).width;
    const spots = [[x + gap, y], [x - gap - w, y], [x - w / 2, y + gap + h / 2], [x - w / 2, y - gap - h / 2]];
    const covers = (sx, sy, b) => sx < b[0] + b[2] && b[0] < sx + w && sy - h / 2 < b[1] + b[3] && b[1] < sy + h / 2;
    const inside = (sx, sy) => sx >= 2 && sx + w <= c.clientWidth - 2 && sy - h / 2 >= 0 && sy + h / 2 <= c.clientHeight;
    const [lx, ly] = spots.find(([sx, sy]) => inside(sx, sy) && !boxes.some((b) => covers(sx, sy, b))) ||
      spots.find(([sx, sy]) => inside(sx, sy)) || spots[0];
    boxes.push([lx, ly - h / 2, w, h]);
    studio.placed.push({ text, box: [lx, ly - h / 2, w, h] });
    g.fillStyle = "rgba(255,255,255,0.8)"; g.fillRect(lx - 2, ly - h / 2, w + 4, h);
    g.strokeStyle = "rgba(255,255,255,0.9)"; g.lineWidth = 3; g.lineJoin = "round"; g.strokeText(text, lx, ly);
    g.fillStyle = "#222"; g.fillText(text, lx, ly);
  }
}

function samePasses(a, b) { return JSON.stringify(a) === JSON.stringify(b); }

// Marker radii on screen, per junction role (a triple point's is drawn by tripleMarker).
const MARKER_R = { triple: 22, crossing: 10, unresolved: 9 };

// Where each junction's marker is drawn, in screen px: on its junction, except where
// markers would cover each other (the two halves of a split crossing a pixel apart, a Y
// beside a crossing): such a group is fanned out around its middle, each marker tied to
// its junction by a thin line, so that each one reads and takes its own click.
function markerPlaces() {
  const ms = studio.state.graph.junctions.map((j) => {
    const at = toScreen(...j.at);
    return { j, at, x: at[0], y: at[1], r: MARKER_R[j.role] || 6 };
  });
  const group = ms.map((_, i) => i);
  const root = (i) => (group[i] === i ? i : (group[i] = root(group[i])));
  ms.forEach((a, i) => ms.forEach((b, k) => {
    if (k > i && a.j.role !== "triple" && b.j.role !== "triple" &&
        Math.hypot(a.x - b.x, a.y - b.y) < a.r + b.r + 2) group[root(i)] = root(k);
  }));
  const groups = new Map();
  ms.forEach((m, i) => { const k = root(i); groups.set(k, (groups.get(k) || []).concat([m])); });
  for (const members of groups.values()) {
    const n = members.length;
    if (n < 2) continue;
    const cx = members.reduce((t, m) => t + m.at[0], 0) / n, cy = members.reduce((t, m) => t + m.at[1], 0) / n;
    const spread = Math.max(...members.map((m) => m.r)) + 2;
    const radius = spread / Math.sin(Math.PI / n);
    // Around the middle in the order they lie (coinciding ones by id), turned so that the
    // first keeps its own side.
    const angle = (m) => Math.atan2(m.at[1] - cy, m.at[0] - cx);
    members.sort((a, b) => angle(a) - angle(b) || a.j.id - b.j.id);
    const first = Math.hypot(members[0].at[0] - cx, members[0].at[1] - cy) > 0.5 ? angle(members[0]) : Math.PI;
    members.forEach((m, k) => {
      const a = first + (2 * Math.PI * k) / n;
      m.x = cx + radius * Math.cos(a); m.y = cy + radius * Math.sin(a); m.moved = true;
    });
  }
  return ms;
}

// The marker under screen point (sx, sy) among these roles, or null.
function markerHit(sx, sy, roles) {
  let best = null, bestD = Infinity;
  for (const m of studio.markers || []) {
    const d = Math.hypot(m.x - sx, m.y - sy);
    if (roles.includes(m.j.role) && d <= Math.max(18, m.r + 4) && d < bestD) { best = m.j; bestD = d; }
  }
  return best;
}
studio.markerAt = (id) => {
  const m = (studio.markers || []).find((q) => q.j.id === id);
  const r = $("canvas").getBoundingClientRect();
  return m ? [r.left + m.x, r.top + m.y] : null;
};

function junctionMarkers(g) {
  const graph = studio.state.graph;
  if (studio.tool === "start") {
    for (const at of graph.ends || []) {
      const [x, y] = toScreen(...at);
      g.strokeStyle = COLORS.start; g.lineWidth = 2; g.setLineDash([3, 2]);
      g.beginPath(); g.arc(x, y, 9, 0, 2 * Math.PI); g.stroke(); g.setLineDash([]);
    }
  }
  if (studio.tool === "merge") {
    for (const b of graph.branches) {
      const [x, y] = toScreen(...b.at);
      g.fillStyle = "#00897b"; g.beginPath();
      g.moveTo(x, y - 7); g.lineTo(x + 7, y); g.lineTo(x, y + 7); g.lineTo(x - 7, y); g.closePath(); g.fill();
    }
  }
  studio.markers = markerPlaces();
  for (const m of studio.markers) {
    if (!m.moved) continue;
    // A marker moved off its junction: a thin line from the junction (a dot) to it.
    g.strokeStyle = "rgba(60,60,60,0.8)"; g.fillStyle = "rgba(60,60,60,0.9)"; g.lineWidth = 1.5;
    g.beginPath(); g.moveTo(m.at[0], m.at[1]); g.lineTo(m.x, m.y); g.stroke();
    g.beginPath(); g.arc(m.at[0], m.at[1], 2.5, 0, 2 * Math.PI); g.fill();
  }
  for (const { j, x, y } of studio.markers) {
    if (j.role === "triple") { tripleMarker(g, j); continue; }
    if (j.role !== "crossing") {
      // An unresolved junction (the warning's "three or more strokes seem to meet") is
      // named where it is: the order there is the walk's guess. A click says what to do.
      const open = j.role === "unresolved";
      g.strokeStyle = open ? COLORS.gap : COLORS.other; g.lineWidth = 2; g.fillStyle = "rgba(255,255,255,0.85)";
      g.beginPath(); g.arc(x, y, open ? 7 : 5, 0, 2 * Math.PI); g.fill(); g.stroke();
      if (open) {
        g.fillStyle = COLORS.gap; g.font = "bold 10px sans-serif"; g.textAlign = "center"; g.textBaseline = "middle";
        g.fillText("?", x, y + 0.5);
        label(g, "unresolved", x, y, 10);
      }
      continue;
    }
    const color = COLORS[j.decision] || COLORS.other;
    g.lineWidth = 3; g.strokeStyle = color; g.fillStyle = "rgba(255,255,255,0.85)";
    g.beginPath();
    if (j.fixed) g.rect(x - 9, y - 9, 18, 18); else g.arc(x, y, 9, 0, 2 * Math.PI);
    g.fill(); g.stroke();
    // Confidence as the filled share of an inner disc.
    g.fillStyle = color; g.beginPath(); g.moveTo(x, y);
    g.arc(x, y, 6, -Math.PI / 2, -Math.PI / 2 + 2 * Math.PI * (j.confidence || 0)); g.closePath(); g.fill();
    label(g, `${j.decision} ${Math.round(100 * (j.confidence || 0))}%`, x, y, 12);
  }
}

// What an unresolved junction offers: merge it with the degree-3 node its shortest branch
// leads to (one crossing again), and drop a split made there. Buttons, for the hint shown
// on a click and the junction list.
function unresolvedFixes(j) {
  const s = studio.state, buttons = [];
  const branch = s.graph.branches.filter((b) => (b.nodes || []).includes(j.id)).sort((a, b) => a.length - b.length)[0];
  if (branch) {
    const other = s.graph.junctions.find((o) => o.id === branch.nodes.find((n) => n !== j.id));
    const button = document.createElement("button");
    button.className = "merge-here";
    button.textContent = other ? `merge with (${other.at[0].toFixed(0)}, ${other.at[1].toFixed(0)}): one crossing`
      : "merge by its shortest branch";
    button.title = `collapse the ${branch.length.toFixed(0)} px branch between them into a degree-4 crossing`;
    button.onclick = () => { hint(""); apply(withEdit({ kind: "merge", at: branch.at }, false)); };
    buttons.push(button);
  }
  const tol = currentEdits().tolerance;
  const splits = currentEdits().edits.filter((e) => e.kind === "split" && dist(e.at, j.at) <= tol);
  if (splits.length) {
    const button = document.createElement("button");
    button.className = "unsplit";
    button.textContent = "undo the split here";
    button.onclick = () => {
      hint("");
      const edits = JSON.parse(JSON.stringify(currentEdits()));
      edits.edits = edits.edits.filter((e) => !(e.kind === "split" && dist(e.at, j.at) <= edits.tolerance));
      apply(edits);
    };
    buttons.push(button);
  }
  return buttons;
}

function describeUnresolved(j) {
  return `(${j.at[0].toFixed(0)}, ${j.at[1].toFixed(0)}) unresolved: ${j.degree} branches meet and none ` +
    "is read as going on through it, so the line's order here is a guess";
}

// The pen's place through an edit: a paused (or playing) pen stays on the spot of the
// drawing where it was, i.e. at the new curve's point nearest to it; where the new curve
// passes that spot more than once (a crossing, a stretch drawn twice), on the pass whose
// share of the length is nearest to the pen's old share. The part before it is then what
// the new order draws before that spot. A pen at the end (nothing paused) stays there.
function keepPen(before, after) {
  if (!before || !after.pts.length || (studio.pen >= 1 && !studio.playing)) return;
  const share = studio.pen;
  const spot = before.pts[penIndex(before, share * before.total)];
  const d = after.pts.map((q) => dist(q, spot));
  const near = Math.min(...d) + PEN_SLACK;
  // Each pass of the new curve by the spot: a run of points within `near`; on it, the
  // point nearest the spot.
  const passes = [];
  after.pts.forEach((q, i) => {
    if (d[i] > near) return;
    const last = passes[passes.length - 1];
    if (last && last.end === i - 1 && !q.first) { last.end = i; if (d[i] < d[last.at]) last.at = i; }
    else passes.push({ at: i, end: i });
  });
  const shareOf = (i) => (after.total ? after.cum[i] / after.total : 0);
  const pass = passes.reduce((a, b) => (Math.abs(shareOf(b.at) - share) < Math.abs(shareOf(a.at) - share) ? b : a));
  studio.pen = shareOf(pass.at);
  $("scrub").value = Math.round(studio.pen * 1000);
}
// px: a pass of the new curve this much farther from the spot than the nearest one still
// goes through it (the curve is sampled every 2 px: CURVE_SPACING in session.py).
const PEN_SLACK = 2.5;
studio.penPoint = () => studio.line.pts[penIndex(studio.line, studio.pen * studio.line.total)].slice(0, 2);

function penIndex(t, penAt) {
  const i = t.cum.findIndex((c) => c >= penAt - 1e-9);
  return i < 0 ? t.pts.length - 1 : i;
}

function penMarker(g, t, penAt) {
  const [x, y] = toScreen(...t.pts[penIndex(t, penAt)]);
  g.fillStyle = "#d50000"; g.strokeStyle = "#fff"; g.lineWidth = 2;
  g.beginPath(); g.arc(x, y, 7, 0, 2 * Math.PI); g.fill(); g.stroke();
  $("where").textContent = `${Math.round(penAt)} / ${Math.round(t.total)} px`;
}

// ---------------------------------------------------------------- showing a state
function show(state) {
  const first = !studio.state;
  const before = studio.line;
  studio.state = state;
  studio.line = timeline();
  if (first) fit();
  else keepPen(before, studio.line);
  $("name").textContent = state.name;
  const r = state.report;
  $("summary").textContent = `${r.strokes} stroke${r.strokes === 1 ? "" : "s"}, ${r.intersections} crossing` +
    `${r.intersections === 1 ? "" : "s"}, ${state.edits.edits.length} edit${state.edits.edits.length === 1 ? "" : "s"}` +
    ` · ${(state.answered ?? r.seconds).toFixed(2)} s`;
  $("summary").dataset.order = JSON.stringify(state.strokes.map((s) => s.points[0]));
  const list = $("junctions"); list.innerHTML = "";
  for (const j of state.graph.junctions.filter((j) => j.role === "crossing" || j.role === "triple")) {
    const li = document.createElement("li");
    const where = `(${j.at[0].toFixed(0)}, ${j.at[1].toFixed(0)})`;
    li.style.color = COLORS[j.decision];
    if (j.role === "triple") {
      const offered = state.settings.multi ? `all ${j.options.length} pairings`
        : `the ${j.options.length} pairings that keep one line`;
      li.append(`${where} three passes: pairing ${passRank(j)} · ` +
        `${j.confidence === null ? "straightest" : "pass scorer" + percent(j.confidence)}` +
        `${j.fixed ? " · fixed by you" : ""} · ${offered}, likeliest first:`);
      li.appendChild(passChoice(j));
    } else {
      li.textContent = `${where} ${j.decision} · CNN p(cross) ${(j.p_crossing * 100).toFixed(0)}%` +
        (j.fixed ? " · fixed by you" : "");
    }
    list.appendChild(li);
  }
  for (const j of state.graph.junctions.filter((j) => j.role === "unresolved")) {
    const li = document.createElement("li");
    li.className = "unresolved";
    li.append(describeUnresolved(j), ...unresolvedFixes(j));
    list.appendChild(li);
  }
  const gaps = state.graph.bridges || [];
  if (gaps.length) {
    const li = document.createElement("li");
    li.className = "gaps";
    li.textContent = `pen gap${gaps.length === 1 ? "" : "s"} bridged: ${gaps.length} (dashed circle${gaps.length === 1 ? "" : "s"})`;
    list.appendChild(li);
  }
  const open = state.graph.unbridged || [];
  if (open.length) {
    const li = document.createElement("li");
    li.className = "open-gaps";
    li.textContent = `pen gap${open.length === 1 ? "" : "s"} kept open by you: ${open.length} (struck-through circle${open.length === 1 ? "" : "s"})`;
    list.appendChild(li);
  }
  if (r.dropped && !state.settings.multi) {
    // What single-line mode does with ink in several pieces (as the CLI does): the largest
    // piece is the line; the others stay grey, undrawn.
    const li = document.createElement("li");
    li.className = "pieces";
    li.append(`the ink is in ${r.dropped + 1} pieces: one line keeps the largest, the grey rest is not drawn. `);
    const keep = document.createElement("button");
    keep.id = "keep-pieces"; keep.textContent = "Keep every piece (multi-stroke)";
    keep.title = "Multi-stroke mode draws each piece as its own stroke (and bridges no pen gap)";
    keep.onclick = () => settingsEdit({ multi: true });
    li.appendChild(keep);
    list.appendChild(li);
  }
  const twice = state.graph.retraces || [];
  if (twice.length) {
    const li = document.createElement("li");
    li.className = "retraces";
    li.textContent = `drawn twice (×2): ${twice.length} stretch${twice.length === 1 ? "" : "es"}, ` +
      `${Math.round(twice.reduce((sum, r) => sum + r.length, 0))} px`;
    list.appendChild(li);
  }
  const warnings = $("warnings"); warnings.innerHTML = "";
  for (const w of r.warnings) {
    const li = document.createElement("li"); li.textContent = fieldNames(w, null); warnings.appendChild(li);
  }
  // The controls show the state's settings, except a slider the user holds: writing its
  // value mid-drag would move the thumb away from the pointer.
  const st = state.settings;
  if (studio.holding !== "threshold") {
    // Automatic: the slider rests on the level Li's method chose, so a drag (or unticking
    // "automatic") starts from the threshold in use.
    const used = st.threshold === null ? r.threshold : st.threshold;
    $("auto-threshold").checked = st.threshold === null;
    if (used !== null && used !== undefined) $("threshold").value = used;
    $("threshold-value").textContent = st.threshold !== null ? Number(st.threshold).toFixed(2)
      : used === null || used === undefined ? "auto" : `auto ${Number(used).toFixed(2)}`;
  }
  if (studio.holding !== "blur") { $("blur").value = st.blur; $("blur-value").textContent = st.blur; }
  $("multi").checked = st.multi;
  draw();
  refreshPanel();
}

// The pairings a triple point may take, likeliest first (single-line mode: those that keep
// the line one stroke; multi-stroke: all 15), each a small drawing of its passes with its
// place and the pass scorer's posterior; the one drawn is outlined. A click picks one.
function passChoice(j) {
  const box = document.createElement("div");
  box.className = "pass-options";
  const dpr = window.devicePixelRatio || 1;
  j.options.forEach((o, k) => {
    const button = document.createElement("button");
    button.type = "button"; button.dataset.index = String(k);
    button.className = "pass-option" + (samePasses(o.passes, j.passes) ? " current" : "");
    button.title = `pairing ${k + 1}${percent(o.p)}: passes ` +
      o.passes.map(([a, b]) => `${Math.round(a)}°–${Math.round(b)}°`).join(", ");
    const c = document.createElement("canvas");
    c.width = c.height = Math.round(34 * dpr); c.style.width = c.style.height = "34px";
    const g = c.getContext("2d"); g.scale(dpr, dpr);
    drawPasses(g, 17, 17, 13, o.passes, 2);
    const caption = document.createElement("span");
    caption.textContent = `${k + 1}${percent(o.p)}`;
    button.append(c, caption);
    button.onclick = () => choosePasses(j, o);
    box.appendChild(button);
  });
  return box;
}

function choosePasses(j, option) {
  return apply(withEdit({ kind: "passes", at: j.at, passes: option.passes }, true));
}

// ---------------------------------------------------------------- clicks on the drawing
function nearest(items, point, radius) {
  let best = null, bestD = radius / studio.view.scale;
  for (const item of items) {
    const d = dist(item.at, point);
    if (d <= bestD) { best = item; bestD = d; }
  }
  return best;
}

// What a click that finds nothing to act on says, per tool.
const MISSED = {
  pairing: () => "no crossing or triple point here: click on a junction's marker",
  split: () => "no crossing or triple point here: click on a junction's marker",
  merge: () => studio.state.graph.branches.length ? "no branch handle (◆) here: click on one"
    : "no branch joins two degree-3 nodes in this reading: nothing to merge",
  start: () => "no free end here: click on a stroke's end or a ring (◌)",
  retrace: () => "no line here: click on the line",
  reverse: () => "no stroke here: click on a stroke",
  gap: () => (studio.state.graph.bridges || []).length + (studio.state.graph.unbridged || []).length
    ? "no pen gap here: click on a dashed circle to open it, a struck-through one to close it"
    : "no pen gap was bridged in this drawing (single-line mode bridges them; multi-stroke none)",
};

function hint(text, buttons = []) {
  $("hint").textContent = text || "";
  for (const b of buttons) $("hint").append(" ", b);
  $("hint").hidden = !text;
}

function onClick(event) {
  const s = studio.state;
  if (!s || studio.dragged) return;
  const r = $("canvas").getBoundingClientRect();
  const sx = event.clientX - r.left, sy = event.clientY - r.top;
  const p = toImage(sx, sy);
  const done = clickTool(s, p, sx, sy);
  if (done !== "hint") hint(done ? "" : MISSED[studio.tool]());
}

// The edit a click at image point p (screen point sx, sy) makes with the current tool (its
// request), "hint" when it only explains, or nothing.
function clickTool(s, p, sx, sy) {
  const tool = studio.tool;
  if (tool === "pairing" || tool === "split" || tool === "merge") {
    const open = markerHit(sx, sy, ["unresolved"]);
    const fixes = open ? unresolvedFixes(open) : [];
    if (open && tool === "merge" && fixes.length && fixes[0].className === "merge-here") return fixes[0].onclick() || true;
    if (open && !markerHit(sx, sy, ["crossing", "triple"])) { hint(describeUnresolved(open) + ".", fixes); return "hint"; }
  }
  if (tool === "pairing" || tool === "split") {
    const j = markerHit(sx, sy, ["crossing", "triple"]);
    if (!j) return;
    if (tool === "split") {
      // A pairing chosen at this junction has nothing left to act on once it is split.
      const edits = withEdit({ kind: "split", at: j.at }, false);
      edits.edits = edits.edits.filter((e) => !((e.kind === "pairing" || e.kind === "passes") &&
                                              dist(e.at, j.at) <= edits.tolerance));
      return apply(edits);
    }
    if (j.role === "triple") {
      // The next of the pairings that keep one stroke, in the order of their likelihood.
      if (!j.options.length) return null;
      const k = j.options.findIndex((o) => samePasses(o.passes, j.passes));
      return choosePasses(j, j.options[(k + 1) % j.options.length]);
    }
    const next = PAIRINGS[(PAIRINGS.indexOf(j.decision) + 1) % 3];
    return apply(withEdit({ kind: "pairing", at: j.at, pairing: next }, true));
  }
  if (tool === "merge") {
    const b = nearest(s.graph.branches, p, 16);
    return b ? apply(withEdit({ kind: "merge", at: b.at }, false)) : null;
  }
  if (tool === "start") {
    // A stroke's end, or a free end the line passes (the tip of a stem drawn down and back
    // up): starting there, the line retraces other branches instead.
    const ends = (s.graph.ends || []).map((at) => ({ at }));
    for (const stroke of s.strokes) if (!stroke.closed) {
      ends.push({ at: stroke.points[0] }, { at: stroke.points[stroke.points.length - 1] });
    }
    const e = nearest(ends, p, 24);
    return e ? apply(withEdit({ kind: "start", at: e.at.slice(0, 2) }, false)) : null;
  }
  if (tool === "retrace") {
    // On a stretch drawn twice: draw it once; elsewhere on the line: go back over it here
    // (route inspection then retraces this branch rather than another).
    const twice = (s.graph.retraces || []).flatMap((r) => r.points.map((q) => ({ at: q })));
    const onBand = nearest(twice, p, 14);
    const q = onBand || nearest(studio.line.pts.map((q) => ({ at: q })), p, 16);
    if (!q) return;
    const edit = { kind: onBand ? "once" : "twice", at: q.at.slice(0, 2) };
    const edits = JSON.parse(JSON.stringify(currentEdits()));
    edits.edits = edits.edits.filter((e) => !((e.kind === "twice" || e.kind === "once") &&
                                              dist(e.at, edit.at) <= edits.tolerance));
    edits.edits.push(edit);
    return apply(edits);
  }
  if (tool === "gap") {
    // A gap kept open: close it again (drop the edits that opened it); a bridged gap: open it.
    const open = nearest((s.graph.unbridged || []).map(middle), p, 24);
    if (open) {
      const edits = JSON.parse(JSON.stringify(currentEdits()));
      edits.edits = edits.edits.filter((e) => !(e.kind === "unbridge" && toSegment(e.at, open.ends) <= edits.tolerance));
      return apply(edits);
    }
    const gap = nearest((s.graph.bridges || []).map(middle), p, 24);
    return gap ? apply(withEdit({ kind: "unbridge", at: gap.at }, false)) : null;
  }
  if (tool === "reverse") {
    const points = studio.line.pts.map((q) => ({ at: q }));
    const q = nearest(points, p, 16);
    return q ? apply(withEdit({ kind: "reverse", at: q.at.slice(0, 2) }, false)) : null;
  }
}

function setupView() {
  const c = $("canvas");
  let drag = null;
  c.addEventListener("mousedown", (e) => { drag = { x: e.clientX, y: e.clientY, vx: studio.view.x, vy: studio.view.y }; studio.dragged = false; });
  window.addEventListener("mousemove", (e) => {
    if (!drag) return;
    const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
    if (Math.abs(dx) + Math.abs(dy) > 4) studio.dragged = true;
    if (studio.dragged) { studio.view.x = drag.vx + dx; studio.view.y = drag.vy + dy; studio.moved = true; draw(); }
  });
  window.addEventListener("mouseup", () => { drag = null; });
  c.addEventListener("click", onClick);
  c.addEventListener("dblclick", () => { studio.moved = false; fit(); draw(); });
  c.addEventListener("wheel", (e) => {
    e.preventDefault();
    const r = c.getBoundingClientRect();
    const sx = e.clientX - r.left, sy = e.clientY - r.top;
    const [ix, iy] = toImage(sx, sy);
    const factor = Math.exp(-e.deltaY * 0.0015);
    studio.view.scale = Math.min(50, Math.max(0.05, studio.view.scale * factor));
    studio.moved = true;
    studio.view.x = sx - ix * studio.view.scale; studio.view.y = sy - iy * studio.view.scale;
    draw();
  }, { passive: false });
  window.addEventListener("resize", () => { fit(); draw(); });
}

// ---------------------------------------------------------------- play
let lastFrame = 0;
function frame(now) {
  if (!studio.playing) return;
  const dt = lastFrame ? (now - lastFrame) / 1000 : 0;
  lastFrame = now;
  const seconds = Math.min(12, Math.max(4, studio.line.total / 400));  // whole curve in 4-12 s
  studio.pen = Math.min(1, studio.pen + dt / seconds);
  $("scrub").value = Math.round(studio.pen * 1000);
  draw();
  if (studio.pen >= 1) { studio.playing = false; $("play").textContent = "▶ Play"; return; }
  requestAnimationFrame(frame);
}

function play() {
  if (studio.playing) { studio.playing = false; $("play").textContent = "▶ Play"; return; }
  if (studio.pen >= 1) studio.pen = 0;
  studio.playing = true; lastFrame = 0; $("play").textContent = "▮▮ Pause";
  requestAnimationFrame(frame);
}

// ---------------------------------------------------------------- wiring
function settingsEdit(change) {
  clearTimeout(previewTimer);
  const edits = JSON.parse(JSON.stringify(currentEdits()));
  Object.assign(edits, change);
  apply(edits);
}

// While a slider is dragged, the value it rests on is vectorized already (not yet a step
// in the history): on release the answer comes from the cache. Moving it drops the
// answers still on their way (they are for values the slider has left).
let previewTimer = null;
function preview(change) {
  studio.requests += 1;
  clearTimeout(previewTimer);
  previewTimer = setTimeout(() => apply(Object.assign(JSON.parse(JSON.stringify(currentEdits())), change), false), 350);
}

function setup() {
  setupView();
  $("undo").onclick = undo; $("redo").onclick = redo;
  document.addEventListener("keydown", (e) => {
    if (!(e.ctrlKey || e.metaKey) || e.target.tagName === "INPUT") return;
    if (e.key === "z" && !e.shiftKey) { e.preventDefault(); undo(); }
    if (e.key === "y" || (e.key === "z" && e.shiftKey)) { e.preventDefault(); redo(); }
  });
  for (const radio of document.querySelectorAll("input[name=tool]")) {
    radio.onchange = () => { studio.tool = radio.value; hint(""); draw(); };
  }
  $("reverse-all").onclick = () => {
    const s = studio.state; if (!s || !s.strokes.length) return;
    const pts = s.strokes[0].points;
    apply(withEdit({ kind: "reverse", at: pts[Math.floor(pts.length / 2)].slice(0, 2) }, false));
  };
  for (const id of ["threshold", "blur"]) $(id).addEventListener("pointerdown", () => { studio.holding = id; });
  window.addEventListener("pointerup", () => { studio.holding = null; });
  $("threshold").oninput = () => {
    $("auto-threshold").checked = false;
    $("threshold-value").textContent = Number($("threshold").value).toFixed(2);
    preview({ threshold: Number($("threshold").value) });
  };
  $("threshold").onchange = () => settingsEdit({ threshold: Number($("threshold").value) });
  $("auto-threshold").onchange = () => settingsEdit({ threshold: $("auto-threshold").checked ? null : Number($("threshold").value) });
  $("blur").oninput = () => { $("blur-value").textContent = $("blur").value; preview({ blur: Number($("blur").value) }); };
  $("blur").onchange = () => settingsEdit({ blur: Number($("blur").value) });
  $("multi").onchange = () => settingsEdit({ multi: $("multi").checked });
  $("play").onclick = play;
  $("scrub").oninput = () => { studio.playing = false; $("play").textContent = "▶ Play"; studio.pen = $("scrub").value / 1000; draw(); };
  setupPanels(() => studio.shown);
  $("save").onclick = async () => {
    try { const r = await call("api/edits", { edits: currentEdits() }); $("summary").textContent += ` · saved ${r.saved}`; }
    catch (error) { report(error); }
  };
  $("load").onclick = async () => {
    try { const r = await call("api/edits"); apply(r.edits); } catch (error) { report(error); }
  };
  $("open").onchange = async () => {
    const file = $("open").files[0]; if (!file) return;
    let data;
    try { data = JSON.parse(await file.text()); }
    catch (error) { report(new Error(`${file.name} is not an edits file (not JSON)`)); }
    if (data !== undefined) apply(data);
    $("open").value = "";
  };
  // The first view fits the ink too: the first state is drawn once the image is read.
  const loaded = new Promise((done) => {
    studio.image.onload = () => {
      try { studio.ink = inkBox(studio.image); } catch (error) { studio.ink = null; }
      done(); draw();
    };
    studio.image.onerror = done;
  });
  studio.image.src = "api/image";
  (async () => {
    busy(true);
    try {
      const [state] = await Promise.all([call("api/state"), loaded]);
      studio.history = [state.edits]; studio.at = 0; studio.shown = state.edits; updateButtons();
      show(state);
    } catch (error) { report(error); } finally { busy(false); }
  })();
}

setup();

// onestroke studio: the page's wiring, the drawing view (fit, draw, pan and zoom), the pen
// (play, scrub, its place kept through an edit) and the Refine panel's lists of a state. Plain
// JS, no build step; every computation is the server's (the library's). The edits and their
// history: edits.js; clicks per tool: tools.js; the marks on the curve: marks.js.
"use strict";
import { $, busy, call, report } from "./api.js";
import { apply, redo, SETTINGS, setupEdits, undo, updateButtons, withEdit, withSettings } from "./edits.js";
import { hint } from "./hint.js";
import { setupJunctions, showJunctions } from "./junctions.js";
import { arrows, bridges, junctionMarkers, placeLabels, retraces, selectionRing, startMarkers,
         startPlaces } from "./marks.js";
import { fieldNames, refreshPanel, setupPanels } from "./panels.js";
import { onClick } from "./tools.js";
import { dist, studio, toImage, toScreen } from "./view.js";

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
  studio.fitScale = scale;
}

// A place chosen in the junction list: ringed and, with `zoom`, brought into view at least
// 2.5 times the fitted scale (a junction's branches then read), centred.
function select(place, zoom = true) {
  studio.selected = place;
  if (!zoom) { draw(); return; }
  const c = $("canvas"), v = studio.view;
  v.scale = Math.max(v.scale, Math.min(50, 2.5 * (studio.fitScale || v.scale)));
  v.x = c.clientWidth / 2 - place.at[0] * v.scale; v.y = c.clientHeight / 2 - place.at[1] * v.scale;
  studio.moved = true;
  draw();
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
  // The drawing shows through more as the curve fades: at 0 the ink is seen alone.
  const curve = studio.curveOpacity;
  if (studio.image.complete && studio.image.naturalWidth) {
    g.globalAlpha = 0.3 + 0.7 * (1 - curve);
    g.drawImage(studio.image, 0, 0, s.width, s.height);
  }
  // While a threshold or blur slider moves: the pixels that value makes ink, under the curve.
  if (studio.mask && maskWanted()) {
    g.globalAlpha = 0.6;
    g.drawImage(studio.mask.canvas, 0, 0, s.width, s.height);
  }
  g.globalAlpha = 1;
  g.restore();
  // The curve half faded over a mask, so that the mask's edges read beside it.
  g.globalAlpha = curve * (studio.mask && maskWanted() ? 0.5 : 1);
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
  g.globalAlpha = 1;
  junctionMarkers(g);
  bridges(g);
  const starts = studio.starts = startPlaces();  // screen px, for the tests too
  selectionRing(g);  // under the texts: a text beside a ringed marker stays readable
  placeLabels(g, starts.map(([x, y]) => [x - 8, y - 8, 16, 16]));
  startMarkers(g, starts);
  if (studio.pen < 1 || studio.playing) penMarker(g, t, penAt);
  else $("where").textContent = `${Math.round(t.total)} px, ${s.strokes.length} stroke${s.strokes.length === 1 ? "" : "s"}`;
}



// A threshold or blur that leaves little of the ink (the line shrinks to a stub, the
// drawing vanishes from the view) says so, beside the longest line this page has shown
// (a slider moved step by step shrinks the line a little at each answer); a later answer
// from other settings takes it back.
function sayShrunk(old) {
  const s = studio.state, now = studio.line.total;
  const setting = (st, r) => `${st.threshold === null ? `the automatic threshold ${Number(r.threshold).toFixed(2)}`
    : `threshold ${Number(st.threshold).toFixed(2)}`} and blur ${st.blur} px`;
  const moved = old && SETTINGS.some((k) => old.edits[k] !== s.edits[k]);
  const most = studio.longest;
  if (moved && most && now < SHRUNK * most.total) {
    hint(`at ${setting(s.settings, s.report)} the line is ${Math.round(now)} px long (${Math.round(most.total)} px at ` +
      `${most.setting}): most of the ink is lighter than the threshold (blur lightens thin lines); raise the ` +
      "threshold, lower the blur or tick \"automatic threshold\"");
    studio.shrunk = true;
  } else if (studio.shrunk && moved) { hint(""); studio.shrunk = false; }
  if (!most || now > most.total) studio.longest = { total: now, setting: setting(s.settings, s.report) };
}
const SHRUNK = 0.25;  // a line under a quarter of the longest shown is a stub

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
  const before = studio.line, old = studio.state;
  studio.state = state;
  studio.line = timeline();
  if (first) fit();
  else keepPen(before, studio.line);
  sayShrunk(old);
  $("name").textContent = state.name;
  const r = state.report;
  // Crossings are the junctions read as crossings; touchings and third pairings are not.
  const read = (kind) => state.graph.junctions.filter((j) => j.role === "crossing" && j.decision === kind).length;
  const crossings = read("crossing"), others = read("touching") + read("third");
  $("summary").textContent = `${r.strokes} stroke${r.strokes === 1 ? "" : "s"}, ${crossings} crossing` +
    `${crossings === 1 ? "" : "s"}${others ? `, ${others} touching${others === 1 ? "" : "s"}` : ""}, ` +
    `${state.edits.edits.length} edit${state.edits.edits.length === 1 ? "" : "s"}` +
    // The time this page waited for the answer (the first state comes from the command's run).
    (state.answered === undefined ? "" : ` · ${state.answered.toFixed(2)} s`);
  $("summary").dataset.order = JSON.stringify(state.strokes.map((s) => s.points[0]));
  showJunctions(state, () => settingsEdit({ multi: true }));
  const warnings = $("warnings"); warnings.innerHTML = "";
  for (const w of r.warnings) {
    const li = document.createElement("li"); li.textContent = fieldNames(w, null); warnings.appendChild(li);
  }
  showSettings(state);
  if (studio.mask && !maskWanted()) studio.mask = null;  // the answer for the slider's value came
  draw();
  refreshPanel();
}

// The controls show the state's settings, except a slider the user holds: writing its value
// mid-drag would move the thumb away from the pointer. Also after a refused setting: the
// controls go back to what the drawing shows.
function showSettings(state) {
  const st = state.settings, r = state.report;
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
}

// A refused setting (a threshold that finds no ink): the controls and the view go back to
// the state shown.
function refused() {
  if (!studio.state) return;
  studio.mask = null;
  showSettings(studio.state);
  draw();
}

// ---------------------------------------------------------------- the threshold's mask
// While a threshold or blur slider moves: the pixels its value makes ink (the library's
// binarization, GET /api/mask), tinted, under the curve; only the latest value's answer is
// drawn, and the mask goes once the state for that value is shown.
const MASK_COLOR = "#00897b";
let maskTicket = 0, maskTimer = null;
function askMask() { clearTimeout(maskTimer); maskTimer = setTimeout(requestMask, 60); }
async function requestMask() {
  const ticket = ++maskTicket;
  const threshold = $("auto-threshold").checked ? null : Number($("threshold").value);
  const blur = Number($("blur").value);
  try {
    const response = await call(`api/mask?threshold=${threshold === null ? "auto" : threshold}&blur=${blur}`, undefined, true);
    const bitmap = await createImageBitmap(await response.blob());
    if (ticket !== maskTicket) return;
    const canvas = document.createElement("canvas");
    canvas.width = bitmap.width; canvas.height = bitmap.height;
    const g = canvas.getContext("2d");
    g.drawImage(bitmap, 0, 0);
    g.globalCompositeOperation = "source-in"; g.fillStyle = MASK_COLOR; g.fillRect(0, 0, canvas.width, canvas.height);
    studio.mask = { canvas, for: { threshold, blur } };
    draw();
  } catch (error) { /* a refused value: the state request says why */ }
}
function maskWanted() {
  const m = studio.mask, st = studio.state && studio.state.settings;
  return !!m && (studio.holding !== null || !st || m.for.threshold !== st.threshold || m.for.blur !== st.blur);
}

// The canvas by keyboard: arrows pan, + and - zoom, 0 fits, Enter acts with the tool chosen
// at the place selected in the junction list, Escape drops the selection.
function canvasKeys(e) {
  const c = $("canvas"), v = studio.view, step = 40;
  const zoom = (f) => {
    const cx = c.clientWidth / 2, cy = c.clientHeight / 2, [ix, iy] = toImage(cx, cy);
    v.scale = Math.min(50, Math.max(0.05, v.scale * f)); v.x = cx - ix * v.scale; v.y = cy - iy * v.scale;
  };
  const pan = { ArrowLeft: [step, 0], ArrowRight: [-step, 0], ArrowUp: [0, step], ArrowDown: [0, -step] }[e.key];
  if (pan) { v.x += pan[0]; v.y += pan[1]; studio.moved = true; }
  else if (e.key === "+" || e.key === "=") { zoom(1.25); studio.moved = true; }
  else if (e.key === "-") { zoom(0.8); studio.moved = true; }
  else if (e.key === "0") { studio.moved = false; fit(); }
  else if (e.key === "Escape") studio.selected = null;
  else if (e.key === "Enter" && studio.selected) {
    const r = c.getBoundingClientRect(), [sx, sy] = toScreen(...studio.selected.at);
    onClick({ clientX: r.left + sx, clientY: r.top + sy });
  } else return;
  e.preventDefault();
  draw();
}

function setupView() {
  const c = $("canvas");
  c.addEventListener("keydown", canvasKeys);
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
  // A resized window fits the drawing again, unless the user zoomed or panned: then the
  // point at the middle of the view stays there.
  let size = [$("canvas").clientWidth, $("canvas").clientHeight];
  window.addEventListener("resize", () => {
    const now = [$("canvas").clientWidth, $("canvas").clientHeight];
    if (!studio.moved) fit();
    else { studio.view.x += (now[0] - size[0]) / 2; studio.view.y += (now[1] - size[1]) / 2; }
    size = now; draw();
  });
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
  apply(withSettings(change));
}

// While a slider is dragged, the value it rests on is vectorized already (not yet a step
// in the history): on release the answer comes from the cache. Moving it drops the
// answers still on their way (they are for values the slider has left).
let previewTimer = null;
function preview(change) {
  studio.requests += 1;
  clearTimeout(previewTimer);
  previewTimer = setTimeout(() => apply(withSettings(change), false), 350);
}

function setup() {
  setupView();
  document.addEventListener("keydown", (e) => {
    // Space plays and pauses the pen (as in the player), unless a control has the key.
    if (e.key === " " && !e.ctrlKey && !["INPUT", "BUTTON", "SELECT", "TEXTAREA", "LABEL"].includes(e.target.tagName) &&
        !$("tab-refine").hidden) { e.preventDefault(); play(); return; }
    // Ctrl+Z / Ctrl+Y step through the edits wherever the focus is, but in a text field (its
    // own typing is what Ctrl+Z undoes there).
    const typing = e.target.matches("textarea, input:not([type=range]):not([type=checkbox]):not([type=radio])" +
      ":not([type=file]):not([type=color]):not([type=button])");
    if (!(e.ctrlKey || e.metaKey) || typing) return;
    if (e.key === "z" && !e.shiftKey) { e.preventDefault(); undo(); }
    if (e.key === "y" || (e.key === "z" && e.shiftKey)) { e.preventDefault(); redo(); }
  });
  for (const radio of document.querySelectorAll("input[name=tool]")) {
    radio.onchange = () => { studio.tool = radio.value; hint(""); draw(); };
  }
  $("reverse-all").onclick = () => {
    const s = studio.state; if (!s || !s.strokes.length) return;
    const pts = s.strokes[0].points;
    apply(withEdit({ kind: "reverse", at: pts[Math.floor(pts.length / 2)].slice(0, 2) }));
  };
  for (const id of ["threshold", "blur"]) $(id).addEventListener("pointerdown", () => { studio.holding = id; });
  window.addEventListener("pointerup", () => { studio.holding = null; if (studio.mask) draw(); });
  $("threshold").oninput = () => {
    $("auto-threshold").checked = false;
    $("threshold-value").textContent = Number($("threshold").value).toFixed(2);
    askMask();
    preview({ threshold: Number($("threshold").value) });
  };
  $("threshold").onchange = () => settingsEdit({ threshold: Number($("threshold").value) });
  $("auto-threshold").onchange = () => settingsEdit({ threshold: $("auto-threshold").checked ? null : Number($("threshold").value) });
  $("blur").oninput = () => {
    $("blur-value").textContent = $("blur").value;
    askMask();
    preview({ blur: Number($("blur").value) });
  };
  $("curve-opacity").oninput = () => {
    studio.curveOpacity = Number($("curve-opacity").value);
    $("curve-opacity-value").textContent = studio.curveOpacity ? `${Math.round(100 * studio.curveOpacity)}%` : "ink only";
    draw();
  };
  $("blur").onchange = () => settingsEdit({ blur: Number($("blur").value) });
  $("multi").onchange = () => settingsEdit({ multi: $("multi").checked });
  $("play").onclick = play;
  $("scrub").oninput = () => { studio.playing = false; $("play").textContent = "▶ Play"; studio.pen = $("scrub").value / 1000; draw(); };
  setupPanels(() => studio.shown);
  setupEdits(show, refused);
  setupJunctions(select);
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

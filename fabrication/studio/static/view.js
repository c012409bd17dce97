// onestroke studio: the page's shared state (the `studio` object, also window.studio for the
// tests), its colours and the view's geometry (image px <-> canvas px).
"use strict";
import { $ } from "./api.js";

export const COLORS = { crossing: "#1565c0", touching: "#ef6c00", third: "#8e24aa", other: "#757575", start: "#2e7d32",
                 passes: "#00838f", retrace: "rgba(255, 179, 0, 0.55)", gap: "#c2185b" };
// The three passes through a triple point, each in its own colour inside the marker.
export const PASS_COLORS = ["#d81b60", "#43a047", "#1e88e5", "#6d4c41"];

export const studio = {
  state: null,            // last answer of /api/state
  history: [],            // edits states (plain objects), for undo/redo
  at: -1,                 // index of the current state in history
  view: { scale: 1, x: 0, y: 0 },
  pen: 1,                 // play position, fraction of the total length
  playing: false,
  tool: "pairing",
  tab: "refine",          // the panel in view ("refine", "embroidery", "laser")
  image: new Image(),
  requests: 0,            // answers to ignore when a newer request was sent
  shown: null,            // the edits of the state shown (what the panels and downloads use)
  rerunning: 0,           // pending requests that re-run from binarization
  holding: null,          // the slider the pointer holds ("threshold", "blur")
  selected: null,         // the place chosen in the junction list ({at, key}), ringed on the drawing
  curveOpacity: 1,        // 0: the ink alone (the curve, its arrows and bands hidden)
  mask: null,             // the threshold's mask under the curve while a slider moves ({canvas, for})
  // This page's id: the server skips a queued state request once the page sent a newer one.
  page: Math.random().toString(36).slice(2) + Date.now().toString(36),
};
window.studio = studio;

export function dist(a, b) { return Math.hypot(a[0] - b[0], a[1] - b[1]); }
export function toScreen(x, y) { const v = studio.view; return [x * v.scale + v.x, y * v.scale + v.y]; }
export function toImage(sx, sy) { const v = studio.view; return [(sx - v.x) / v.scale, (sy - v.y) / v.scale]; }
studio.toScreen = (x, y) => {
  const r = $("canvas").getBoundingClientRect();
  const [sx, sy] = toScreen(x, y);
  return [r.left + sx, r.top + sy];
};

// A crossing's decision as the page says it ("crossing 100%"); one the user forced says
// what the classifier said too: "touching (yours; CNN: crossing 100%)".
export function decisionText(j) {
  const share = `${Math.round(100 * (j.confidence || 0))}%`;
  if (!j.fixed) return `${j.decision} ${share}`;
  const by = studio.state && studio.state.classifier === "geometric" ? "geometric rule" : "CNN";
  return `${j.decision} (yours; ${by}: ${j.p_crossing >= 0.5 ? "crossing" : "touching"} ${share})`;
}

// Stretches drawn twice that the page bands and counts: a retrace shorter than the ink is
// wide stays inside the ink of a junction (a split crossing's two halves), seen as nothing.
export function shownRetraces() {
  const s = studio.state;
  return (s.graph.retraces || []).filter((r) => r.length >= s.stroke_width);
}

export function percent(p) { return p === null || p === undefined ? "" : p < 0.001 ? " <0.1%" : ` ${Math.round(100 * p)}%`; }

// The place of the pairing drawn among the ones offered (likeliest first), 1-based.
export function passRank(j) { return j.options.findIndex((o) => samePasses(o.passes, j.passes)) + 1; }

export function samePasses(a, b) { return JSON.stringify(a) === JSON.stringify(b); }

// onestroke studio: the marks drawn over the curve on the drawing view (start markers,
// direction arrows, stretches drawn twice, pen gaps, junction markers fanned out where they
// would cover each other, triple points' passes) and their texts, placed clear of each other.
"use strict";
import { $ } from "./api.js";
import { COLORS, PASS_COLORS, decisionText, passRank, percent, shownRetraces, studio, toScreen } from "./view.js";

// Start markers: where each stroke begins. One that would hide a junction's marker (a line
// starting at a junction) sits just beyond the markers along its stroke: beyond the marker
// as drawn (fanned out beside its junction, `markerPlaces`) and the junction's dot.
export function startPlaces() {
  const s = studio.state;
  const markers = (studio.markers || []).flatMap((m) => {
    const r = m.j.role === "triple" ? 24 : 11;
    return m.moved ? [{ at: [m.x, m.y], r }, { at: m.at, r: 4 }] : [{ at: m.at, r }];
  });
  const clear = ([px, py], extra) => markers.every((m) => Math.hypot(m.at[0] - px, m.at[1] - py) >= m.r + extra);
  return s.strokes.map((stroke) => {
    const start = toScreen(...stroke.points[0]);
    if (clear(start, 6)) return start;
    return stroke.points.map((p) => toScreen(...p)).find((p) => clear(p, 9)) || start;
  });
}

export function startMarkers(g, starts) {
  starts.forEach(([x, y], k) => {
    g.fillStyle = COLORS.start; g.beginPath(); g.arc(x, y, k === 0 ? 7 : 5, 0, 2 * Math.PI); g.fill();
    g.fillStyle = "#fff"; g.font = "bold 9px sans-serif"; g.textAlign = "center"; g.textBaseline = "middle";
    g.fillText(String(k + 1), x, y + 0.5);
  });
}

export function arrows(g, t) {
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
// a wide amber band under the curve, "×2" beside its middle.
export function retraces(g) {
  const s = studio.state;
  g.save();
  g.lineCap = "round"; g.lineJoin = "round";
  g.lineWidth = Math.max(8, s.stroke_width * studio.view.scale * 1.6);
  g.strokeStyle = COLORS.retrace;
  const twice = shownRetraces();
  for (const r of twice) {
    g.beginPath();
    r.points.forEach((p, i) => { const [x, y] = toScreen(...p); if (i) g.lineTo(x, y); else g.moveTo(x, y); });
    g.stroke();
  }
  g.restore();
  // "×2" beside the band's middle, placed like the markers' texts: clear of them and of each other.
  for (const r of twice) { const [x, y] = toScreen(...r.at); label(g, "×2", x, y, 7); }
}

// Pen gaps the vectorizer bridged: the two ends joined, dashed, under the curve; gaps the
// user kept open (an "unbridge" edit): a grey circle struck through.
export function bridges(g) {
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

// The passes of a triple point in a circle of radius r at (x, y): each pass joins its two
// branch directions through the centre in its own colour, on a white halo; stub: px it
// runs on beyond the circle along the real branches, so that each branch shows its pass.
export function drawPasses(g, x, y, r, passes, stub = 0) {
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

// Screen cells (CURVE_CELL px square, keys "col,row") the drawn curve runs through: a text
// whose box touches one would hide the line where it matters (a triple point's branches).
const CURVE_CELL = 6;
const LABEL_SPACE = 6;  // px between two texts' boxes
function curveCells(width, height) {
  const cells = new Set(), t = studio.line;
  const mark = (x, y) => { if (x >= 0 && y >= 0 && x <= width && y <= height) cells.add(`${Math.floor(x / CURVE_CELL)},${Math.floor(y / CURVE_CELL)}`); };
  let a = null;
  for (const p of t ? t.pts : []) {
    const b = toScreen(p[0], p[1]);
    if (a && !p.first && Math.max(a[0], b[0]) >= 0 && Math.min(a[0], b[0]) <= width &&
        Math.max(a[1], b[1]) >= 0 && Math.min(a[1], b[1]) <= height) {
      const n = Math.ceil(Math.hypot(b[0] - a[0], b[1] - a[1]) / (CURVE_CELL / 2));
      for (let k = 1; k <= n; k++) mark(a[0] + ((b[0] - a[0]) * k) / n, a[1] + ((b[1] - a[1]) * k) / n);
    } else mark(b[0], b[1]);
    a = b;
  }
  return cells;
}

// Each text on a white box so that it reads over the curve, right of its marker, else
// left, below or above, wherever it stays on the canvas and covers no marker (nor `more`
// boxes: [x, y, w, h]) and no text placed before (junctions a few px apart would print over
// each other), and hides none of the curve, or the least of it where the curve is all around.
export function placeLabels(g, more = []) {
  g.font = "11px sans-serif"; g.textAlign = "left"; g.textBaseline = "middle";
  const markers = studio.labels.map(({ x, y, gap }) => [x - gap, y - gap, 2 * gap, 2 * gap]).concat(more);
  const h = 13, c = $("canvas");
  const curve = studio.labels.length ? curveCells(c.clientWidth, c.clientHeight) : null;
  studio.placed = [];  // the texts drawn: their markers' places and their boxes (screen px)
  for (const { text, x, y, gap } of studio.labels) {
    // Two nodes a pixel or two apart (a split crossing) would print the same text twice.
    if (studio.placed.some((q) => q.text === text && Math.hypot(q.x - x, q.y - y) < 12)) continue;
    const w = g.measureText(text).width;
    // Right, left, below, above; then the corners; then the same farther out (a crowd of
    // markers: the halves of a split crossing with a "×2" between them).
    const around = (d) => [[x + d, y], [x - d - w, y], [x - w / 2, y + d + h / 2], [x - w / 2, y - d - h / 2],
      [x + d * 0.7, y - d * 0.7 - h / 2], [x + d * 0.7, y + d * 0.7 + h / 2],
      [x - d * 0.7 - w, y - d * 0.7 - h / 2], [x - d * 0.7 - w, y + d * 0.7 + h / 2]];
    const spots = around(gap).concat(around(gap + 14), around(gap + 28));
    const covers = (sx, sy, b, pad = 0) => sx < b[0] + b[2] + pad && b[0] - pad < sx + w &&
      sy - h / 2 < b[1] + b[3] + pad && b[1] - pad < sy + h / 2;
    const inside = (sx, sy) => sx >= 2 && sx + w <= c.clientWidth - 2 && sy - h / 2 >= 0 && sy + h / 2 <= c.clientHeight;
    // Texts keep LABEL_SPACE px apart: two boxes side by side would read as one ("unresolved×2").
    const free = (sx, sy) => !markers.some((b) => covers(sx, sy, b)) &&
      !studio.placed.some((q) => covers(sx, sy, q.box, LABEL_SPACE));
    // How much of the curve a box there would hide: the curve's cells under the white box
    // (2 px wider than the text) and 2 px around it (the line is up to 6 px wide).
    const hidden = (sx, sy) => {
      let n = 0;
      for (let i = Math.floor((sx - 4) / CURVE_CELL); i <= Math.floor((sx + w + 4) / CURVE_CELL); i++) {
        for (let j = Math.floor((sy - h / 2 - 2) / CURVE_CELL); j <= Math.floor((sy + h / 2 + 2) / CURVE_CELL); j++) {
          if (curve.has(`${i},${j}`)) n += 1;
        }
      }
      return n;
    };
    // Among the places on the canvas clear of markers and texts, the first that hides none
    // of the curve, else the one that hides least (crossing a line, not lying along it).
    const clear = spots.filter(([sx, sy]) => inside(sx, sy) && free(sx, sy));
    let best = null, least = Infinity;
    for (const spot of clear) {
      const n = hidden(...spot);
      if (n < least) { best = spot; least = n; }
      if (!n) break;
    }
    const [lx, ly] = best || spots.find(([sx, sy]) => inside(sx, sy)) || spots[0];
    // A text pushed beyond the first ring around its marker (a crowd) is tied to it by a
    // line, so that it reads as its own marker's, not a neighbour's.
    const box = [lx, ly - h / 2, w, h];
    const near = [Math.max(box[0], Math.min(x, box[0] + w)), Math.max(box[1], Math.min(y, box[1] + h))];
    const leader = Math.hypot(near[0] - x, near[1] - y) > gap + 16;
    if (leader) {
      g.strokeStyle = "rgba(60,60,60,0.7)"; g.lineWidth = 1; g.setLineDash([2, 2]);
      g.beginPath(); g.moveTo(x, y); g.lineTo(...near); g.stroke(); g.setLineDash([]);
    }
    studio.placed.push({ text, x, y, box, leader });
    g.fillStyle = "rgba(255,255,255,0.8)"; g.fillRect(lx - 2, ly - h / 2, w + 4, h);
    g.strokeStyle = "rgba(255,255,255,0.9)"; g.lineWidth = 3; g.lineJoin = "round"; g.strokeText(text, lx, ly);
    g.fillStyle = "#222"; g.fillText(text, lx, ly);
  }
}

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
export function markerHit(sx, sy, roles) {
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

export function junctionMarkers(g) {
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
    label(g, decisionText(j), x, y, 12);
  }
}

// The place chosen in the junction list: a ring the eye finds at once.
export function selectionRing(g) {
  if (!studio.selected) return;
  const [x, y] = toScreen(...studio.selected.at);
  g.save();
  g.strokeStyle = "#ffd600"; g.lineWidth = 6; g.beginPath(); g.arc(x, y, 24, 0, 2 * Math.PI); g.stroke();
  g.strokeStyle = "#111"; g.lineWidth = 2; g.beginPath(); g.arc(x, y, 24, 0, 2 * Math.PI); g.stroke();
  g.restore();
}


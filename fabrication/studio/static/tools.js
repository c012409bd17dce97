// onestroke studio: clicks on the drawing, per tool (pairing, split, merge, start, retrace,
// reverse, gap): the edit a click makes, or a hint when it finds nothing to act on, and what
// an unresolved junction offers (merge it, undo a split there).
"use strict";
import { $ } from "./api.js";
import { apply, currentEdits, isNear, without, withEdit } from "./edits.js";
import { hint } from "./hint.js";
import { markerHit } from "./marks.js";
import { dist, samePasses, studio, toImage } from "./view.js";

const PAIRINGS = ["crossing", "touching", "third"];

function middle([a, b]) { return { at: [(a[0] + b[0]) / 2, (a[1] + b[1]) / 2], ends: [a, b] }; }

// Distance from point p to the segment a-b (image px).
function toSegment(p, [a, b]) {
  const dx = b[0] - a[0], dy = b[1] - a[1], n = dx * dx + dy * dy;
  const t = n ? Math.max(0, Math.min(1, ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / n)) : 0;
  return dist(p, [a[0] + t * dx, a[1] + t * dy]);
}

// The branch a merge at unresolved junction j collapses: its shortest, to the degree-3 node
// it leads to (the two are one crossing again), or undefined.
function shortestBranch(j) {
  return studio.state.graph.branches.filter((b) => (b.nodes || []).includes(j.id))
    .sort((a, b) => a.length - b.length)[0];
}

// Merge unresolved junction j by its shortest branch (its button and the merge tool's click
// on it); null when no branch leads from it.
function mergeBranch(j) {
  const branch = shortestBranch(j);
  if (!branch) return null;
  hint("");
  return apply(withEdit({ kind: "merge", at: branch.at }));
}

// What an unresolved junction offers: merge it with the degree-3 node its shortest branch
// leads to (one crossing again), and drop a split made there. Buttons, for the hint shown
// on a click and the junction list.
export function unresolvedFixes(j) {
  const s = studio.state, buttons = [];
  const branch = shortestBranch(j);
  if (branch) {
    const other = s.graph.junctions.find((o) => o.id === branch.nodes.find((n) => n !== j.id));
    const button = document.createElement("button");
    button.className = "merge-here";
    button.textContent = other ? `merge with (${other.at[0].toFixed(0)}, ${other.at[1].toFixed(0)}): one crossing`
      : "merge by its shortest branch";
    button.title = `collapse the ${branch.length.toFixed(0)} px branch between them into a degree-4 crossing`;
    button.onclick = () => mergeBranch(j);
    buttons.push(button);
  }
  const edits = currentEdits();
  if (edits.edits.some((e) => isNear(e, edits, ["split"], j.at))) {
    const button = document.createElement("button");
    button.className = "unsplit";
    button.textContent = "undo the split here";
    button.onclick = () => { hint(""); apply(without(currentEdits(), ["split"], j.at)); };
    buttons.push(button);
  }
  return buttons;
}

export function describeUnresolved(j) {
  return `(${j.at[0].toFixed(0)}, ${j.at[1].toFixed(0)}) unresolved: ${j.degree} branches meet and none ` +
    "is read as going on through it, so the line's order here is a guess";
}

// The ends the line may start from: the strokes' ends and the free ends it passes (the
// tip of a stem drawn down and back up), image px, each place once.
export function lineEnds(state) {
  const found = (state.graph.ends || []).map((at) => at.slice(0, 2));
  for (const stroke of state.strokes) if (!stroke.closed) {
    found.push(stroke.points[0].slice(0, 2), stroke.points[stroke.points.length - 1].slice(0, 2));
  }
  return found.filter((at, k) => found.findIndex((o) => dist(o, at) < 3) === k);
}

// Close a pen gap kept open (`ends`: its two sides): drop the edits that opened it.
export function closeGap(ends) { return apply(without(currentEdits(), ["unbridge"], ends, toSegment)); }

export function choosePasses(j, option) {
  return apply(withEdit({ kind: "passes", at: j.at, passes: option.passes }, ["passes"]));
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

export function onClick(event) {
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
    const merged = open && tool === "merge" ? mergeBranch(open) : null;
    if (merged) return merged;
    if (open && !markerHit(sx, sy, ["crossing", "triple"])) {
      hint(describeUnresolved(open) + ".", unresolvedFixes(open));
      return "hint";
    }
  }
  if (tool === "pairing" || tool === "split") {
    const j = markerHit(sx, sy, ["crossing", "triple"]);
    if (!j) return;
    if (tool === "split") {
      // A pairing chosen at this junction has nothing left to act on once it is split.
      return apply(withEdit({ kind: "split", at: j.at }, ["pairing", "passes"]));
    }
    if (j.role === "triple") {
      // The next of the pairings that keep one stroke, in the order of their likelihood.
      if (!j.options.length) return null;
      const k = j.options.findIndex((o) => samePasses(o.passes, j.passes));
      return choosePasses(j, j.options[(k + 1) % j.options.length]);
    }
    const next = PAIRINGS[(PAIRINGS.indexOf(j.decision) + 1) % 3];
    return apply(withEdit({ kind: "pairing", at: j.at, pairing: next }, ["pairing"]));
  }
  if (tool === "merge") {
    const b = nearest(s.graph.branches, p, 16);
    return b ? apply(withEdit({ kind: "merge", at: b.at })) : null;
  }
  if (tool === "start") {
    // A stroke's end, or a free end the line passes (the tip of a stem drawn down and back
    // up): starting there, the line retraces other branches instead.
    const e = nearest(lineEnds(s).map((at) => ({ at })), p, 24);
    return e ? apply(withEdit({ kind: "start", at: e.at }, ["start"])) : null;
  }
  if (tool === "retrace") {
    // On a stretch drawn twice: draw it once; elsewhere on the line: go back over it here
    // (route inspection then retraces this branch rather than another).
    const twice = (s.graph.retraces || []).flatMap((r) => r.points.map((q) => ({ at: q })));
    const onBand = nearest(twice, p, 14);
    const q = onBand || nearest(studio.line.pts.map((q) => ({ at: q })), p, 16);
    if (!q) return;
    return apply(withEdit({ kind: onBand ? "once" : "twice", at: q.at.slice(0, 2) }, ["twice", "once"]));
  }
  if (tool === "gap") {
    // A gap kept open: close it again (drop the edits that opened it); a bridged gap: open it.
    const open = nearest((s.graph.unbridged || []).map(middle), p, 24);
    if (open) return closeGap(open.ends);
    const gap = nearest((s.graph.bridges || []).map(middle), p, 24);
    return gap ? apply(withEdit({ kind: "unbridge", at: gap.at })) : null;
  }
  if (tool === "reverse") {
    const points = studio.line.pts.map((q) => ({ at: q }));
    const q = nearest(points, p, 16);
    return q ? apply(withEdit({ kind: "reverse", at: q.at.slice(0, 2) })) : null;
  }
}

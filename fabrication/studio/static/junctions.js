// onestroke studio: the Refine panel's list of the places the line's reading can be fixed
// (crossings, triple points, unresolved junctions, merge handles, stretches drawn twice,
// pen gaps, the ends it may start from), each row with buttons for what the canvas tools
// do there: a drawing can be fixed with the keyboard alone. A row that takes the focus
// (Tab, or the arrow keys within the list) selects its place: the view zooms to it and
// rings it. After an edit the focus comes back to the same place's row.
"use strict";
import { $ } from "./api.js";
import { apply, currentEdits, isNear, withEdit } from "./edits.js";
import { hint } from "./hint.js";
import { drawPasses } from "./marks.js";
import { choosePasses, closeGap, describeUnresolved, lineEnds, unresolvedFixes } from "./tools.js";
import { COLORS, decisionText, dist, passRank, percent, samePasses, shownRetraces, studio } from "./view.js";

const PAIRINGS = ["crossing", "touching", "third"];
let select = () => {};  // ring a place, and zoom to it (the view's, set by setupJunctions)
let refocusing = false;

export function setupJunctions(selectPlace) {
  select = selectPlace;
  const list = $("junctions");
  list.addEventListener("focusin", (e) => {
    const row = e.target.closest("li[data-x]");
    // Reached by keyboard, or the row itself clicked: zoom to it; a mouse click on a row's
    // button only rings the place (the view stays where the user put it).
    // The focus put back after an edit keeps the view as it is.
    const zoom = !refocusing && (e.target === row || e.target.matches(":focus-visible"));
    if (row) select({ at: [Number(row.dataset.x), Number(row.dataset.y)], key: row.dataset.key }, zoom);
  });
  list.addEventListener("keydown", (e) => {
    // Up and down move between the rows (Tab walks through each row's buttons).
    if (e.key !== "ArrowDown" && e.key !== "ArrowUp") return;
    const rows = [...list.querySelectorAll("li[data-x]")];
    const k = rows.indexOf(e.target.closest("li"));
    const next = rows[k + (e.key === "ArrowDown" ? 1 : -1)];
    if (next) { e.preventDefault(); next.focus(); }
  });
}

function button(text, title, run, pressed = null) {
  const b = document.createElement("button");
  b.type = "button"; b.textContent = text; b.title = title; b.dataset.action = text;
  if (pressed !== null) b.setAttribute("aria-pressed", String(pressed));
  b.onclick = () => { hint(""); run(); };
  return b;
}

// A row for the place `at`: focusable, keyed by its kind and place (kept through an edit).
function row(kind, at, className = "") {
  const li = document.createElement("li");
  li.tabIndex = 0; li.className = className;
  li.dataset.x = String(at[0]); li.dataset.y = String(at[1]);
  li.dataset.key = `${kind}:${Math.round(at[0])},${Math.round(at[1])}`;
  return li;
}
const where = (at) => `(${at[0].toFixed(0)}, ${at[1].toFixed(0)})`;

function crossingRow(j, state) {
  const li = row("junction", j.at);
  li.style.color = COLORS[j.decision];
  // The marker's figure is the confidence (how far the classifier's views agree), not the
  // probability: "touching 100%" beside p(cross) 19% reads as a contradiction unless both are named.
  li.title = "confidence: the share of the classifier's 8 turned and mirrored views of this junction " +
    "that agree (the figure on the marker); p(crossing): their mean probability that two strokes cross here";
  const by = state.classifier === "geometric" ? "geometric rule" : "CNN";
  li.append(`${where(j.at)} ${decisionText(j)} · ${by} p(crossing) ${(j.p_crossing * 100).toFixed(0)}% `);
  for (const kind of PAIRINGS) {
    li.append(button(kind, `the pen goes through here as a ${kind}`, () =>
      apply(withEdit({ kind: "pairing", at: j.at, pairing: kind }, ["pairing"])), j.decision === kind));
  }
  li.append(splitButton(j));
  return li;
}

function splitButton(j) {
  return button("split", "split it back into the junctions it was merged from", () =>
    apply(withEdit({ kind: "split", at: j.at }, ["pairing", "passes"])));
}

function tripleRow(j, state) {
  const li = row("junction", j.at);
  li.style.color = COLORS.passes;
  const offered = state.settings.multi ? `all ${j.options.length} pairings`
    : `the ${j.options.length} pairings that keep one line`;
  li.append(`${where(j.at)} three passes: pairing ${passRank(j)} · ` +
    `${j.confidence === null ? "straightest" : "pass scorer" + percent(j.confidence)}` +
    `${j.fixed ? " · fixed by you" : ""} · ${offered}, likeliest first:`);
  li.append(passChoice(j), splitButton(j));
  return li;
}

// The pairings a triple point may take, likeliest first (single-line mode: those that keep
// the line one stroke; multi-stroke: all 15), each a small drawing of its passes with its
// place and the pass scorer's posterior; the one drawn is outlined. A click picks one.
function passChoice(j) {
  const box = document.createElement("div");
  box.className = "pass-options";
  const dpr = window.devicePixelRatio || 1;
  j.options.forEach((o, k) => {
    const current = samePasses(o.passes, j.passes);
    const b = button("", "", () => choosePasses(j, o), current);
    b.className = "pass-option" + (current ? " current" : "");
    b.dataset.index = String(k);
    b.title = `pairing ${k + 1}${percent(o.p)}: passes ` + o.passes.map(([a, z]) => `${Math.round(a)}°–${Math.round(z)}°`).join(", ");
    b.setAttribute("aria-label", b.title);
    const c = document.createElement("canvas");
    c.width = c.height = Math.round(34 * dpr); c.style.width = c.style.height = "34px";
    c.setAttribute("aria-hidden", "true");
    const g = c.getContext("2d"); g.scale(dpr, dpr);
    drawPasses(g, 17, 17, 13, o.passes, 2);
    const caption = document.createElement("span");
    caption.textContent = `${k + 1}${percent(o.p)}`;
    b.append(c, caption);
    box.appendChild(b);
  });
  return box;
}

function note(text, className) {
  const li = document.createElement("li");
  li.className = className; li.textContent = text;
  return li;
}

// The list for `state`; `keepPieces` switches to multi-stroke (the pieces' note offers it).
export function showJunctions(state, keepPieces) {
  const list = $("junctions");
  const focused = list.contains(document.activeElement) ? document.activeElement : null;
  const was = focused && focused.closest("li[data-key]");
  const memory = was ? { key: was.dataset.key, action: focused.dataset.action, at: [Number(was.dataset.x), Number(was.dataset.y)] } : null;
  list.innerHTML = "";
  const junctions = state.graph.junctions;
  for (const j of junctions) {
    if (j.role === "crossing") list.appendChild(crossingRow(j, state));
    else if (j.role === "triple") list.appendChild(tripleRow(j, state));
  }
  for (const j of junctions.filter((q) => q.role === "unresolved")) {
    const li = row("junction", j.at, "unresolved");
    li.append(describeUnresolved(j), ...unresolvedFixes(j));
    list.appendChild(li);
  }
  for (const b of state.graph.branches) {
    const li = row("branch", b.at, "branch");
    li.append(`${where(b.at)} branch of ${b.length.toFixed(0)} px between two junctions (◆) `,
      button("merge", "collapse this branch: its two junctions become one crossing", () =>
        apply(withEdit({ kind: "merge", at: b.at }))),
      button("draw twice", "go back over this branch where the line must retrace something", () =>
        apply(withEdit({ kind: "twice", at: b.at }, ["twice", "once"]))));
    list.appendChild(li);
  }
  const twice = shownRetraces();
  if (twice.length) {
    list.appendChild(note(`drawn twice (×2): ${twice.length} stretch${twice.length === 1 ? "" : "es"}, ` +
      `${Math.round(twice.reduce((sum, r) => sum + r.length, 0))} px`, "retraces"));
  }
  for (const r of twice) {
    const li = row("retrace", r.at, "retraces");
    li.append(`${where(r.at)} ${Math.round(r.length)} px drawn twice `,
      button("draw once", "draw this stretch once; the route then retraces another", () =>
        apply(withEdit({ kind: "once", at: r.at }, ["twice", "once"]))));
    list.appendChild(li);
  }
  const gaps = state.graph.bridges || [], open = state.graph.unbridged || [];
  if (gaps.length) {
    list.appendChild(note(`pen gap${gaps.length === 1 ? "" : "s"} bridged: ${gaps.length} (dashed ` +
      `circle${gaps.length === 1 ? "" : "s"})`, "gaps"));
  }
  for (const gap of gaps) {
    const at = [(gap[0][0] + gap[1][0]) / 2, (gap[0][1] + gap[1][1]) / 2];
    const li = row("gap", at, "gaps");
    li.append(`${where(at)} pen gap bridged (dashed circle) `,
      button("open", "keep this gap open: its two sides are separate strokes", () =>
        apply(withEdit({ kind: "unbridge", at }))));
    list.appendChild(li);
  }
  if (open.length) {
    list.appendChild(note(`pen gap${open.length === 1 ? "" : "s"} kept open by you: ${open.length} ` +
      `(struck-through circle${open.length === 1 ? "" : "s"})`, "open-gaps"));
  }
  for (const gap of open) {
    const at = [(gap[0][0] + gap[1][0]) / 2, (gap[0][1] + gap[1][1]) / 2];
    const li = row("gap", at, "open-gaps");
    li.append(`${where(at)} pen gap kept open by you `, button("close", "bridge this gap again", () => closeGap(gap)));
    list.appendChild(li);
  }
  const start = state.strokes.length ? state.strokes[0].points[0] : null;
  const edits = currentEdits();
  for (const at of lineEnds(state)) {
    const li = row("end", at, "ends");
    const first = start && dist(start, at) < 3;
    const chosen = edits.edits.some((e) => isNear(e, edits, ["start"], at));
    li.append(`${where(at)} ${first ? "the line starts here" : "an end"}${chosen ? " (yours)" : ""} `,
      button("start here", "start the line at this end", () => apply(withEdit({ kind: "start", at }, ["start"])), first));
    list.appendChild(li);
  }
  if (state.report.dropped && !state.settings.multi) {
    // What single-line mode does with ink in several pieces (as the CLI does): the largest
    // piece is the line; the others stay grey, undrawn.
    const li = note(`the ink is in ${state.report.dropped + 1} pieces: one line keeps the largest, the grey rest ` +
      "is not drawn. ", "pieces");
    const keep = button("Keep every piece (multi-stroke)", "Multi-stroke mode draws each piece as its own stroke " +
      "(and bridges no pen gap)", keepPieces);
    keep.id = "keep-pieces";
    li.appendChild(keep);
    list.appendChild(li);
  }
  if (memory) refocus(list, memory);
}

// The focus back on the row of the same place (or the nearest row: a split crossing's
// halves), on the same button when it is still there.
function refocus(list, memory) {
  const rows = [...list.querySelectorAll("li[data-key]")];
  if (!rows.length) return;
  const same = rows.find((r) => r.dataset.key === memory.key) ||
    rows.reduce((a, b) => (dist([Number(b.dataset.x), Number(b.dataset.y)], memory.at) <
      dist([Number(a.dataset.x), Number(a.dataset.y)], memory.at) ? b : a));
  const again = memory.action && [...same.querySelectorAll("button")].find((b) => b.dataset.action === memory.action);
  refocusing = true;
  try { (again || same).focus({ preventScroll: false }); } finally { refocusing = false; }
}

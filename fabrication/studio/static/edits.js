// onestroke studio: the edits as data and their history: the edits list of each step, edits
// added, replaced or dropped near a place (`without`, `withEdit`), undo/redo, sending a step to
// the server (stale answers dropped) and saving, loading and opening edits files.
"use strict";
import { $, busy, call } from "./api.js";
import { hint, tell } from "./hint.js";
import { dist, studio } from "./view.js";

// What shows an answered state (the page's `show`) and puts the controls back to the state
// shown after a refusal (`refused`), set by setupEdits.
let show = null, refused = () => {};

export function currentEdits() { return studio.history[studio.at]; }
export const SETTINGS = ["threshold", "blur", "multi"];
// Only the answer to the latest request is shown: a slow re-run answered after a newer
// edit (or while a slider moves on) is dropped, so the page never shows a stale state.
export async function apply(edits, push = true) {
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
    if (ticket === studio.requests) { tell(error.message, true); refused(); }
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

// Does edit e, of one of these kinds, lie within the edits' tolerance of `at` (by
// `distance(e.at, at)`, image px: the radius within which the library matches an edit to
// its junction or branch)?
export function isNear(e, edits, kinds, at, distance = dist) {
  return kinds.includes(e.kind) && distance(e.at, at) <= edits.tolerance;
}

// A copy of `edits` without its edits of these kinds near `at`.
export function without(edits, kinds, at = null, distance = dist) {
  const copy = JSON.parse(JSON.stringify(edits));
  copy.edits = copy.edits.filter((e) => !isNear(e, copy, kinds, at, distance));
  return copy;
}

// The current edits with these settings changed (threshold, blur, multi).
export function withSettings(change) { return Object.assign(without(currentEdits(), []), change); }

// The current edits plus `edit`, which replaces the edits of the kinds `replaces` near its
// place (one pairing per junction: a new choice replaces the old one instead of piling up).
export function withEdit(edit, replaces = []) {
  const edits = without(currentEdits(), replaces, edit.at);
  edits.edits.push(edit);
  return edits;
}

export function undo() { if (studio.at > 0) { studio.at -= 1; apply(currentEdits(), false); } }
export function redo() { if (studio.at < studio.history.length - 1) { studio.at += 1; apply(currentEdits(), false); } }

export function updateButtons() {
  $("undo").disabled = studio.at <= 0;
  $("redo").disabled = studio.at >= studio.history.length - 1;
}

// The history's buttons and the edits files' (save, load, open); `showState` shows an answer.
export function setupEdits(showState, restore) {
  show = showState; refused = restore;
  $("undo").onclick = undo; $("redo").onclick = redo;
  $("save").onclick = async () => {
    try {
      const r = await call("api/edits", { edits: currentEdits() });
      if (studio.tab === "refine") $("summary").textContent += ` · saved ${r.saved}`;
      else tell(`saved ${r.saved}`);
    } catch (error) { tell(error.message, true); }
  };
  $("load").onclick = async () => {
    try {
      const r = await call("api/edits");
      // No file yet: nothing to load (applying "no edits" would throw the user's away).
      if (!r.exists) tell(`no edits saved yet: ${r.path} does not exist (Save edits writes it)`);
      else if (JSON.stringify(r.edits) === JSON.stringify(currentEdits())) tell(`the edits are those of ${r.path} already`);
      else { hint(""); apply(r.edits); }
    } catch (error) { tell(error.message, true); }
  };
  $("open").onchange = async () => {
    const file = $("open").files[0]; if (!file) return;
    let data;
    try { data = JSON.parse(await file.text()); }
    catch (error) { tell(`${file.name} is not an edits file (not JSON)`, true); }
    if (data !== undefined) apply(data);
    $("open").value = "";
  };
}

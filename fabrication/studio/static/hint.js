// onestroke studio: what the page says to the user: the hint line under the drawing and the
// notes and errors of the header's actions, in the panel in view.
"use strict";
import { $, report } from "./api.js";
import { studio } from "./view.js";

// What comes of the header's actions (undo, redo, save, load, open: at hand on every tab),
// said in the panel in view: on Refine an error in its warnings and a note as the hint; on
// the Embroidery or Laser tab both in that panel's list, where the user is looking.
export function tell(message, error = false) {
  const list = studio.tab === "refine" ? "warnings" : `${studio.tab}-warnings`;
  if (error) report(new Error(message), list);
  else if (studio.tab === "refine") hint(message);
  else { const li = document.createElement("li"); li.textContent = message; $(list).replaceChildren(li); }
}

export function hint(text, buttons = []) {
  $("hint").textContent = text || "";
  for (const b of buttons) $("hint").append(" ", b);
  $("hint").hidden = !text;
}

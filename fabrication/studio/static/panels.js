// onestroke studio: the make-it panels (embroidery, laser), downloads and "send to laser".
// Every figure and file comes from the server, i.e. from the library calls the CLI makes.
"use strict";
import { $, busy, call, escapeHtml, report } from "./api.js";
import { createPlayer } from "./player.js";
import { studio } from "./view.js";

let edits = () => null;  // the page's current edits state (set by setupPanels)

// ---------------------------------------------------------------- make-it panels
function formValues(id) {
  const values = {};
  for (const el of $(id).elements) {
    if (!el.name) continue;
    values[el.name] = el.type === "checkbox" ? el.checked : el.value;
  }
  return values;
}
function panelOptions(kind) {
  if (kind === "embroidery") return formValues("embroidery-form");
  if (kind === "laser") return formValues("laser-form");
  return {};
}

let panelTicket = 0;
export async function refreshPanel() {
  const tab = studio.tab;
  if (tab === "refine" || !edits()) return;
  const ticket = ++panelTicket;
  busy(true);
  try {
    const data = await call(`api/${tab}`, { edits: edits(), options: panelOptions(tab) });
    if (ticket !== panelTicket) return;
    if (tab === "embroidery") showStitches(data); else showToolpath(data);
    stale(tab, false);
  } catch (error) {
    if (ticket !== panelTicket) return;
    stale(tab, true, fieldNames(error.message, `${tab}-form`));
  } finally {
    busy(false);
  }
}

// The options in the form failed: the preview and figures still shown are those of the last
// options that worked, dimmed and said so, never taken for the new ones.
function stale(tab, on, message = "") {
  $(`tab-${tab}`).classList.toggle("stale", on);
  $(`${tab}-stale`).hidden = !on;
  if (!on) return;
  const shown = !players[tab] ? "" : tab === "laser" ? " The toolpath below is from the last options that worked."
    : " The stitches below are from the last options that worked.";
  $(`${tab}-stale`).textContent = `error: ${message}.${shown}`.replace(/\.\./, ".");
  $(`${tab}-warnings`).innerHTML = "";
}

// The library names options as the CLI spells them ("--stitch-length"); on the page they
// are the form's fields ("Stitch length").
export function fieldNames(message, formId) {
  return message.replace(/--([a-z][a-z-]*)/g, (flag, name) => {
    // A form's field, or a control of the Refine panel by its id ("--multi": "multi-stroke drawing").
    const field = (formId && $(formId).elements[name.replace(/-/g, "_")]) || $(name);
    const label = field && field.closest("label");
    const text = label && [...label.childNodes].filter((n) => n.nodeType === Node.TEXT_NODE)
      .map((n) => n.textContent.trim()).join(" ").trim();
    return text ? `"${text}"` : flag;
  });
}

// Stitches and laser moves play in the project's player (fabrication/player), one per panel.
const players = {};
let laserShown = 0, laserSent = -1;  // which toolpath the laser player shows, which one was sent
function showPlayer(kind, data) {
  if (!players[kind]) players[kind] = createPlayer($(`${kind}-player`), data);
  else players[kind].load(data);
  if (kind === "laser") laserShown += 1;
  players[kind].seek(data.total);  // the finished job first; Play starts it from the beginning
  studio.players = players;
}

function showStitches(data) {
  showPlayer("embroidery", data.player);
  $("embroidery-stats").textContent = data.stats.join("\n");
  $("embroidery-warnings").innerHTML = data.warnings.map((m) => `<li>${escapeHtml(m)}</li>`).join("");
}

function showToolpath(data) {
  showPlayer("laser", data.player);
  $("laser-time").textContent = `estimated ${data.time} (GRBL planner model; length/feed says ${data.naive}) · ` +
    `burn ${data.burn_length} mm, travel ${data.travel_length} mm · ${data.lines} lines · profile: ${data.profile}`;
  $("laser-warnings").innerHTML = data.warnings.map((m) => `<li>${escapeHtml(m)}</li>`).join("");
}

async function download(kind) {
  busy(true);
  const tab = ["pes", "dst", "jef", "exp", "vp3"].includes(kind) ? "embroidery" : kind === "gcode" ? "laser" : "refine";
  try {
    const response = await call(`api/export/${kind}`, { edits: edits(), options: panelOptions(tab) }, true);
    const blob = await response.blob();
    const name = /filename="([^"]+)"/.exec(response.headers.get("Content-Disposition") || "")?.[1] || `drawing.${kind}`;
    const a = document.createElement("a");
    a.href = URL.createObjectURL(blob); a.download = name;
    document.body.appendChild(a); a.click(); a.remove();
    setTimeout(() => URL.revokeObjectURL(a.href), 10000);
  } catch (error) {
    const message = tab === "refine" ? error.message : fieldNames(error.message, `${tab}-form`);
    report(new Error(message), tab === "refine" ? "warnings" : `${tab}-warnings`);  // beside the button clicked
  } finally {
    busy(false);
  }
}

// ---------------------------------------------------------------- send to laser
// The job runs in the server (fabrication/studio/sender.py); the page polls its state
// while it is active and enables only the controls that state allows.
const ACTIVE = ["connecting", "streaming", "paused", "aborting"];
let sendTimer = null;
async function sendAction(action) {
  try {
    const status = action === "send"
      ? await call("api/send", { edits: edits(), options: panelOptions("laser"), port: $("port").value.trim() })
      : await call(`api/send/${action}`, {});
    if (action === "send") laserSent = laserShown;
    showSend(status);
  } catch (error) {
    sendError(fieldNames(error.message, "laser-form"));
  }
}
async function pollSend() {
  try { showSend(await call("api/send")); } catch (error) { sendError(error.message); }
}
function sendError(message) {
  $("send-status").textContent = "error: " + message;
  $("send-status").dataset.state = "error";
}
function showSend(s) {
  const active = ACTIVE.includes(s.state);
  $("send-progress").max = s.total || 1; $("send-progress").value = s.acked || 0;
  const lines = s.total && (active || s.acked) ? ` · ${s.acked}/${s.total} lines` : "";
  const machine = s.machine && active ? ` · machine ${s.machine}` : "";
  $("send-status").textContent = `${s.state}${s.port ? ` on ${s.port}` : ""}${lines}${machine}` +
    `${s.message ? ` · ${s.message}` : ""}`;
  $("send-status").dataset.state = s.state;
  // The laser player follows the job (the line the machine acknowledged last) while it
  // shows the toolpath that was sent.
  if (active && s.line && players.laser && laserSent === laserShown) players.laser.seekNumber(s.line);
  $("send").disabled = active;
  $("pause").disabled = s.state !== "streaming";
  $("resume").disabled = s.state !== "paused";
  $("abort").disabled = !active || s.state === "aborting";
  if (active && !sendTimer) sendTimer = setInterval(pollSend, 250);
  if (!active && sendTimer) { clearInterval(sendTimer); sendTimer = null; }
}
// ---------------------------------------------------------------- machine profiles
// The select lists the built-in profiles, the command line's --profile and those loaded here;
// a loaded file is sent as text and checked by the server's profile loader. A bad one leaves
// the select as it was.
function showProfiles(list, chosen) {
  const select = $("profile");
  const keep = chosen || select.value || list.default;
  select.innerHTML = list.profiles.map((p) => `<option value="${escapeHtml(p.id)}">${escapeHtml(p.label)}</option>`).join("");
  select.value = list.profiles.some((p) => p.id === keep) ? keep : list.default;
}
async function listProfiles() {
  try { showProfiles(await call("api/profiles")); }
  catch (error) { $("profile-status").textContent = "error: " + error.message; }
}
async function loadProfile(file) {
  const status = $("profile-status");
  status.dataset.state = "";
  try {
    if (file.size > 64 * 1024) throw new Error(`${file.name} is too large for a profile (at most 64 kB)`);
    const answer = await call("api/profiles", { name: file.name, text: await file.text() });
    showProfiles(answer, answer.id);
    status.textContent = `loaded ${file.name}: ${answer.name}`;
    refreshPanel();
  } catch (error) {
    status.textContent = `error: ${error.message} (the profile in use is unchanged)`;
    status.dataset.state = "error";
  } finally {
    $("profile-file").value = "";  // picking the same file again loads it again
  }
}

async function listPorts() {
  try {
    const found = (await call("api/ports")).ports;
    $("ports").innerHTML = found.map((p) => `<option value="${escapeHtml(p.device)}">${escapeHtml(p.description || "")}` +
      `${p.problem ? " (" + escapeHtml(p.problem) + ")" : ""}</option>`).join("");
  } catch (error) { /* typing a port still works */ }
}

export function setupPanels(currentEdits) {
  edits = currentEdits;
  for (const tab of document.querySelectorAll("nav .tab")) {
    tab.onclick = () => {
      studio.tab = tab.dataset.tab;
      document.querySelectorAll("nav .tab").forEach((t) => t.classList.toggle("active", t === tab));
      document.querySelectorAll(".panel").forEach((p) => { p.hidden = p.id !== `tab-${tab.dataset.tab}`; });
      refreshPanel();
    };
  }
  for (const form of ["embroidery-form", "laser-form"]) $(form).addEventListener("change", refreshPanel);
  for (const button of document.querySelectorAll("[data-export]")) button.onclick = () => download(button.dataset.export);
  for (const action of ["send", "pause", "resume", "abort"]) $(action).onclick = () => sendAction(action);
  $("profile-file").addEventListener("change", (event) => {
    if (event.target.files.length) loadProfile(event.target.files[0]);
  });
  listProfiles();
  listPorts();
  pollSend();  // a job started before this page was (re)loaded
}

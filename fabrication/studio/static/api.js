// onestroke studio: talking to the server (token header, JSON, errors) and small page helpers.
"use strict";

export const TOKEN = new URLSearchParams(location.search).get("token") || "";
export const $ = (id) => document.getElementById(id);

// ---------------------------------------------------------------- server calls
export async function call(path, body, raw = false) {
  const init = { headers: { "X-Studio-Token": TOKEN } };
  if (body !== undefined) {
    init.method = "POST";
    init.headers["Content-Type"] = "application/json";
    init.body = JSON.stringify(body);
  }
  let response;
  try { response = await fetch(path, init); }
  catch (error) { throw new Error("the studio server does not answer (was it stopped?): " + error.message); }
  if (!response.ok) {
    let message = response.statusText;
    try { message = (await response.json()).error || message; } catch (e) { /* not JSON */ }
    throw new Error(message);
  }
  return raw ? response : response.json();
}

let busyCount = 0;
export function busy(on) {
  busyCount += on ? 1 : -1;
  $("busy").hidden = busyCount <= 0;
  document.body.classList.toggle("busy", busyCount > 0);
}

// An error in one line, in the warnings list of the panel in view (`list`: its id).
export function report(error, list = "warnings") {
  $(list).innerHTML = "";
  const li = document.createElement("li");
  li.textContent = "error: " + error.message;
  $(list).appendChild(li);
}

export function escapeHtml(text) {
  return text.replace(/[&<>"]/g, (c) => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;" }[c]));
}


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
  const response = await fetch(path, init);
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

export function report(error) {
  $("warnings").innerHTML = "";
  const li = document.createElement("li");
  li.textContent = "error: " + error.message;
  $("warnings").appendChild(li);
}

export function escapeHtml(text) {
  return text.replace(/[&<>"]/g, (c) => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;" }[c]));
}


// onestroke player: plays stitches, laser moves or a drawing's pen in order on a time axis.
//
// Plain ES module, no dependencies, no network. Data: PlayerData.to_json() from
// fabrication/player/data.py (row i = the head's move from point i-1 to point i, done at
// t[i]). Usage: createPlayer(element, data) -> {play, pause, seek, load, ...}.
// Drawing is incremental: finished rows are drawn once into an off-screen "ink" layer;
// each frame only adds the rows finished since the last frame, so 100k stitches play
// smoothly. Going back in time or changing the view redraws the layer once.

export const DRAW = 0, TRAVEL = 1, TRIM = 2, COLOR = 3, DOWN = 4;

const KIND_TEXT = {
  embroidery: ["stitch", "jump", "trim", "colour change", "needle down"],
  gcode: ["burn", "travel", "-", "-", "-"],
  drawing: ["pen down", "pen up", "-", "-", "-"],
};
const LEGEND = {
  embroidery: ["── stitches in their thread colour", "┄┄ jump (needle up)", "× trim", "◆ colour change",
               "▪ needle points (zoomed in)", "○ needle: red sewing, blue moving"],
  gcode: ["── burn, coloured first → last", "┄┄ travel, laser off", "○ laser head: red burning, blue moving"],
  drawing: ["── pen, coloured start → end", "┄┄ pen up to the next stroke", "○ pen"],
};
const SPEEDS = [0.1, 0.25, 0.5, 1, 2, 5, 10, 20, 50, 100, 200, 500, 1000, 2000, 5000];
const SCRUB_STEPS = 100000;
const PLAY_SECONDS = 20;  // default speed plays the whole job in about this long

function decode(text, Type) {
  const bin = atob(text);
  const bytes = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
  return new Type(bytes.buffer);
}

// Parsed PlayerData JSON (object or string) -> typed arrays plus the header fields.
export function decodeData(input) {
  const d = typeof input === "string" ? JSON.parse(input) : input;
  const out = Object.assign({}, d, {
    x: decode(d.x, Float32Array), y: decode(d.y, Float32Array), t: decode(d.t, Float64Array),
    kind: decode(d.kind, Uint8Array), color: decode(d.color, Uint16Array), num: decode(d.num, Uint32Array),
  });
  out.total = Math.max(d.total, d.n ? out.t[d.n - 1] : 0);
  return out;
}

function formatTime(value, unit) {
  if (unit !== "s") return `${value.toFixed(1)} ${unit}`;
  const whole = Math.floor(value);
  const h = Math.floor(whole / 3600), m = Math.floor((whole % 3600) / 60);
  const s = (value - h * 3600 - m * 60).toFixed(1).padStart(4, "0");
  return h ? `${h}:${String(m).padStart(2, "0")}:${s}` : `${m}:${s}`;
}

function el(tag, attrs = {}, children = []) {
  const node = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k === "text") node.textContent = v; else node.setAttribute(k, v);
  }
  for (const child of children) node.append(child);
  return node;
}

function buildDom(root) {
  root.classList.add("osp-root");
  root.replaceChildren();
  const speed = el("select", { "data-role": "speed", title: "playback speed" });
  for (const s of SPEEDS) speed.append(el("option", { value: String(s), text: `${s}×` }));
  const dom = {
    title: el("span", { class: "osp-title", "data-role": "title" }),
    number: el("span", { class: "osp-value", "data-role": "number" }),
    time: el("span", { class: "osp-value", "data-role": "time" }),
    kind: el("span", { class: "osp-value", "data-role": "kind" }),
    swatch: el("span", { class: "osp-swatch", "data-role": "swatch" }),
    canvas: el("canvas", { class: "osp-canvas", "data-role": "canvas", role: "img",
                           "aria-label": "the job played in order" }),
    where: el("span", { class: "osp-value osp-where", "data-role": "position" }),
    info: el("ul", { class: "osp-info", "data-role": "info" }),
    play: el("button", { type: "button", "data-role": "play", title: "play / pause (space)", text: "▶ Play" }),
    back: el("button", { type: "button", "data-role": "back", title: "previous move (←)", text: "◀ step" }),
    next: el("button", { type: "button", "data-role": "next", title: "next move (→)", text: "step ▶" }),
    scrub: el("input", { type: "range", min: "0", max: String(SCRUB_STEPS), value: "0", step: "1",
                         "data-role": "scrub", "aria-label": "time" }),
    speed,
    zoomIn: el("button", { type: "button", "data-role": "zoom-in", title: "zoom in", text: "+" }),
    zoomOut: el("button", { type: "button", "data-role": "zoom-out", title: "zoom out", text: "−" }),
    fit: el("button", { type: "button", "data-role": "fit", title: "fit the design", text: "fit" }),
    travel: el("input", { type: "checkbox", "data-role": "show-travel", checked: "" }),
    ghost: el("input", { type: "checkbox", "data-role": "show-all", checked: "" }),
    follow: el("input", { type: "checkbox", "data-role": "follow", checked: "" }),
  };
  dom.numberLabel = el("span", { class: "osp-label" });
  dom.timeLabel = el("span", { class: "osp-label", text: "time" });
  const readout = el("div", { class: "osp-readout" }, [
    dom.numberLabel, dom.number, dom.timeLabel, dom.time,
    dom.swatch, dom.kind, dom.where]);
  dom.legend = el("ul", { class: "osp-legend", "data-role": "legend" });
  dom.stage = el("div", { class: "osp-stage" }, [dom.canvas]);
  root.append(
    el("div", { class: "osp-head" }, [dom.title, readout]),
    el("div", { class: "osp-main" }, [dom.stage, el("aside", { class: "osp-side" }, [dom.info, dom.legend,
      el("p", { class: "osp-keys", text: "space play / pause · ← → step · wheel or + − zoom · drag pan · 0 fit" })])]),
    el("div", { class: "osp-controls" }, [
      dom.back, dom.play, dom.next, dom.scrub, el("label", {}, ["speed ", speed]),
      dom.zoomOut, dom.zoomIn, dom.fit,
      el("label", {}, [dom.travel, " travel"]), el("label", {}, [dom.ghost, " whole design"]),
      el("label", { title: "when zoomed in, keep the head in view" }, [dom.follow, " follow"])]));
  return dom;
}

export function createPlayer(root, input, options = {}) {
  const dom = buildDom(root);
  const ctx = dom.canvas.getContext("2d");
  const ink = document.createElement("canvas"), inkCtx = ink.getContext("2d");
  const ghost = document.createElement("canvas"), ghostCtx = ghost.getContext("2d");
  let d = null, time = 0, playing = false, speed = 1, last = null, frameId = 0;
  let inkUpTo = -1, dirtyView = true, scrubbing = false;
  const view = { scale: 1, ox: 0, oy: 0 };
  const shift = { x: 0, y: 0 };  // pan not yet applied to the layers, device px
  let fitScale = 1;  // the scale "fit" chose: following the head only makes sense zoomed in
  let dpr = window.devicePixelRatio || 1;

  // The data's y as drawn (down the canvas): G-code's y points up, so it is flipped.
  const down = (y) => (d.yUp ? -y : y);
  const sx = (i) => view.ox + d.x[i] * view.scale;
  const sy = (i) => view.oy + down(d.y[i]) * view.scale;
  // The frame (hoop, bed) as drawn: [left, top, right, bottom] in the data's units, y down.
  function frameRect() {
    const [x0, y0, x1, y1] = d.frame;
    return [x0, Math.min(down(y0), down(y1)), x1, Math.max(down(y0), down(y1))];
  }

  // index of the last row finished at time `t` (-1 if none): binary search on d.t
  function rowAt(t) {
    let lo = 0, hi = d.n - 1, best = -1;
    while (lo <= hi) {
      const mid = (lo + hi) >> 1;
      if (d.t[mid] <= t) { best = mid; lo = mid + 1; } else hi = mid - 1;
    }
    return best;
  }

  function lineWidth() {
    const mm = d.source === "embroidery" ? 0.4 : d.source === "gcode" ? 0.25 : 0;
    const px = mm ? Math.min(Math.max(mm * view.scale, 1), 4) : 2;
    return px;
  }

  // draw rows from..to (inclusive) onto c: lines batched per colour, travel dashed, markers
  function drawRows(c, from, to, { plain = null } = {}) {
    if (to < from) return;
    c.lineCap = "round"; c.lineJoin = "round";
    c.lineWidth = lineWidth() * dpr;
    let colour = -1, open = false;
    const flush = () => { if (open) c.stroke(); open = false; };
    for (let i = Math.max(from, 1); i <= to; i++) {
      if (d.kind[i] !== DRAW) continue;
      const col = plain ? 0 : d.color[i];
      if (col !== colour || !open) {
        flush();
        colour = col;
        c.strokeStyle = plain || d.palette[col];
        c.beginPath(); open = true;
        c.moveTo(sx(i - 1), sy(i - 1));
      } else if (d.kind[i - 1] !== DRAW || d.color[i - 1] !== col) {
        c.moveTo(sx(i - 1), sy(i - 1));
      }
      c.lineTo(sx(i), sy(i));
    }
    flush();
    if (plain) return;
    if (d.source === "embroidery" && view.scale >= 8) {
      // zoomed in: the needle penetrations, where the thread goes through the fabric
      const r = 2 * dpr;
      c.fillStyle = "rgba(0,0,0,0.7)";
      for (let i = from; i <= to; i++) {
        if (d.kind[i] === DRAW || d.kind[i] === DOWN) c.fillRect(sx(i) - r, sy(i) - r, 2 * r, 2 * r);
      }
    }
    if (dom.travel.checked) {
      c.save();
      c.strokeStyle = "rgba(110,110,110,0.7)"; c.lineWidth = dpr; c.setLineDash([4 * dpr, 4 * dpr]);
      c.beginPath();
      for (let i = Math.max(from, 1); i <= to; i++) {
        // a needle going down after a jump or trim got there by travel too
        if (d.kind[i] !== TRAVEL && d.kind[i] !== DOWN) continue;
        c.moveTo(sx(i - 1), sy(i - 1)); c.lineTo(sx(i), sy(i));
      }
      c.stroke(); c.restore();
    }
    const r = 4 * dpr;
    c.save(); c.lineWidth = 1.5 * dpr;
    c.strokeStyle = "#d0021b"; c.beginPath();
    for (let i = from; i <= to; i++) {
      if (d.kind[i] !== TRIM) continue;
      const x = sx(i), y = sy(i);
      c.moveTo(x - r, y - r); c.lineTo(x + r, y + r); c.moveTo(x - r, y + r); c.lineTo(x + r, y - r);
    }
    c.stroke();
    c.fillStyle = "#7b1fa2"; c.beginPath();
    for (let i = from; i <= to; i++) {
      if (d.kind[i] !== COLOR) continue;
      const x = sx(i), y = sy(i);
      c.moveTo(x, y - r * 1.4); c.lineTo(x + r, y); c.lineTo(x, y + r * 1.4); c.lineTo(x - r, y); c.closePath();
    }
    c.fill(); c.restore();
  }

  function resize() {
    dpr = window.devicePixelRatio || 1;
    const w = Math.max(1, Math.round(dom.stage.clientWidth * dpr));
    const h = Math.max(1, Math.round(dom.stage.clientHeight * dpr));
    if (dom.canvas.width === w && dom.canvas.height === h) return false;
    for (const c of [dom.canvas, ink, ghost]) { c.width = w; c.height = h; }
    return true;
  }

  function fit() {
    if (!d) return;
    let xmin = Infinity, ymin = Infinity, xmax = -Infinity, ymax = -Infinity, any = false;
    for (const pass of [true, false]) {
      for (let i = 0; i < d.n; i++) {
        if (pass && d.kind[i] !== DRAW && d.kind[i] !== DOWN) continue;
        const x = d.x[i], y = down(d.y[i]);
        if (x < xmin) xmin = x; if (x > xmax) xmax = x; if (y < ymin) ymin = y; if (y > ymax) ymax = y;
        any = true;
      }
      if (any) break;
    }
    // The frame (a hoop, a bed) too when it is about the design's size: which hoop the
    // design sits in is part of the picture; a 400 mm bed around an 80 mm design is not.
    if (d.frame && any) {
      const [x0, fy0, x1, fy1] = frameRect();
      if (Math.max(x1 - x0, fy1 - fy0) <= 3 * Math.max(xmax - xmin, ymax - ymin)) {
        xmin = Math.min(xmin, x0); xmax = Math.max(xmax, x1); ymin = Math.min(ymin, fy0); ymax = Math.max(ymax, fy1);
      }
    }
    const w = dom.canvas.width, h = dom.canvas.height, pad = 0.05;
    const bw = Math.max(xmax - xmin, 1e-6), bh = Math.max(ymax - ymin, 1e-6);
    view.scale = fitScale = Math.min(w / (bw * (1 + 2 * pad)), h / (bh * (1 + 2 * pad)));
    view.ox = w / 2 - (xmin + bw / 2) * view.scale;
    view.oy = h / 2 - (ymin + bh / 2) * view.scale;
    dirtyView = true; request();
  }

  function zoom(factor, cx = dom.canvas.width / 2, cy = dom.canvas.height / 2) {
    view.ox = cx - (cx - view.ox) * factor;
    view.oy = cy - (cy - view.oy) * factor;
    view.scale *= factor;
    dirtyView = true; request();
  }

  function render() {
    frameId = 0;
    if (!d) return;
    if (resize()) { fit(); }
    const w = dom.canvas.width, h = dom.canvas.height;
    const i = rowAt(time);
    if (!dirtyView && (shift.x || shift.y)) {
      for (const c of [ghostCtx, inkCtx]) {
        c.save(); c.globalCompositeOperation = "copy"; c.drawImage(c.canvas, shift.x, shift.y); c.restore();
      }
    }
    shift.x = shift.y = 0;
    if (dirtyView) {
      ghostCtx.clearRect(0, 0, w, h);
      drawRows(ghostCtx, 0, d.n - 1, { plain: "rgba(0,0,0,0.09)" });
      inkCtx.clearRect(0, 0, w, h); inkUpTo = -1; dirtyView = false;
    }
    if (i < inkUpTo) { inkCtx.clearRect(0, 0, w, h); inkUpTo = -1; }
    if (i > inkUpTo) { drawRows(inkCtx, inkUpTo + 1, i); inkUpTo = i; }

    ctx.clearRect(0, 0, w, h);
    if (d.frame) {
      const [x0, ya, x1, yb] = frameRect(), s = view.scale;
      ctx.save(); ctx.strokeStyle = "#b0b0b0"; ctx.lineWidth = dpr; ctx.setLineDash([6 * dpr, 4 * dpr]);
      ctx.strokeRect(view.ox + x0 * s, view.oy + ya * s, (x1 - x0) * s, (yb - ya) * s); ctx.restore();
    }
    if (dom.ghost.checked) ctx.drawImage(ghost, 0, 0);
    ctx.drawImage(ink, 0, 0);

    // the move in progress, and the head on it
    let hx = sx(Math.max(i, 0)), hy = sy(Math.max(i, 0));
    const j = i + 1;
    if (j < d.n && j > 0) {
      const t0 = i >= 0 ? d.t[i] : 0, span = d.t[j] - t0;
      const f = span > 0 ? Math.min(Math.max((time - t0) / span, 0), 1) : 0;
      const px = sx(j - 1), py = sy(j - 1);
      hx = px + (sx(j) - px) * f; hy = py + (sy(j) - py) * f;
      if (f > 0) {
        ctx.save(); ctx.lineCap = "round";
        if (d.kind[j] === DRAW) { ctx.strokeStyle = d.palette[d.color[j]]; ctx.lineWidth = lineWidth() * dpr; }
        else { ctx.strokeStyle = "rgba(110,110,110,0.7)"; ctx.lineWidth = dpr; ctx.setLineDash([4 * dpr, 4 * dpr]); }
        ctx.beginPath(); ctx.moveTo(px, py); ctx.lineTo(hx, hy); ctx.stroke(); ctx.restore();
      }
    }
    // zoomed in and the head is leaving the view: bring it back to the centre
    if (playing && dom.follow.checked && view.scale > fitScale * 1.01
        && (hx < 0.1 * w || hx > 0.9 * w || hy < 0.1 * h || hy > 0.9 * h)) {
      view.ox += w / 2 - hx; view.oy += h / 2 - hy; dirtyView = true;
      return render();
    }
    const active = j < d.n ? d.kind[j] === DRAW : false;
    ctx.save(); ctx.lineWidth = 2 * dpr; ctx.strokeStyle = active ? "#e53935" : "#1e88e5";
    ctx.beginPath(); ctx.arc(hx, hy, 7 * dpr, 0, 2 * Math.PI);
    ctx.moveTo(hx - 11 * dpr, hy); ctx.lineTo(hx - 3 * dpr, hy); ctx.moveTo(hx + 3 * dpr, hy); ctx.lineTo(hx + 11 * dpr, hy);
    ctx.moveTo(hx, hy - 11 * dpr); ctx.lineTo(hx, hy - 3 * dpr); ctx.moveTo(hx, hy + 3 * dpr); ctx.lineTo(hx, hy + 11 * dpr);
    ctx.stroke(); ctx.restore();

    const row = Math.max(i, 0);
    const shownRow = j < d.n && time > (i >= 0 ? d.t[i] : 0) ? j : row;
    dom.number.textContent = `${(i >= 0 ? d.num[i] : 0).toLocaleString("en-US")} / ${d.numberTotal.toLocaleString("en-US")}`;
    dom.time.textContent = `${formatTime(time, d.timeUnit)} / ${formatTime(d.total, d.timeUnit)}`;
    dom.kind.textContent = (KIND_TEXT[d.source] || KIND_TEXT.drawing)[d.kind[shownRow]] || "";
    dom.swatch.style.background = d.palette[d.color[shownRow]];
    const wx = (hx - view.ox) / view.scale, wy = (hy - view.oy) / view.scale;
    dom.where.textContent = `x ${wx.toFixed(1)} y ${down(wy).toFixed(1)} ${d.unit}`;
    if (!scrubbing) dom.scrub.value = String(Math.round(d.total > 0 ? time / d.total * SCRUB_STEPS : 0));
    dom.play.textContent = playing ? "❚❚ Pause" : "▶ Play";
    root.dataset.index = String(i);
    root.dataset.time = String(time);
    if (options.onupdate) options.onupdate({ time, index: i, number: i >= 0 ? d.num[i] : 0 });
    if (playing) frameId = requestAnimationFrame(tick);
  }

  function tick(now) {
    frameId = 0;
    if (!playing) return render();
    if (last !== null) time = Math.min(time + (now - last) / 1000 * speed, d.total);
    last = now;
    if (time >= d.total) { playing = false; last = null; }
    render();
  }

  function request() { if (!frameId) frameId = requestAnimationFrame(playing ? tick : render); }

  const api = {
    play() { if (!d) return; if (time >= d.total) time = 0; playing = true; last = null; request(); },
    pause() { playing = false; last = null; request(); },
    toggle() { playing ? api.pause() : api.play(); },
    seek(t) { time = Math.min(Math.max(t, 0), d.total); request(); },
    // jump to the end of row i (and a step never stays put on rows of zero duration)
    seekRow(i) { i = Math.min(Math.max(i, -1), d.n - 1); api.seek(i >= 0 ? d.t[i] : 0); },
    // jump to the end of the last row numbered n or less (numbers ascend: e.g. the G-code
    // line a machine has just acknowledged while a job streams)
    seekNumber(n) {
      if (!d) return;
      let lo = 0, hi = d.n;  // first row numbered above n
      while (lo < hi) { const mid = (lo + hi) >> 1; if (d.num[mid] <= n) lo = mid + 1; else hi = mid; }
      api.pause(); api.seekRow(lo - 1);
    },
    step(delta) {
      api.pause();
      const i = rowAt(time);
      let k = i + delta;
      if (delta > 0) { while (k < d.n - 1 && d.t[k] <= time) k++; } else { while (k > 0 && d.t[k] >= time) k--; }
      api.seekRow(k);
    },
    setSpeed(s) { speed = s; dom.speed.value = String(s); },
    // Where the frame (hoop, bed) is drawn: [left, top, right, bottom] as fractions of the
    // canvas (inside: 0..1), or null without one.
    frameBox() {
      if (!d || !d.frame) return null;
      const [x0, ya, x1, yb] = frameRect(), w = dom.canvas.width, h = dom.canvas.height;
      return [(view.ox + x0 * view.scale) / w, (view.oy + ya * view.scale) / h,
              (view.ox + x1 * view.scale) / w, (view.oy + yb * view.scale) / h];
    },
    fit,
    zoom,
    load(data) {
      d = decodeData(data);
      dom.title.textContent = d.title;
      dom.numberLabel.textContent = d.numberLabel;
      dom.timeLabel.textContent = d.timeUnit === "s" ? "time" : "drawn";
      dom.info.replaceChildren(...d.info.map((line) => el("li", { text: line })));
      dom.legend.replaceChildren(...(LEGEND[d.source] || LEGEND.drawing).map((line) => el("li", { text: line })));
      const want = d.total / PLAY_SECONDS;
      api.setSpeed(SPEEDS.find((s) => s >= want) || SPEEDS[SPEEDS.length - 1]);
      time = Math.min(time, d.total); inkUpTo = -1;
      resize(); fit();
    },
    get time() { return time; },
    get index() { return d ? rowAt(time) : -1; },
    get playing() { return playing; },
    destroy() { playing = false; if (frameId) cancelAnimationFrame(frameId); observer.disconnect(); root.replaceChildren(); },
  };

  dom.play.addEventListener("click", () => api.toggle());
  dom.back.addEventListener("click", () => api.step(-1));
  dom.next.addEventListener("click", () => api.step(1));
  dom.scrub.addEventListener("input", () => { scrubbing = true; api.seek(Number(dom.scrub.value) / SCRUB_STEPS * d.total); });
  dom.scrub.addEventListener("change", () => { scrubbing = false; request(); });
  dom.speed.addEventListener("change", () => { speed = Number(dom.speed.value); });
  dom.zoomIn.addEventListener("click", () => zoom(1.5));
  dom.zoomOut.addEventListener("click", () => zoom(1 / 1.5));
  dom.fit.addEventListener("click", () => fit());
  for (const box of [dom.travel, dom.ghost]) box.addEventListener("change", () => { dirtyView = true; request(); });
  dom.canvas.addEventListener("wheel", (e) => {
    e.preventDefault();
    const rect = dom.canvas.getBoundingClientRect();
    zoom(Math.exp(-e.deltaY * 0.0015), (e.clientX - rect.left) * dpr, (e.clientY - rect.top) * dpr);
  }, { passive: false });
  let drag = null;
  dom.canvas.addEventListener("pointerdown", (e) => { drag = { x: e.clientX, y: e.clientY }; dom.canvas.setPointerCapture(e.pointerId); });
  dom.canvas.addEventListener("pointermove", (e) => {
    if (!drag) return;
    const dx = (e.clientX - drag.x) * dpr, dy = (e.clientY - drag.y) * dpr;
    view.ox += dx; view.oy += dy; shift.x += dx; shift.y += dy;
    drag = { x: e.clientX, y: e.clientY }; request();
  });
  // while dragging the layers only slide; one full redraw when the drag ends
  for (const end of ["pointerup", "pointercancel"]) {
    dom.canvas.addEventListener(end, () => { if (drag) { drag = null; dirtyView = true; request(); } });
  }
  root.tabIndex = 0;
  root.addEventListener("keydown", (e) => {
    if (e.target instanceof HTMLInputElement && e.target.type !== "checkbox" && e.key !== " ") return;
    if (e.key === " ") { e.preventDefault(); api.toggle(); }
    else if (e.key === "ArrowRight") { e.preventDefault(); api.step(1); }
    else if (e.key === "ArrowLeft") { e.preventDefault(); api.step(-1); }
    else if (e.key === "+" || e.key === "=") zoom(1.5);
    else if (e.key === "-") zoom(1 / 1.5);
    else if (e.key === "0") fit();
  });
  const observer = new ResizeObserver(() => { if (resize()) fit(); });
  observer.observe(dom.stage);

  api.load(input);
  return api;
}

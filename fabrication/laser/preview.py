"""Preview of a GRBL G-code file as PNG or SVG (chosen by the output's extension).

Shows the truth of the file, not of the plan: every move is read back through GRBL's own
reading of it (`machines.gcode_program`: arcs drawn as the chords GRBL cuts).
Burn moves are coloured along the job's order (blue first, through purple and red, to
yellow last), travel is dashed grey, the first burn is marked with a green ring, machine
(0, 0) with a cross. The main view is zoomed on the job; a thumbnail shows it on the bed
outline (travel leaving the view is clipped). The side panel prints the job time
(`machines.job_time`), which bound sets it (planner or serial link), and the length/feed figure.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from machines.gcode_program import Program, ProgramStats, analyze_program, load_program
from machines.grbl_settings import settings_from_profile
from machines.job_time import JobTime, estimate_program_time, format_duration
from machines.laser_profile import LaserProfile, load_laser_profile
from onestroke.atomic import atomic_open, atomic_write_text, check_writable
from onestroke.errors import InputError

FORMATS = (".png", ".svg")
MAIN = 900        # px, longest side of the main view
PANEL = 300       # px, side panel width
MARGIN = 30       # px around the main view
_STOPS = np.array([[0.13, 0.35, 0.85], [0.55, 0.25, 0.75], [0.85, 0.2, 0.35], [0.95, 0.55, 0.1],
                   [0.9, 0.8, 0.1]])


def order_colours(fraction: np.ndarray) -> np.ndarray:
    """RGB (M, 3) uint8 for positions in [0, 1] along the job: blue -> purple -> red -> yellow."""
    f = np.clip(fraction, 0.0, 1.0) * (len(_STOPS) - 1)
    i = np.minimum(f.astype(int), len(_STOPS) - 2)
    t = (f - i)[:, None]
    return np.round(255 * ((1 - t) * _STOPS[i] + t * _STOPS[i + 1])).astype(np.uint8)


@dataclass(frozen=True)
class _Scene:
    burn: list[tuple[np.ndarray, np.ndarray]]   # polylines (N, 2) mm with colours (N-1, 3)
    travel: list[np.ndarray]                     # (2, 2) mm
    start: np.ndarray | None
    bounds: tuple[float, float, float, float]
    bed: tuple[float, float]
    text: list[str]


def _bound_text(job: JobTime) -> str:
    if job.bound == "link":
        return f"bound: serial link (planner {format_duration(job.planner_seconds)})"
    return "bound: GRBL planner"


def _burn_runs(moves, seg, burn_mask, first, last, fraction):
    """Burn polylines with per-point colours, travel moves and the first burn point, in one
    array pass over all moves (a 500,000-move job would otherwise loop in Python).

    A run is a stretch of consecutive burn moves: its polyline is the first move's start,
    then each move's points as GRBL cuts it (its chord ends, or its end without segments),
    each point coloured by its move's position along the job.
    """
    on = np.flatnonzero(burn_mask)
    off = np.flatnonzero(~burn_mask)
    moving = np.any(moves.start[off] != moves.end[off], axis=1)
    travel = [np.array([a, b]) for a, b in zip(moves.start[off[moving]], moves.end[off[moving]])]
    if not len(on):
        return [], travel, None
    has = last[on] > first[on]
    count = np.where(has, last[on] - first[on], 1)
    owner = np.repeat(np.arange(len(on)), count)
    row = np.repeat(first[on], count) + np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
    points = np.where(np.repeat(has, count)[:, None], seg.end[np.minimum(row, max(len(seg.end) - 1, 0)), :2]
                      if len(seg.end) else 0.0, moves.end[on[owner]])
    colours = order_colours(fraction[on])[owner]
    # a run starts at a burn move whose predecessor does not burn
    opens = np.flatnonzero(np.r_[True, np.diff(on) > 1])
    cuts = np.r_[np.cumsum(count)[opens[1:] - 1], len(points)]
    burn, begin = [], 0
    for move, end in zip(on[opens].tolist(), cuts.tolist()):
        burn.append((np.vstack([moves.start[move][None], points[begin:end]]), colours[begin:end]))
        begin = end
    return burn, travel, moves.start[on[0]]


def _scene(stats: ProgramStats, job: JobTime, profile: LaserProfile, name: str, n_lines: int) -> _Scene:
    moves, seg = stats.moves, stats.segments
    burn_mask = moves.laser_on
    lengths = np.hypot(*(moves.end - moves.start).T)
    # each move's points as GRBL cuts it (chord ends of its segments)
    first = np.searchsorted(seg.move, np.arange(len(moves)))
    last = np.searchsorted(seg.move, np.arange(len(moves)), side="right")
    along = np.cumsum(np.where(burn_mask, lengths, 0.0))
    total = max(along[-1] if len(along) else 0.0, 1e-12)
    burn, travel, start = _burn_runs(moves, seg, burn_mask, first, last, (along - lengths / 2) / total)
    # the view is zoomed on what is burned; travel leaving it is clipped at the edge
    shown = [p for p, _ in burn] or travel
    if shown:
        pts = np.vstack(shown)
        bounds = (*pts.min(axis=0), *pts.max(axis=0))
    else:
        bounds = (0.0, 0.0, profile.bed_width, profile.bed_height)
    burn_len, travel_len = job.burn_length, job.travel_length
    text = [name if len(name) <= 34 else name[:31] + "...",
            f"time: {format_duration(job.total_seconds)}",
            _bound_text(job),
            f"length / feed: {format_duration(job.naive_seconds)} (common senders)",
            f"burn {burn_len:.0f} mm, travel {travel_len:.0f} mm",
            f"{n_lines} lines, {job.blocks} planner blocks",
            f"{'burn area' if burn else 'moves (no burn)'} {bounds[2] - bounds[0]:.1f} x "
            f"{bounds[3] - bounds[1]:.1f} mm",
            f"bed {profile.bed_width:g} x {profile.bed_height:g} mm",
            "", "colour: burn order (first -> last)", "dashed grey: travel, laser off",
            "green ring: start, cross: (0, 0)"]
    return _Scene(burn, travel, start, bounds, (profile.bed_width, profile.bed_height), text)


class _View:
    """mm (machine, +y up) -> px (image, +y down)."""

    def __init__(self, bounds, size, offset):
        xmin, ymin, xmax, ymax = bounds
        w, h = max(xmax - xmin, 1e-6), max(ymax - ymin, 1e-6)
        self.scale = size / max(w, h)
        self.xmin, self.ymax = xmin, ymax
        self.offset = offset
        self.width, self.height = w * self.scale, h * self.scale

    def __call__(self, pts: np.ndarray) -> np.ndarray:
        pts = np.atleast_2d(pts)
        return np.c_[self.offset[0] + (pts[:, 0] - self.xmin) * self.scale,
                     self.offset[1] + (self.ymax - pts[:, 1]) * self.scale]


def _dashes(a: np.ndarray, b: np.ndarray, dash: float, gap: float) -> list[tuple[np.ndarray, np.ndarray]]:
    length = float(np.hypot(*(b - a)))
    if length == 0:
        return []
    out, s = [], 0.0
    while s < length:
        e = min(s + dash, length)
        out.append((a + (b - a) * s / length, a + (b - a) * e / length))
        s = e + gap
    return out


def _layout(scene: _Scene):
    """Main view, bed thumbnail, canvas size and the panel's y positions (bar, thumb label)."""
    xmin, ymin, xmax, ymax = scene.bounds
    pad = 0.04 * max(xmax - xmin, ymax - ymin, 1.0)
    view = _View((xmin - pad, ymin - pad, xmax + pad, ymax + pad), MAIN, (MARGIN, MARGIN))
    x0 = MARGIN * 2 + view.width + 10
    bar_y = MARGIN + 22 * len(scene.text) + 6
    label_y = bar_y + 30
    bw, bh = scene.bed
    side = PANEL - 60
    thumb = _View((0.0, 0.0, bw, bh), side, (x0, label_y + 24))
    width = int(x0 + PANEL)
    height = int(max(MARGIN * 2 + view.height, label_y + 24 + thumb.height + MARGIN))
    return view, thumb, width, height, x0, bar_y, label_y


def _render_png(scene: _Scene, path: Path) -> None:
    view, thumb, width, height, x0, bar_y, label_y = _layout(scene)
    image = Image.new("RGB", (width, height), "white")
    font = ImageFont.load_default(size=15)
    # the main view gets its own image so that the bed outline is clipped to it
    main = Image.new("RGB", (int(MARGIN * 2 + view.width), height), "white")
    draw = ImageDraw.Draw(main)
    bw, bh = scene.bed
    bed = view(np.array([[0, 0], [bw, 0], [bw, bh], [0, bh], [0, 0]]))
    draw.line([tuple(p) for p in bed.tolist()], fill=(150, 150, 150), width=2)
    for seg in scene.travel:
        a, b = view(seg)
        for p, q in _dashes(a, b, 6.0, 5.0):
            draw.line([tuple(p), tuple(q)], fill=(140, 140, 140), width=1)
    for pts, colours in scene.burn:
        px = view(pts).tolist()
        # one call per run of equal colour: PIL draws a polyline segment by segment, so the
        # pixels are those of one call per segment
        change = np.flatnonzero(np.r_[True, np.any(colours[1:] != colours[:-1], axis=1), True])
        for s, e in zip(change[:-1].tolist(), change[1:].tolist()):
            draw.line([tuple(p) for p in px[s:e + 1]], fill=tuple(int(c) for c in colours[s]), width=2)
    o = view(np.zeros(2))[0]
    draw.line([(o[0] - 8, o[1]), (o[0] + 8, o[1])], fill="black", width=2)
    draw.line([(o[0], o[1] - 8), (o[0], o[1] + 8)], fill="black", width=2)
    if scene.start is not None:
        s = view(scene.start)[0]
        draw.ellipse([s[0] - 9, s[1] - 9, s[0] + 9, s[1] + 9], outline=(0, 160, 60), width=3)
        draw.text((s[0] + 11, s[1] - 20), "start", fill=(0, 130, 50), font=font)
    image.paste(main, (0, 0))
    draw = ImageDraw.Draw(image)
    draw.line([(main.width, 0), (main.width, height)], fill=(220, 220, 220), width=1)
    for i, line in enumerate(scene.text):
        draw.text((x0, MARGIN + 22 * i), line, fill="black", font=font)
    ramp = order_colours(np.linspace(0, 1, PANEL - 60))
    for i, c in enumerate(ramp):
        draw.line([(x0 + i, bar_y), (x0 + i, bar_y + 12)], fill=tuple(int(v) for v in c))
    tb = thumb(np.array([[0, 0], [bw, 0], [bw, bh], [0, bh], [0, 0]]))
    draw.line([tuple(p) for p in tb.tolist()], fill=(90, 90, 90), width=1)
    xmin, ymin, xmax, ymax = scene.bounds
    jb = thumb(np.array([[xmin, ymin], [xmax, ymax]]))
    draw.rectangle([min(jb[:, 0]), min(jb[:, 1]), max(max(jb[:, 0]), min(jb[:, 0]) + 1),
                    max(max(jb[:, 1]), min(jb[:, 1]) + 1)], outline=(200, 40, 40), width=2)
    draw.text((x0, label_y), "the job on the bed", fill="black", font=font)
    with atomic_open(path, "wb") as handle:
        image.save(handle, format="PNG")


def _render_svg(scene: _Scene, path: Path) -> None:
    view, thumb, width, height, x0, bar_y, label_y = _layout(scene)
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
           f'viewBox="0 0 {width} {height}">', f'<rect width="{width}" height="{height}" fill="white"/>']

    def poly(px, **attrs):
        pts = " ".join(f"{x:.2f},{y:.2f}" for x, y in px.tolist())
        extra = " ".join(f'{k.replace("_", "-")}="{v}"' for k, v in attrs.items())
        return f'<polyline points="{pts}" fill="none" {extra}/>'

    bw, bh = scene.bed
    main_w = MARGIN * 2 + view.width
    out.append(f'<clipPath id="main"><rect width="{main_w:.1f}" height="{height}"/></clipPath>')
    out.append('<g clip-path="url(#main)">')
    out.append(poly(view(np.array([[0, 0], [bw, 0], [bw, bh], [0, bh], [0, 0]])), stroke="#969696", stroke_width=2))
    for seg in scene.travel:
        out.append(poly(view(seg), stroke="#8c8c8c", stroke_width=1, stroke_dasharray="6 5"))
    for pts, colours in scene.burn:
        px = view(pts)
        # one polyline per run of equal colour keeps the file small
        change = np.r_[True, np.any(colours[1:] != colours[:-1], axis=1)]
        starts = np.flatnonzero(change)
        for i, s in enumerate(starts.tolist()):
            e = starts[i + 1] if i + 1 < len(starts) else len(colours)
            c = colours[s]
            out.append(poly(px[s:e + 1], stroke="#%02x%02x%02x" % tuple(int(v) for v in c), stroke_width=2,
                            stroke_linecap="round", stroke_linejoin="round"))
    o = view(np.zeros(2))[0]
    out.append(f'<path d="M{o[0] - 8:.1f},{o[1]:.1f}h16M{o[0]:.1f},{o[1] - 8:.1f}v16" stroke="black" stroke-width="2"/>')
    if scene.start is not None:
        s = view(scene.start)[0]
        out.append(f'<circle cx="{s[0]:.2f}" cy="{s[1]:.2f}" r="9" fill="none" stroke="#00a03c" stroke-width="3"/>')
        out.append(f'<text x="{s[0] + 11:.1f}" y="{s[1] - 8:.1f}" font-family="sans-serif" font-size="15" '
                   f'fill="#008232">start</text>')
    out.append("</g>")
    for i, line in enumerate(scene.text):
        safe = line.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
        out.append(f'<text x="{x0:.1f}" y="{MARGIN + 22 * i + 14}" font-family="monospace" font-size="14">{safe}</text>')
    stops = "".join(f'<stop offset="{i / (len(_STOPS) - 1):.2f}" stop-color="#%02x%02x%02x"/>'
                    % tuple(int(round(255 * v)) for v in c) for i, c in enumerate(_STOPS))
    out.append(f'<defs><linearGradient id="order">{stops}</linearGradient></defs>')
    out.append(f'<rect x="{x0:.1f}" y="{bar_y}" width="{PANEL - 60}" height="12" fill="url(#order)"/>')
    out.append(f'<text x="{x0:.1f}" y="{label_y + 14}" font-family="monospace" font-size="14">'
               'the job on the bed</text>')
    tb = thumb(np.array([[0, 0], [bw, 0], [bw, bh], [0, bh], [0, 0]]))
    out.append(poly(tb, stroke="#5a5a5a", stroke_width=1))
    xmin, ymin, xmax, ymax = scene.bounds
    jb = thumb(np.array([[xmin, ymin], [xmax, ymax]]))
    out.append(f'<rect x="{jb[:, 0].min():.2f}" y="{jb[:, 1].min():.2f}" width="{max(np.ptp(jb[:, 0]), 1):.2f}" '
               f'height="{max(np.ptp(jb[:, 1]), 1):.2f}" fill="none" stroke="#c82828" stroke-width="2"/>')
    out.append("</svg>")
    atomic_write_text(path, "\n".join(out) + "\n")


def render_gcode_preview(gcode: str | os.PathLike | Program, out_path: str | os.PathLike, *,
                         profile: LaserProfile | None = None, progress=None) -> JobTime:
    """Draw `gcode` (a G-code file, or a `Program` read already) into `out_path` (.png or
    .svg) and return its `JobTime`.

    profile: the machine (bed outline, time model); None uses the default profile.
    progress: an `onestroke.progress.ProgressCallback` (G-code lines read).
    """
    out_path = Path(out_path)
    suffix = out_path.suffix.lower()
    if suffix not in FORMATS:
        raise InputError(f"preview {str(out_path)!r} must end in {' or '.join(FORMATS)}")
    check_writable(out_path)
    profile = profile or load_laser_profile()
    program = gcode if isinstance(gcode, Program) else load_program(gcode)
    stats = analyze_program(program, settings=settings_from_profile(profile), planner_blocks=profile.planner_blocks,
                             progress=progress)
    if len(stats.moves) == 0:
        raise InputError(f"G-code file {program.source!r} holds no moves to preview")
    job = estimate_program_time(program, profile, stats=stats)
    scene = _scene(stats, job, profile, Path(program.source).name, program.n_lines)
    (_render_png if suffix == ".png" else _render_svg)(scene, out_path)
    return job

"""How long the same drawing would take as a raster engraving (the paper's Fig. 14 comparison).

The burned paths are drawn into a bitmap of `interval` mm pixels with the beam's line
width; each row with ink becomes one bidirectional scan, as raster senders do it
("skip blank" rows and margins): a G0 to the first ink of the row, then collinear G1
moves across it with the beam switched per run of ink (laser mode, so no stops). The
moves go through the same GRBL planner model as vector jobs (`machines.planner_model.plan_times`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from PIL import Image, ImageDraw

from fabrication.laser.gcode_write import FEED
from fabrication.laser.toolpath import Toolpath
from machines.grbl_settings import kinematics_from_profile
from machines.laser_profile import LaserProfile
from machines.planner_model import plan_times
from onestroke.errors import InputError
from onestroke.ranges import Range

# Row spacing of the compared raster engraving, mm; MAX_PIXELS bounds it from below per job.
INTERVAL = Range(0.001, 10.0, unit="mm", name="--raster-interval")
RASTER_FEED = FEED.named("--raster-feed")
MAX_PIXELS = 40_000_000


@dataclass(frozen=True)
class RasterTime:
    """seconds: planner-model time of the raster job; rows: scan lines with ink;
    interval: mm between rows; moves: G-code moves the raster job would hold."""

    seconds: float
    rows: int
    interval: float
    moves: int


def raster_time(toolpath: Toolpath, profile: LaserProfile, *, interval: float = 0.1, feed: float = 1500.0,
                line_width: float | None = None) -> RasterTime:
    """Time to raster-engrave the toolpath's lines at `interval` mm rows and `feed` mm/min.

    line_width: burned line width in mm (default: one interval, the finest line a raster
    of that interval can show).
    """
    INTERVAL.check(interval)
    RASTER_FEED.check(feed)
    width_mm = interval if line_width is None else line_width
    xmin, ymin, xmax, ymax = toolpath.bounds
    pad = width_mm
    cols = int(np.ceil((xmax - xmin + 2 * pad) / interval)) + 1
    rows = int(np.ceil((ymax - ymin + 2 * pad) / interval)) + 1
    if cols * rows > MAX_PIXELS:
        raise InputError(f"raster interval {interval:g} mm gives {cols} x {rows} pixels; use a larger interval")
    image = Image.new("1", (cols, rows), 0)
    draw = ImageDraw.Draw(image)
    px_width = max(1, int(round(width_mm / interval)))
    for path in toolpath.paths:
        pts = path.polyline()
        xy = np.c_[(pts[:, 0] - xmin + pad) / interval, (pts[:, 1] - ymin + pad) / interval]
        draw.line([tuple(p) for p in xy.tolist()], fill=1, width=px_width)
    ink = np.asarray(image, dtype=bool)
    # runs of ink per row: +1 where a run starts, -1 one past where it ends
    edges = np.diff(np.pad(ink.astype(np.int8), ((0, 0), (1, 1))), axis=1)
    starts_list, ends_list = [], []
    row_ids = np.flatnonzero(ink.any(axis=1))
    x_mm = lambda c: xmin - pad + c * interval  # noqa: E731
    points, rapid = [np.zeros(2)], []
    for n, r in enumerate(row_ids.tolist()):
        s = np.flatnonzero(edges[r] == 1)
        e = np.flatnonzero(edges[r] == -1)
        y = ymin - pad + r * interval
        # alternate direction so each row starts near where the last one ended
        xs = np.column_stack([s, e]).ravel().astype(float)
        if n % 2:
            xs = xs[::-1]
        xs = x_mm(xs)
        points.append(np.array([xs[0], y]))
        rapid.append(True)
        for x in xs[1:].tolist():
            points.append(np.array([x, y]))
            rapid.append(False)
    if len(points) < 2:
        return RasterTime(0.0, 0, interval, 0)
    pts = np.array(points)
    rapid_arr = np.array(rapid)
    seconds = plan_times(pts[:-1], pts[1:], np.full(len(rapid_arr), float(feed)), rapid_arr,
                         np.zeros(len(rapid_arr), dtype=bool), kinematics_from_profile(profile))
    return RasterTime(float(seconds.sum()), len(row_ids), interval, len(rapid_arr))

"""Preview PNG/SVG tell the truth of the G-code; raster-time comparison behaves."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pytest
from PIL import Image

from laser_fixtures import parse_gcode
from fabrication.laser.gcode_write import GcodeOptions, gcode_lines, write_gcode
from machines.job_time import estimate_job_time as estimate_gcode_time
from machines.job_time import format_duration
from fabrication.laser.preview import order_colours, render_gcode_preview
from fabrication.laser.raster_time import raster_time
from fabrication.laser.toolpath import ToolpathOptions, plan_toolpath
from fabrication.placement import PlacementOptions
from benchmarks.sets.laser_jobs import hershey_text_drawing, rose_drawing
from machines.laser_profile import load_laser_profile
from onestroke.errors import InputError

PROFILE = load_laser_profile()


@pytest.fixture(scope="module")
def job(tmp_path_factory):
    folder = tmp_path_factory.mktemp("job")
    tp = plan_toolpath(hershey_text_drawing("laser"), PROFILE,
                       ToolpathOptions(placement=PlacementOptions(size=80), arcs=True))
    lines = gcode_lines(tp, PROFILE, GcodeOptions())
    path = folder / "job.gcode"
    write_gcode(path, lines)
    return tp, lines, path


def _has_colour(pixels, rgb, tol=12):
    return bool((np.abs(pixels.astype(int) - np.array(rgb)).max(axis=2) <= tol).any())


def test_png_preview(job, tmp_path):
    tp, lines, path = job
    out = tmp_path / "p.png"
    result = render_gcode_preview(path, out)
    assert result.total_seconds == pytest.approx(estimate_gcode_time(lines, PROFILE).total_seconds)
    pixels = np.asarray(Image.open(out).convert("RGB"))
    assert pixels.shape[0] >= 400 and pixels.shape[1] >= 800
    assert _has_colour(pixels, (0, 160, 60))        # start ring
    assert _has_colour(pixels, (140, 140, 140), 3)  # dashed travel
    first, last = order_colours(np.array([0.02, 0.98]))
    assert _has_colour(pixels, first, 20) and _has_colour(pixels, last, 20)


def test_svg_preview_matches_the_file(job, tmp_path):
    tp, lines, path = job
    out = tmp_path / "p.svg"
    result = render_gcode_preview(path, out)
    root = ET.parse(out).getroot()
    ns = "{http://www.w3.org/2000/svg}"
    texts = " ".join(t.text or "" for t in root.iter(ns + "text"))
    assert format_duration(result.total_seconds) in texts
    dashed = [p for p in root.iter(ns + "polyline") if p.get("stroke-dasharray")]
    moves = parse_gcode(lines)
    travel = (~moves.laser_on) & (np.hypot(*(moves.end - moves.start).T) > 0)
    assert len(dashed) == int(travel.sum())
    coloured = {p.get("stroke") for p in root.iter(ns + "polyline") if p.get("stroke-linecap") == "round"}
    assert len(coloured) >= 10  # colours change along the job


def test_preview_refuses_bad_paths(job, tmp_path):
    _, _, path = job
    with pytest.raises(InputError, match=".png or .svg"):
        render_gcode_preview(path, tmp_path / "p.jpg")
    empty = tmp_path / "empty.gcode"
    empty.write_text("G21\nG90\n")
    with pytest.raises(InputError, match="no moves"):
        render_gcode_preview(empty, tmp_path / "p.png")
    with pytest.raises(InputError, match="does not exist"):
        render_gcode_preview(tmp_path / "missing.gcode", tmp_path / "p.png")
    assert not (tmp_path / "p.png").exists()


def test_preview_reads_foreign_gcode(tmp_path):
    # inches, relative moves, R arcs, spaces and comments, as other programs write them
    path = tmp_path / "other.nc"
    path.write_text("G20 G91 (inch, relative)\nM3 S500\nG0 X1 Y1\nG1 X1 F40\nG2 X1 Y-1 R1\nG90\nM5\n")
    out = tmp_path / "o.png"
    result = render_gcode_preview(path, out)
    assert out.exists() and result.burn_length == pytest.approx(25.4 + 25.4 * np.pi / 2, rel=1e-3)


def test_raster_takes_far_longer_than_vector():
    tp = plan_toolpath(rose_drawing(), PROFILE, ToolpathOptions(placement=PlacementOptions(size=60)))
    vector = estimate_gcode_time(gcode_lines(tp, PROFILE, GcodeOptions()), PROFILE).total_seconds
    coarse = raster_time(tp, PROFILE, interval=0.2, feed=1500.0)
    fine = raster_time(tp, PROFILE, interval=0.1, feed=1500.0)
    assert fine.seconds > 5 * vector
    assert fine.rows == pytest.approx(2 * coarse.rows, rel=0.05)
    assert fine.seconds == pytest.approx(2 * coarse.seconds, rel=0.15)
    with pytest.raises(InputError):
        raster_time(tp, PROFILE, interval=0.0)

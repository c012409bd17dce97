"""Previews tell the truth: real PNGs opened with Pillow (size, content, colours where the
thread, jumps, trims and hoop are), SVGs parsed as XML."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pytest
from PIL import Image

from benchmarks.sets.embroidery_designs import design
from fabrication.embroidery.export import write_embroidery
from fabrication.embroidery.plan import JUMP, STITCH, TRIM, PlanOptions, plan_embroidery, style_options
from fabrication.embroidery.preview import (PreviewOptions, render_drawing_preview, render_stitch_preview,
                                            stitch_canvas)
from fabrication.embroidery.read import read_embroidery
from fabrication.embroidery.stats import embroidery_stats
from machines.hoops import hoop_named
from onestroke.errors import InputError

HOOP = hoop_named("100x100")


@pytest.fixture(scope="module")
def plan():
    return plan_embroidery(design(), PlanOptions(style=style_options("running"), color=(200, 30, 40)))


DIAGNOSTIC = PreviewOptions(style="diagnostic")


def _pixel(image, canvas, point_mm):
    x, y = canvas.px(np.asarray(point_mm, float))
    return np.asarray(image)[int(round(y)), int(round(x))].astype(int)


def test_png_preview_size_and_content(plan, tmp_path):
    path = tmp_path / "p.png"
    render_stitch_preview(plan, path, hoop=HOOP, stats=embroidery_stats(plan), options=DIAGNOSTIC)
    with Image.open(path) as image:
        image.load()
        assert image.format == "PNG" and image.size == (1000, 1000)  # 108 x 108 mm shown
        pixels = np.asarray(image.convert("RGB")).reshape(-1, 3).astype(int)
        colours = image.convert("RGB").getcolors(1 << 20)
    background = np.array([250, 248, 243])
    assert (np.abs(pixels - background).sum(axis=1) > 30).mean() > 0.01
    assert len(colours) > 100
    wide = tmp_path / "wide.png"
    render_stitch_preview(plan, wide, options=PreviewOptions(width=640, margin=2.0, style="diagnostic"))
    xmin, ymin, xmax, ymax = plan.bounds()
    with Image.open(wide) as image:
        assert image.size == (640, round(640 * (ymax - ymin + 4) / (xmax - xmin + 4)))


def test_png_preview_shows_order_jumps_trims_and_hoop(plan, tmp_path):
    canvas = stitch_canvas(plan, hoop=HOOP, stats=None, options=DIAGNOSTIC)
    image = canvas.to_image()
    a, b = plan.stitches()
    first, last = (a[10] + b[10]) / 2, (a[-10] + b[-10]) / 2
    r, g, bl = _pixel(image, canvas, first)
    assert bl > r + 40  # the start of the curve is blue
    r, g, bl = _pixel(image, canvas, last)
    assert r > bl + 40  # its end is red
    # A jump is drawn dashed: along it some pixels are grey, some background.
    jump = int(np.flatnonzero(plan.kinds == JUMP)[0])
    start, end = plan.points[jump - 1], plan.points[jump]
    samples = [_pixel(image, canvas, start + (end - start) * f) for f in np.linspace(0.2, 0.8, 60)]
    grey = [abs(p[0] - p[2]) < 20 and p[0] < 200 for p in samples]
    assert 0.2 < np.mean(grey) < 0.9
    # Trims are red crosses; the hoop edge is a grey line.
    trim = plan.points[np.flatnonzero(plan.kinds == TRIM)[1]]
    x, y = canvas.px(trim)
    patch = np.asarray(image)[int(y) - 6:int(y) + 7, int(x) - 6:int(x) + 7].reshape(-1, 3).astype(int)
    assert ((patch[:, 0] > 180) & (patch[:, 1] < 110)).any()
    edge = _pixel(image, canvas, [0.0, -50.0])
    assert edge.max() < 170 and abs(edge[0] - edge[2]) < 15


def test_svg_preview_is_valid_xml(plan, tmp_path):
    path = tmp_path / "p.svg"
    render_stitch_preview(plan, path, hoop=HOOP, stats=embroidery_stats(plan),
                          options=PreviewOptions(width=800, style="diagnostic"))
    root = ET.parse(path).getroot()
    assert root.tag.endswith("svg") and root.get("width") == "800" and root.get("height") == "800"
    ns = "{http://www.w3.org/2000/svg}"
    paths = root.findall(f"{ns}path")
    assert len(paths) > 10
    assert any(p.get("stroke-dasharray") for p in paths)  # jumps
    assert any("stitches" in (t.text or "") for t in root.findall(f"{ns}text"))


def test_preview_of_a_file_read_back(plan, tmp_path):
    write_embroidery(plan, tmp_path / "d.dst")
    read = read_embroidery(tmp_path / "d.dst")
    stats = embroidery_stats(read.plan)
    assert stats.stitches == int((plan.kinds == STITCH).sum()) and stats.trims == 2
    render_stitch_preview(read.plan, tmp_path / "d.png", stats=stats)
    with Image.open(tmp_path / "d.png") as image:
        assert image.size[0] == 1000 and image.getbbox() is not None


def test_drawing_preview(tmp_path):
    render_drawing_preview(design(), tmp_path / "drawing.png", PreviewOptions(width=500))
    with Image.open(tmp_path / "drawing.png") as image:
        assert image.width == 500 and 300 < image.height < 700
        assert len(image.convert("RGB").getcolors(1 << 20)) > 50


def test_bad_preview_requests_write_nothing(plan, tmp_path):
    with pytest.raises(InputError, match="use .png or .svg"):
        render_stitch_preview(plan, tmp_path / "p.jpg")
    with pytest.raises(InputError):
        PreviewOptions(width=10)
    assert list(tmp_path.iterdir()) == []


def test_stats_box_takes_the_corner_with_fewest_stitches():
    from fabrication.embroidery.canvas import Canvas

    canvas = Canvas.fitting((0.0, 0.0, 100.0, 100.0), 1000)
    busy_top_left = np.random.default_rng(1).uniform(0, 30, (500, 2))
    canvas.text_box(["stitches  1", "thread    2 m"], avoid=busy_top_left)
    origin = canvas.items[-1][3]
    assert origin[0] > 500 and origin[1] < 50  # top-right, the first free corner
    canvas.text_box(["stitches  1"], avoid=np.zeros((0, 2)))
    assert canvas.items[-1][3] == (6.0, 6.0)

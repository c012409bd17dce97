"""Files an embroiderer can use as they are (issue 13): the same bytes every run, the hoop
and design name stored, SVG colours sewn as colour blocks with catalogue threads, a
chosen start, zigzag underlays. Real files written by the CLI, read back with pyembroidery."""

from __future__ import annotations

import time

import numpy as np
import pyembroidery
import pytest
from click.testing import CliRunner
from PIL import Image

from benchmarks.sets.embroidery_designs import FORMATS, THREE_COLOURS
from fabrication.cli import main
from fabrication.embroidery.export import jef_hoop_code
from fabrication.embroidery.needles import UNDERLAY
from fabrication.embroidery.plan import COLOR, STITCH, PlanOptions, plan_embroidery, style_options
from fabrication.embroidery.preview import FABRIC_COLOR, PreviewOptions, stitch_canvas
from fabrication.embroidery.thread import THREAD_CHARTS, nearest_thread
from fabrication.embroidery.zigzag import ZigzagOptions, zigzag_stitch
from vectorize.drawing import Drawing
from vectorize.stroke import Stroke

COLOUR_FORMATS = ("pes", "jef", "vp3")  # the formats that store thread colours


@pytest.fixture(scope="module")
def svg(tmp_path_factory):
    path = tmp_path_factory.mktemp("threads") / "flowers.svg"
    path.write_text(THREE_COLOURS)
    return path


def _run(*args):
    result = CliRunner().invoke(main, [str(a) for a in args])
    assert result.exit_code == 0, result.output
    return result


def test_two_runs_a_second_apart_give_the_same_bytes_in_every_format(svg, tmp_path, monkeypatch):
    monkeypatch.delenv("SOURCE_DATE_EPOCH", raising=False)
    first, second = {}, {}
    for runs, folder in ((first, tmp_path / "a"), (second, tmp_path / "b")):
        folder.mkdir()
        for ext in FORMATS:
            _run("embroider", svg, "-o", folder / f"d.{ext}", "--style", "zigzag", "--hoop", "5x7")
            runs[ext] = (folder / f"d.{ext}").read_bytes()
        time.sleep(1.1)  # pyembroidery alone stamps the current second into JEF
    assert first == second
    # A reproducible build's date goes into JEF instead of the fixed one.
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1767225600")  # 2026-01-01 00:00:00 UTC
    _run("embroider", svg, "-o", tmp_path / "dated.jef")
    assert (tmp_path / "dated.jef").read_bytes()[8:22] == b"20260101000000"
    assert first["jef"][8:22] == b"20000101000000"


@pytest.mark.parametrize("hoop, code", [("4x4", 0), ("5x7", 2), ("200x200", 4), ("126x110", 3)])
def test_jef_hoop_code_follows_the_hoop(svg, tmp_path, hoop, code):
    out = tmp_path / "d.jef"
    _run("embroider", svg, "-o", out, "--size", "40mm", "--hoop", hoop)
    assert int.from_bytes(out.read_bytes()[0x20:0x24], "little") == code
    assert pyembroidery.read(str(out)).count_stitches() > 50  # still a valid file


def _pes_hoop(data: bytes) -> tuple[int, tuple[int, int] | None]:
    """The hoop indicator and (version 6) the hoop size in mm of a .pes file, read after
    libpes' description of the header (not through our writer's code)."""
    indicator = int.from_bytes(data[12:14], "little")
    if data[:8] != b"#PES0060":
        return indicator, None
    at = 16  # the indicator, then two characters
    for _ in range(5):  # design, category, author, keywords, comments
        at += 1 + data[at]
    at += 4  # optimize hoop change, design page is custom
    return indicator, (int.from_bytes(data[at:at + 2], "little"), int.from_bytes(data[at + 2:at + 4], "little"))


@pytest.mark.parametrize("hoop, indicator, size", [("4x4", 0, (100, 100)), ("5x7", 1, (130, 180)),
                                                   ("200x200", 1, (200, 200)), ("6x10", 1, (160, 260)),
                                                   ("90x80", 0, (90, 80))])
def test_pes_header_hoop_follows_the_hoop(svg, tmp_path, hoop, indicator, size):
    """pyembroidery writes a 130x180 indicator and a 100x100 mm hoop size whatever the hoop."""
    for version in (6, 1):
        out = tmp_path / f"d{version}.pes"
        _run("embroider", svg, "-o", out, "--size", "40mm", "--hoop", hoop, "--pes-version", version)
        assert _pes_hoop(out.read_bytes()) == (indicator, size if version == 6 else None)
        back = pyembroidery.read(str(out))  # still a valid file, name and all
        assert back.count_stitches() > 50
        assert version == 1 or back.get_metadata("name") == "flowers"


def test_design_name_is_stored_where_the_format_has_room(svg, tmp_path):
    for ext in ("pes", "dst"):
        _run("embroider", svg, "-o", tmp_path / f"d.{ext}")
        assert pyembroidery.read(str(tmp_path / f"d.{ext}")).get_metadata("name") == "flowers"
        _run("embroider", svg, "-o", tmp_path / f"n.{ext}", "--name", "Rosé garden border")
        # Printable ASCII (fixed-width headers count bytes), 16 characters at most (DST).
        assert pyembroidery.read(str(tmp_path / f"n.{ext}")).get_metadata("name") == "Ros_ garden bord"


@pytest.mark.parametrize("chart", ["brother", "janome"])
def test_three_svg_colours_give_three_threads_and_two_changes(svg, tmp_path, chart):
    # Sewing order: red first (both red strokes), then navy, whose stroke starts nearest to
    # where the red block ends (90, 90), then green.
    threads = [nearest_thread(c, chart) for c in ((200, 30, 40), (0, 0, 128), (20, 120, 40))]
    for ext in FORMATS:
        out = tmp_path / f"d.{ext}"
        result = _run("embroider", svg, "-o", out, "--thread-chart", chart)
        pattern = pyembroidery.read(str(out))
        assert pattern.count_color_changes() == 2, ext
        if ext in COLOUR_FORMATS:
            assert len(pattern.threadlist) == 3, ext
        # The stats (on stderr) name the catalogue's number of each thread, with its counts.
        for thread in threads:
            assert f"{thread.chart} {thread.number} {thread.name}" in result.stderr
        assert result.stderr.count("stitches, ") == 3
    pes = pyembroidery.read(str(tmp_path / "d.pes"))
    assert [t.catalog_number for t in pes.threadlist] == [t.number for t in threads]
    assert [(t.get_red(), t.get_green(), t.get_blue()) for t in pes.threadlist] == [t.color for t in threads]


def test_strokes_of_one_colour_are_sewn_together(svg):
    from vectorize.svg.svg_read import read_svg

    drawing = read_svg(svg).as_drawing()
    placed = Drawing(tuple(s.transformed(np.array([[0.5, 0, -25], [0, 0.5, -25]])) for s in drawing.strokes),
                     50, 50, "mm")
    plan = plan_embroidery(placed, PlanOptions())
    assert plan.color_changes == 2 and len(plan.threads) == 3
    needles = plan.kinds == STITCH
    # Blocks only grow: each colour is sewn once, both red strokes in the first block.
    assert np.all(np.diff(plan.blocks) >= 0)
    assert [t.color for t in plan.threads][0] == (200, 30, 40)
    assert len(set(plan.strokes[needles & (plan.blocks == 0)])) == 2
    # --color as a list overrides the SVG's colours stroke by stroke (the last repeats).
    listed = plan_embroidery(placed, PlanOptions(colors=((0, 0, 0), (255, 255, 255))))
    assert [t.color for t in listed.threads] == [(0, 0, 0), (255, 255, 255)]
    assert (listed.kinds == COLOR).sum() == 1


def test_more_colours_than_strokes_are_warned_about(svg, tmp_path):
    result = _run("embroider", svg, "-o", tmp_path / "d.pes", "--color", "red,green,blue,black,white")
    assert "5 colours for 4 stroke(s)" in result.stderr


def test_every_pyembroidery_chart_picks_a_numbered_thread():
    for chart in THREAD_CHARTS:
        thread = nearest_thread((200, 30, 40), chart)
        assert thread.number and thread.name and thread.chart
    from onestroke.errors import InputError

    with pytest.raises(InputError, match="pyembroidery ships"):
        nearest_thread((0, 0, 0), "madeira")


def test_start_reverse_and_start_point():
    line = Drawing((Stroke.from_polyline(np.array([[-20.0, 0.0], [20.0, 0.0]])),), 40, 1, "mm")
    needles = lambda plan: plan.points[plan.kinds == STITCH]  # noqa: E731
    assert needles(plan_embroidery(line, PlanOptions()))[0][0] == pytest.approx(-20)
    assert needles(plan_embroidery(line, PlanOptions(start="reverse")))[0][0] == pytest.approx(20)
    assert needles(plan_embroidery(line, PlanOptions(start=(15.0, 3.0))))[0][0] == pytest.approx(20)
    # A closed curve opens at the point nearest to the start.
    t = np.linspace(0, 2 * np.pi, 65)
    ring = Drawing((Stroke.from_polyline(np.c_[10 * np.cos(t), 10 * np.sin(t)]),), 20, 20, "mm")
    first = needles(plan_embroidery(ring, PlanOptions(start=(0.0, 12.0))))[0]
    assert first == pytest.approx([0.0, 10.0], abs=0.1)


@pytest.mark.parametrize("kind", ["center", "edge", "zigzag", "none"])
def test_zigzag_underlays(kind):
    line = Stroke.from_polyline(np.array([[0.0, 0.0], [30.0, 0.0]]))
    options = ZigzagOptions(width=3.0, underlay=kind)
    needles = zigzag_stitch(line, options)
    under = needles.points[needles.roles == UNDERLAY]
    if kind == "none":
        assert not len(under)
        return
    assert np.allclose(under[[0, -1]], [0.0, 0.0])  # there and back: the zigzag starts at the start
    spread = np.abs(under[:, 1]).max()
    if kind == "center":
        assert spread < 1e-9
    else:
        # Edge walk and zigzag underlay stay 0.4 mm inside the 3 mm column's edges.
        assert spread == pytest.approx(1.5 - options.underlay_inset)
        assert (under[:, 1] > 0.5).any() and (under[:, 1] < -0.5).any()


def test_realistic_preview_is_thread_on_fabric_framed_to_the_design(svg, tmp_path):
    out, preview = tmp_path / "d.pes", tmp_path / "p.png"
    _run("embroider", svg, "-o", out, "--size", "40mm", "--hoop", "5x7", "--style", "triple",
         "--preview", preview)
    with Image.open(preview) as image:
        pixels = np.asarray(image.convert("RGB")).astype(int)
    h, w, _ = pixels.shape
    assert w == 1000 and 0.8 < h / w < 1.25  # the 40 x 40 mm design, not the 130 x 180 hoop
    assert (pixels[0, 0] == FABRIC_COLOR).all()
    # Each thread shows in its own colour (red, green, navy); no blue-to-red ramp.
    flat = pixels.reshape(-1, 3)
    for colour in ((200, 30, 40), (20, 120, 40), (0, 0, 128)):
        assert (np.abs(flat - colour).sum(axis=1) < 40).sum() > 200, colour
    # The hoop only when asked; the diagnostic style keeps it.
    svgplan = plan_embroidery(Drawing((Stroke.from_polyline(np.array([[0.0, 0.0], [10.0, 0.0]])),), 10, 1, "mm"),
                              PlanOptions(style=style_options("running")))
    from machines.hoops import hoop_named

    plain = stitch_canvas(svgplan, hoop=hoop_named("4x4"))
    framed = stitch_canvas(svgplan, hoop=hoop_named("4x4"), options=PreviewOptions(hoop=True))
    assert plain.view[2] - plain.view[0] < 20 and framed.view[2] - framed.view[0] > 100
    diagnostic = stitch_canvas(svgplan, hoop=hoop_named("4x4"), options=PreviewOptions(style="diagnostic"))
    assert diagnostic.view[2] - diagnostic.view[0] > 100


def test_jef_hoop_code_without_a_named_hoop_is_left_to_pyembroidery():
    plan = plan_embroidery(Drawing((Stroke.from_polyline(np.array([[0.0, 0.0], [10.0, 0.0]])),), 10, 1, "mm"))
    assert jef_hoop_code(plan) is None

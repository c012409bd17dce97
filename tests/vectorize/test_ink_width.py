"""The ink width along each stroke: measured by the vectorizer (vectorize/fit/ink_width.py),
carried by `Stroke.widths` through reversal, transforms and re-cutting, written to and read
back from SVG (`data-widths`) and JSON."""

from __future__ import annotations


import numpy as np
import pytest

from benchmarks.common.render import render, render_profile, to_uint8
from fabrication.embroidery.order import _open_at
from onestroke.errors import InputError
from vectorize.drawing import Drawing
from vectorize.pipeline import vectorize_image
from vectorize.stroke import Stroke
from vectorize.svg.svg_read import read_svg
from vectorize.svg_write import drawing_from_json, drawing_to_json, drawing_to_svg


def arc_stroke(widths=None) -> Stroke:
    """A half circle of radius 300 px as four cubic segments, centre (500, 500)."""
    angles = np.linspace(np.pi, 2 * np.pi, 5)
    k = 4 / 3 * np.tan((angles[1] - angles[0]) / 4)
    p = 500 + 300 * np.c_[np.cos(angles), np.sin(angles)]
    d = 300 * np.c_[-np.sin(angles), np.cos(angles)]
    control = np.stack([p[:-1], p[:-1] + k * d[:-1], p[1:] - k * d[1:], p[1:]], axis=1)
    return Stroke(control, None, widths)


PROFILE = np.array([[0.0, 4.0], [0.3, 12.0], [0.7, 12.0], [1.0, 6.0]])


def test_widths_follow_reversal_transforms_and_recutting():
    stroke = arc_stroke(PROFILE)
    t = np.linspace(0.0, 1.0, 41)
    back = stroke.reversed()
    assert np.allclose(back.widths_at(1.0 - t), stroke.widths_at(t))
    # a uniform scale by 0.5 and a rotation: widths halve, at the same places on the curve
    c, s = np.cos(0.7), np.sin(0.7)
    moved = stroke.transformed(np.array([[0.5 * c, -0.5 * s, 3.0], [0.5 * s, 0.5 * c, -2.0]]))
    assert np.allclose(moved.widths_at(t), 0.5 * stroke.widths_at(t))
    drawing = Drawing((stroke,), 1000, 1000).transformed(np.array([[0.1, 0, 0], [0, 0.1, 0]]), width=100,
                                                         height=100, unit="mm", stroke_width=1.0)
    assert np.allclose(drawing.strokes[0].widths_at(t), 0.1 * stroke.widths_at(t))
    assert arc_stroke().reversed().widths is None and arc_stroke().widths_at(0.5) is None


def test_a_closed_stroke_started_elsewhere_keeps_each_places_width():
    angles = np.linspace(0, 2 * np.pi, 7)
    k = 4 / 3 * np.tan((angles[1] - angles[0]) / 4)
    p = np.c_[np.cos(angles), np.sin(angles)] * 20
    d = np.c_[-np.sin(angles), np.cos(angles)] * 20
    control = np.stack([p[:-1], p[:-1] + k * d[:-1], p[1:] - k * d[1:], p[1:]], axis=1)
    closed = Stroke(control, None, np.array([[0.0, 1.0], [0.5, 3.0], [1.0, 1.0]]))
    for t0 in (0.2, 1 / 3, 0.77):  # inside a segment, on a joint, near the end
        opened = _open_at(closed, t0)
        t = np.linspace(0.0, 1.0, 60)
        points = opened.points_at(t)
        # the same place on the old curve: nearest of a dense sampling
        dense_t = np.linspace(0.0, 1.0, 20001)
        nearest = np.argmin(np.linalg.norm(closed.points_at(dense_t)[None] - points[:, None], axis=2), axis=1)
        assert np.allclose(opened.widths_at(t), closed.widths_at(dense_t[nearest]), atol=2e-3)


@pytest.mark.parametrize("widths, message", [
    ([[0.0, 1.0]], "shape"), ([[0.0, 1.0], [0.5, 2.0]], "rise strictly"),
    ([[0.0, 1.0], [0.6, 2.0], [0.6, 3.0], [1.0, 1.0]], "rise strictly"), ([[0.0, -1.0], [1.0, 1.0]], "lie in"),
    ([[0.0, np.nan], [1.0, 1.0]], "finite")])
def test_bad_width_profiles_are_refused(widths, message):
    with pytest.raises(InputError, match=message):
        arc_stroke(widths)


def test_svg_and_json_carry_the_widths_and_read_them_back(tmp_path):
    stroke = arc_stroke(PROFILE)
    drawing = Drawing((stroke, arc_stroke()), 1000, 1000, "px", 8.0)
    svg = drawing_to_svg(drawing)
    assert svg.count("data-widths=") == 1  # the second stroke's widths are unknown
    (tmp_path / "d.svg").write_text(svg)
    back = read_svg(tmp_path / "d.svg").as_drawing()
    assert np.allclose(back.strokes[0].widths, PROFILE, atol=1e-6) and back.strokes[1].widths is None
    again = drawing_from_json(drawing_to_json(drawing))
    assert np.allclose(again.strokes[0].widths, PROFILE) and again.strokes[1].widths is None
    # without widths the JSON is what it was before widths existed: no "widths" key
    assert '"widths"' not in drawing_to_json(Drawing((arc_stroke(),), 1000, 1000))


def test_svg_widths_are_scaled_by_the_viewbox_and_transforms(tmp_path):
    placed = Drawing((arc_stroke(PROFILE),), 1000, 1000).transformed(
        np.array([[0.1, 0, 0], [0, 0.1, 0]]), width=100, height=100, unit="mm", stroke_width=0.8)
    svg = drawing_to_svg(placed).replace("<g ", '<g transform="scale(2)" ', 1)
    (tmp_path / "mm.svg").write_text(svg)
    back = read_svg(tmp_path / "mm.svg").as_drawing()  # px at 96 dpi, the group's scale applied
    assert np.allclose(back.strokes[0].widths[:, 1], PROFILE[:, 1] * 0.1 * 2 * 96 / 25.4, rtol=1e-5)


def test_svg_widths_stay_on_their_pieces_when_a_zero_length_piece_is_dropped(tmp_path):
    # three pieces, the middle one of zero length: the reader keeps two
    svg = ('<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100">'
           '<path stroke="#000" data-widths="0 2 0.3333333 2 0.6666667 8 1 8" '
           'd="M0 0C10 0 20 0 30 0C30 0 30 0 30 0C40 0 50 0 60 0"/></svg>')
    (tmp_path / "z.svg").write_text(svg)
    stroke = read_svg(tmp_path / "z.svg").strokes[0]
    assert stroke.segment_count == 2
    assert stroke.widths_at(0.25) == pytest.approx(2.0) and stroke.widths_at(0.75) == pytest.approx(8.0)


@pytest.mark.parametrize("text", ['data-widths="0 2 1"', 'data-widths="0 2 0.5 x 1 3"', 'data-widths="0.1 2 1 3"'])
def test_malformed_svg_widths_name_the_element(tmp_path, text):
    (tmp_path / "bad.svg").write_text(f'<svg xmlns="http://www.w3.org/2000/svg" width="10" height="10">'
                                      f'<path id="p7" stroke="#000" {text} d="M0 0L9 9"/></svg>')
    with pytest.raises(InputError, match="<path id='p7'>.*data-widths"):
        read_svg(tmp_path / "bad.svg")


@pytest.mark.parametrize("width", [3.0, 6.0, 12.0])
def test_a_constant_line_measures_its_drawn_width(width):
    # anti-aliased, slanted: the outline at Li's threshold lies inside the visible edge,
    # which the edge offset puts back
    line = Drawing((Stroke.from_polyline(np.array([[100.0, 420.0], [900.0, 580.0]])),), 1000, 1000, "px", width)
    result = vectorize_image(to_uint8(render(line)))
    stroke = result.drawing.strokes[0]
    measured = stroke.widths_at(np.linspace(0.1, 0.9, 81))
    assert np.median(measured) == pytest.approx(width, abs=0.25)
    assert np.abs(measured - width).max() < 0.1 * width + 0.2


def test_a_brush_line_measures_its_width_profile():
    stroke = arc_stroke()
    truth = Drawing((stroke,), 1000, 1000, "px", 24.0)
    profile = (np.array([0.0, 0.1, 0.5, 0.8, 1.0]), np.array([8.0, 24.0, 16.0, 24.0, 8.0]))
    result = vectorize_image(to_uint8(render_profile(truth, profile)))
    (out,) = result.drawing.strokes
    s = np.linspace(0.0, out.length, 400)
    t = out.parameters_at_lengths(s)
    # the drawn width where each output point lies: nearest point of the drawn curve
    dense = stroke.sample_evenly(0.25)
    nearest = np.argmin(np.linalg.norm(dense[None] - out.points_at(t)[:, None], axis=2), axis=1)
    drawn = np.interp(nearest / (len(dense) - 1), *profile)
    error = np.abs(out.widths_at(t) - drawn)
    assert np.mean(error <= 0.1 * drawn) >= 0.95
    assert len(out.widths) < 60  # a few rows per change of width, not one per sample


@pytest.mark.parametrize("name", ["loops", "touch-drawing", "spike-drawing"])
def test_edge_offset_read_in_chunks_is_the_whole_profiles(name, monkeypatch):
    """`edge_offset` reads the normals a few steps at a time for the points not crossed yet:
    the same number as reading every step for every point at once (one chunk)."""
    from pathlib import Path

    from vectorize.fit import ink_width
    from vectorize.raster.binarize import ink_image, paper_gray
    from vectorize.raster.image_io import load_image
    from vectorize.raster.outline import outline_rings

    examples = Path(__file__).resolve().parents[2] / "examples"
    path = examples / f"{name}.png"
    image, _ = load_image(path, max_size=1000)
    for blur in (0.0, 1.5):
        gray, scale = paper_gray(image, max_size=1000, blur=blur)
        ink = ink_image(gray, scale, threshold=None)
        rings = outline_rings(ink.gray, ink.threshold, float(np.clip(ink.stroke_width / 8.0, 0.3, 1.0)))
        args = (ink.gray, ink.ink, rings, ink.threshold, ink.stroke_width)
        chunked = ink_width.edge_offset(*args)
        monkeypatch.setattr(ink_width, "EDGE_CHUNK", 10_000)
        assert ink_width.edge_offset(*args) == chunked
        monkeypatch.undo()


def test_paper_median_without_sorting_is_numpys():
    from vectorize.fit.ink_width import _median_where

    rng = np.random.default_rng(3)
    for n in (1, 2, 3, 4, 5, 10, 11, 1000, 1001):
        for top_share in (0.0, 0.4, 0.5, 0.6, 0.9, 1.0):
            for kept in (0.0, 0.5, 0.9, 1.0):  # the share of values asked for (the paper's)
                values = rng.random(n).astype(np.float32)
                values[rng.random(n) < top_share] = 1.0
                where = rng.random(n) < kept
                expected = float(np.median(values[where])) if where.any() else 1.0
                assert _median_where(values, where) == expected, (n, top_share, kept)
                grid = values[: n - n % 2].reshape(2, -1)[:, ::2]  # a strided 2-D view, as edge_offset reads
                mask = where[: n - n % 2].reshape(2, -1)[:, ::2]
                expected = float(np.median(grid[mask])) if mask.any() else 1.0
                assert _median_where(grid, mask) == expected, (n, top_share, kept)

"""Stitch geometry, measured on files read back: running-stitch chords and corners, triple
passes, zigzag width / spacing / inner curves, arrow motifs along the one curve."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks.sets.embroidery_designs import design, spiral
from benchmarks.metrics.stitches import needle_runs, stroke_rows
from fabrication.embroidery.arrows import ArrowOptions, arrow_stitch
from fabrication.embroidery.export import write_embroidery
from fabrication.embroidery.needles import BODY, LOCK, MOTIF, TACK, UNDERLAY
from fabrication.embroidery.plan import JUMP, STITCH, TRIM, PlanOptions, plan_embroidery, style_options
from fabrication.embroidery.read import read_embroidery
from fabrication.embroidery.running import RunningOptions, running_stitch
from fabrication.embroidery.triple import TripleOptions, triple_stitch
from fabrication.embroidery.zigzag import ZigzagOptions, zigzag_stitch
from onestroke.errors import InputError
from vectorize.drawing import Drawing
from vectorize.stroke import Stroke


def _roundtrip(drawing, style, tmp_path, ext="dst", **plan_kw):
    plan = plan_embroidery(drawing, PlanOptions(style=style, **plan_kw))
    path = tmp_path / f"check.{ext}"
    write_embroidery(plan, path)
    back = read_embroidery(path).plan
    needles = back.points[back.kinds == STITCH]
    assert np.array_equal(np.rint(needles * 10), np.rint(plan.points[plan.kinds == STITCH] * 10))
    return plan, needles


def _segment_distance(p, a, b):
    ab = b - a
    u = np.clip(((p - a) @ ab) / max(ab @ ab, 1e-12), 0, 1)
    return np.linalg.norm(p - (a + u[:, None] * ab), axis=1)


def _body_path(plan, rows):
    """Rows of the stroke's body from its start to its end (tack and lock left out)."""
    return rows[4:len(rows) - 4]


# -- running stitch ---------------------------------------------------------------------
@pytest.mark.parametrize("stitch_length", [2.5, 6.0])
def test_running_chords_stay_within_tolerance_of_the_curve(stitch_length, tmp_path):
    drawing = design()
    plan, needles = _roundtrip(drawing, RunningOptions(stitch_length=stitch_length), tmp_path)
    index = {row: i for i, row in enumerate(np.flatnonzero(plan.kinds == STITCH))}
    worst = 0.0
    for stroke_index, rows in stroke_rows(plan).items():
        stroke = drawing.strokes[stroke_index]
        body = _body_path(plan, rows)
        t = plan.params[body] - stroke_index
        assert np.all(np.diff(t) > 0)
        pts = needles[[index[r] for r in body]]
        for i in range(len(body) - 1):
            curve = stroke.points_at(np.linspace(t[i], t[i + 1], 64))
            worst = max(worst, float(_segment_distance(curve, pts[i], pts[i + 1]).max()))
    assert worst <= 0.2 + 1e-9, worst
    a, b = plan.stitches()
    assert np.linalg.norm(b - a, axis=1).max() <= stitch_length + 0.15


def test_running_puts_a_needle_point_on_every_sharp_corner(tmp_path):
    # A polyline with turns of 30, 60, 90, 120 and 150 degrees, plus the S-curve's corner.
    headings = np.radians(np.cumsum([0, 30, -60, 90, -120, 150]))
    legs = np.array([5.3, 6.1, 4.7, 7.9, 5.5, 6.6])
    pts = np.vstack([[-20.0, 0.0], [-20.0, 0.0] + np.cumsum(legs[:, None] * np.c_[np.cos(headings),
                                                                                 np.sin(headings)], axis=0)])
    drawing = Drawing((Stroke.from_polyline(pts), design().strokes[0]), 80, 80, "mm")
    plan, needles = _roundtrip(drawing, RunningOptions(), tmp_path)
    corners = [p for i, p in enumerate(pts[1:-1], 1) if abs((np.degrees(
        np.arctan2(*(pts[i + 1] - p)[::-1]) - np.arctan2(*(p - pts[i - 1])[::-1])) + 180) % 360 - 180) > 45]
    corners.append(np.array([35.0, -20.0]))  # the S-curve's kink (measured ~120 degrees)
    assert len(corners) == 5
    for corner in corners:
        assert np.linalg.norm(needles - corner, axis=1).min() <= 0.1 + 1e-9, corner


def test_running_stitches_are_equal_within_a_piece():
    for length, expected in [(10.0, [2.5] * 4), (11.0, [2.2] * 5), (2.0, [2.0])]:
        stroke = Stroke.from_polyline(np.array([[0.0, 0.0], [length, 0.0]]))
        pts = running_stitch(stroke, RunningOptions()).points
        assert np.allclose(np.linalg.norm(np.diff(pts, axis=0), axis=1), expected)
    # On a circle of radius 2 mm the tolerance, not the 2.5 mm target, sets the length.
    circle = spiral(0, 0, 2.0, 2.0, 1.0, n=16)
    lengths = np.linalg.norm(np.diff(running_stitch(circle, RunningOptions()).points, axis=0), axis=1)
    # sqrt(8 R tol') with tol' = 0.2 mm less the snap and sampling reserve: 1.38 mm
    assert lengths.max() < 1.4 and np.ptp(lengths) < 0.05


def test_running_options_refuse_bad_values():
    for kw in (dict(stitch_length=0), dict(stitch_length=-1), dict(tolerance=0.05), dict(corner_angle=0)):
        with pytest.raises(InputError):
            RunningOptions(**kw)


# -- triple stitch ------------------------------------------------------------------------
@pytest.mark.parametrize("repeats", [1, 2])
def test_triple_goes_back_and_forth_over_every_stitch_in_fresh_holes(repeats):
    stroke = Stroke.from_polyline(np.array([[0.0, 0.0], [10.0, 0.0]]))
    base = running_stitch(stroke).points[:, 0]  # 0, 2.5, 5, 7.5, 10
    pts = triple_stitch(stroke, TripleOptions(repeats=repeats)).points
    shift = TripleOptions().shift
    expected, here = [0.0], 0.0
    for k in range(1, len(base)):
        expected.append(base[k])
        last = k == len(base) - 1
        for r in range(1, repeats + 1):
            expected += [here + r * shift, base[k] + (-r if last else r) * shift]
        here = expected[-1]
    assert np.allclose(pts[:, 0], expected) and np.allclose(pts[:, 1], 0.0)
    # Forward, back, forward: 1 + 2 x repeats layers of thread over the line, each pass
    # shorter by the shifts of its holes.
    thread = np.abs(np.diff(pts[:, 0])).sum()
    assert 0.6 * (1 + 2 * repeats) * 10.0 < thread < (1 + 2 * repeats) * 10.0
    # No hole is pierced again within the next four penetrations.
    for lag in range(1, 5):
        assert np.abs(pts[lag:, 0] - pts[:-lag, 0]).min() >= shift - 1e-9


def test_triple_file_holds_three_layers_without_repeated_holes(tmp_path):
    plan, needles = _roundtrip(design(), TripleOptions(), tmp_path, ext="pes")
    body = plan.roles[plan.kinds == STITCH] == BODY
    a, b = plan.stitches()
    sewn = np.linalg.norm(b - a, axis=1).sum()
    assert sewn > 2.4 * design().length  # three layers, each pass shorter by its shifted holes
    pts = needles[body]
    for lag in range(2, 5):
        assert np.linalg.norm(pts[lag:] - pts[:-lag], axis=1).min() >= 0.2 - 1e-9


# -- zigzag ------------------------------------------------------------------------------
@pytest.mark.parametrize("angle", [0.0, 30.0, 90.0, 137.0])
@pytest.mark.parametrize("width,comp", [(2.0, 0.2), (3.0, 0.4), (1.2, 0.0)])
def test_zigzag_width_and_spacing_on_straight_lines(angle, width, comp, tmp_path):
    direction = np.array([np.cos(np.radians(angle)), np.sin(np.radians(angle))])
    normal = np.array([-direction[1], direction[0]])
    line = Stroke.from_polyline(np.array([-15 * direction, 15 * direction]))
    options = ZigzagOptions(width=width, pull_compensation=comp)
    plan, needles = _roundtrip(Drawing((line,), 30, 30, "mm"), options, tmp_path)
    body = needles[plan.roles[plan.kinds == STITCH] == BODY]
    along = body @ direction
    middle = body[(along > -13) & (along < 13)]
    across = np.abs(np.diff(middle @ normal))
    assert np.abs(across - (width + comp)).max() <= 0.15, across
    spacing = np.abs((middle[2:] - middle[:-2]) @ direction)
    assert abs(spacing.mean() - 0.4) <= 0.04, spacing.mean()
    # Single pairs can only be as exact as the files' 0.1 mm grid allows.
    assert np.abs(spacing - 0.4).max() <= 0.1 * np.sqrt(2) + 1e-9


@pytest.mark.parametrize("radius", [1.5, 2.0, 3.0, 5.0])
@pytest.mark.parametrize("width", [2.0, 3.0])
def test_zigzag_inner_curves_keep_needle_points_apart(radius, width, tmp_path):
    arc = spiral(0, 0, radius, radius, 0.75, n=12)
    plan, needles = _roundtrip(Drawing((arc,), 20, 20, "mm"), ZigzagOptions(width=width), tmp_path)
    roles = plan.roles[plan.kinds == STITCH]
    pts = needles[np.isin(roles, (BODY, UNDERLAY))]
    d = np.linalg.norm(pts[:, None] - pts[None], axis=2)
    np.fill_diagonal(d, np.inf)
    assert d.min() >= 0.1, d.min()


def test_zigzag_underlay_only_when_wide_and_points_alternate_sides():
    line = Stroke.from_polyline(np.array([[0.0, 0.0], [20.0, 0.0]]))
    narrow = zigzag_stitch(line, ZigzagOptions(width=1.2))
    wide = zigzag_stitch(line, ZigzagOptions(width=2.0))
    assert not (narrow.roles == UNDERLAY).any()
    under = wide.points[wide.roles == UNDERLAY]
    assert len(under) > 10 and np.allclose(under[:, 1], 0) and np.allclose(under[-1], [0, 0])
    assert (wide.roles[:len(under)] == UNDERLAY).all()  # underlay first, then the zigzag
    zig = narrow.points
    assert len(zig) % 2 == 0
    assert np.all(np.sign(zig[:, 1]) == np.where(np.arange(len(zig)) % 2 == 0, 1, -1))


def test_zigzag_options_refuse_bad_values():
    for kw in (dict(width=0), dict(width=-2), dict(spacing=0), dict(spacing=0.05),
               dict(pull_compensation=-0.1), dict(short_stitch_inset=1.0)):
        with pytest.raises(InputError):
            ZigzagOptions(**kw)


# -- arrows ------------------------------------------------------------------------------
def _motifs(points, roles):
    """(M, 4, 2) motif points [left, tip, right, leave] and the walk point before each."""
    idx = np.flatnonzero(roles == MOTIF)
    groups = idx.reshape(-1, 4)
    assert np.all(np.diff(groups, axis=1) == 1)
    return points[groups], points[groups[:, 0] - 1]


def test_arrows_point_along_the_curve_and_are_sewn_continuously(tmp_path):
    stroke = design().strokes[0]
    plan, needles = _roundtrip(Drawing((stroke,), 80, 80, "mm"), ArrowOptions(), tmp_path)
    assert len(needle_runs(plan)) == 1 and not (plan.kinds != STITCH).any()
    roles = plan.roles[plan.kinds == STITCH]
    motifs, before = _motifs(needles, roles)
    assert len(motifs) == int((stroke.length - 2.0) // 5.0) + 1
    left, tip, right, leave = motifs.transpose(1, 0, 2)
    # The walk arrives 0.35 mm before the tip, the arms meet at it, the walk leaves 0.35 mm
    # past it: three fresh holes instead of one pierced three times (0.1 mm grid allowed).
    shift = ArrowOptions().shift
    assert np.allclose(np.linalg.norm(tip - before, axis=1), shift, atol=0.15)
    assert np.allclose(np.linalg.norm(leave - tip, axis=1), shift, atol=0.15)
    assert np.linalg.norm(leave - before, axis=1).min() > 0.5
    base = (left + right) / 2
    params = plan.params[plan.kinds == STITCH][roles == MOTIF].reshape(-1, 4)[:, 1]
    tangent = stroke.tangents_at(params)
    assert np.all(np.einsum("ij,ij->i", tip - base, tangent) > 0.5)  # tips lead the way
    spread = np.linalg.norm(left - right, axis=1)
    assert np.median(spread) == pytest.approx(2.5, abs=0.15)
    stitches = np.linalg.norm(np.diff(needles, axis=0), axis=1)
    assert stitches.max() <= 2.5 + 2 * shift + 0.15  # no travel: the thread never leaves the curve


def test_arrows_shrink_on_tight_curves():
    tight = spiral(0, 0, 1.5, 12.0, 3.0, n=36)
    walk = arrow_stitch(tight, ArrowOptions())
    motifs, _ = _motifs(walk.points, walk.roles)
    spread = np.linalg.norm(motifs[:, 0] - motifs[:, 2], axis=1)
    tips = motifs[:, 1]
    radius = np.linalg.norm(tips, axis=1)
    assert spread[np.argmin(radius)] < 0.75 * 2.5  # the innermost, on a ~2 mm radius
    assert np.allclose(spread[radius > 6], 2.5)  # full size where the radius is large
    assert spread.min() >= 0.4 * 2.5 - 1e-9


def test_arrow_rhythm_continues_across_strokes():
    a = Stroke.from_polyline(np.array([[0.0, 0.0], [7.0, 0.0]]))
    b = Stroke.from_polyline(np.array([[0.0, 10.0], [12.0, 10.0]]))
    options = ArrowOptions(size=2.0, spacing=5.0)
    first = arrow_stitch(a, options, offset=0.0)
    second = arrow_stitch(b, options, offset=a.length)
    tips_a = _motifs(first.points, first.roles)[0][:, 1, 0]
    tips_b = _motifs(second.points, second.roles)[0][:, 1, 0]
    assert np.allclose(tips_a, [2.0, 7.0])
    assert np.allclose(tips_b, [5.0, 10.0])  # 12 and 17 mm into the drawing, not restarted
    # Through the planner too: the second stroke's motifs keep the global rhythm.
    plan = plan_embroidery(Drawing((a, b), 20, 20, "mm"), PlanOptions(style=options))
    rows = np.flatnonzero((plan.kinds == STITCH) & (plan.roles == MOTIF) & (plan.strokes == 1))
    assert np.allclose(np.unique(plan.points[rows.reshape(-1, 4)[:, 1], 0]), [5.0, 10.0])


def test_arrow_options_refuse_bad_values():
    for kw in (dict(size=0), dict(width=-1), dict(spacing=1.0, size=2.0), dict(min_scale=0)):
        with pytest.raises(InputError):
            ArrowOptions(**kw)


def test_zigzag_short_stitches_inset_every_other_inner_point():
    radius = 2.5  # inner rail gap 0.4 x (1 - 1.1 / 2.5) = 0.22 mm < 0.35 mm
    arc = spiral(0, 0, radius, radius, 0.5, n=8)
    zig = zigzag_stitch(arc, ZigzagOptions(width=2.0, underlay=False))
    offset = np.linalg.norm(zig.points, axis=1) - radius  # + outside, - inside
    inner = -offset[offset < 0][3:-3]
    assert set(np.round(inner, 2)) == {1.1, round(1.1 * 0.7, 2)}  # full reach and 30 % inset
    assert np.all(np.abs(np.diff(np.round(inner, 2))) > 0.1)  # they alternate
    outer = offset[offset > 0]
    assert np.allclose(outer, 1.1, atol=0.01)
    straight = zigzag_stitch(Stroke.from_polyline(np.array([[0.0, 0.0], [10.0, 0.0]])),
                             ZigzagOptions(width=2.0, underlay=False))
    assert np.allclose(np.abs(straight.points[:, 1]), 1.1)  # no inset on straight parts

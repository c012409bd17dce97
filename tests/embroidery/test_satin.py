"""The satin style: a column as wide as the drawn line (the stroke's ink widths, scaled with
the design), its controls (width scale and limits, pull compensation, underlays, short
stitches, split stitches, random width and phase), its corners (mitred or split, cut back
under the column sewn on top), and the files it writes."""

from __future__ import annotations


import numpy as np
import pytest

from benchmarks.metrics.columns import sewn_widths, slits
from benchmarks.sets.embroidery_designs import FORMATS, spiral
from fabrication.embroidery.export import write_embroidery
from fabrication.embroidery.needles import BODY, UNDERLAY
from fabrication.embroidery.plan import STITCH, PlanOptions, plan_embroidery, style_options
from fabrication.embroidery.quality import needle_density, repeated_holes
from fabrication.embroidery.satin import SatinOptions, satin_stitch
from fabrication.embroidery.stats import embroidery_stats
from onestroke.errors import InputError
from vectorize.drawing import Drawing
from vectorize.stroke import Stroke


def line(widths=None, length=30.0) -> Stroke:
    return Stroke(Stroke.from_polyline(np.array([[0.0, 0.0], [length, 0.0]])).control, None, widths)


def plan_of(stroke: Stroke, options: SatinOptions = SatinOptions(), width: float = 2.0):
    return plan_embroidery(Drawing((stroke,), 40, 40, "mm", width), PlanOptions(style=options))


def widths_along(plan) -> tuple[np.ndarray, np.ndarray]:
    s, _, width = sewn_widths(plan, 0)
    return s, width


def test_the_column_follows_the_drawn_width():
    profile = np.array([[0.0, 1.0], [0.5, 4.0], [1.0, 2.0]])  # mm
    plan = plan_of(line(profile))
    s, width = widths_along(plan)
    drawn = np.interp(s / 30.0, profile[:, 0], profile[:, 1])
    inside = (s > 1.0) & (s < 29.0)
    error = np.abs(width[inside] - drawn[inside])
    assert np.mean(error <= np.maximum(0.1 * drawn[inside], 0.2)) >= 0.95


@pytest.mark.parametrize("options, expected", [
    (SatinOptions(width=3.0), 3.0),  # a constant width overrides the drawing's
    (SatinOptions(width_scale=1.5), 3.0),
    (SatinOptions(max_width=1.5), 1.5),
    (SatinOptions(min_width=2.5), 2.5),
    (SatinOptions(pull_compensation=0.4), 2.4),
    (SatinOptions(pull_compensation_percent=0.1, pull_compensation=0.2), 2.4),
])
def test_width_options(options, expected):
    plan = plan_of(line(np.array([[0.0, 2.0], [1.0, 2.0]])), options)
    s, width = widths_along(plan)
    middle = (s > 3.0) & (s < 27.0)
    assert np.median(width[middle]) == pytest.approx(expected, abs=0.12)


def test_a_stroke_without_widths_takes_the_drawings():
    plan = plan_of(line(), width=1.6)
    s, width = widths_along(plan)
    assert np.median(width[(s > 3) & (s < 27)]) == pytest.approx(1.6, abs=0.12)


@pytest.mark.parametrize("width, kinds", [(1.5, ("center",)), (3.0, ("edge",)), (5.0, ("edge", "zigzag"))])
def test_auto_underlay_by_width_and_each_underlay_out_and_back(width, kinds):
    options = SatinOptions(width=width)
    assert options.underlays_for(width) == kinds
    needles = satin_stitch(line(), options)
    under = needles.points[needles.roles == UNDERLAY]
    # out and back: both ends at the column's start, where the top begins
    assert len(under) > 4 and under[0, 0] < 1.6 and under[-1, 0] < 1.6
    assert (needles.roles[:len(under)] == UNDERLAY).all()
    assert np.abs(under[:, 1]).max() <= width / 2  # under the top stitches


def test_named_underlays_and_none():
    assert SatinOptions(underlay="edge+zigzag").underlay == ("edge", "zigzag")
    assert SatinOptions(underlay="none").underlay == ()
    assert not (satin_stitch(line(), SatinOptions(underlay="none")).roles == UNDERLAY).any()
    for bad in ("edge+foo", "edge+edge", "sideways"):
        with pytest.raises(InputError, match="underlay"):
            SatinOptions(underlay=bad)


def test_wide_rows_are_split_and_short_stitches_inset_inside_a_bend():
    needles = satin_stitch(line(), SatinOptions(width=10.0, underlay="none", max_stitch_length=4.0))
    steps = np.linalg.norm(np.diff(needles.points, axis=0), axis=1)
    assert steps.max() <= 4.0
    # a tight bend: points of the inside rail come closer than 0.25 mm, every other one is inset
    arc = spiral(0, 0, 4.0, 4.0, 0.5, n=8)
    body = satin_stitch(arc, SatinOptions(width=3.0, underlay="none"))
    radius = np.linalg.norm(body.points, axis=1)
    inner = radius[radius < 4.0]
    assert inner.min() > 4.0 - 1.5 - 0.01 and np.unique(np.round(inner, 1)).size > 1  # rail and inset


def test_random_width_and_phase_are_seeded():
    options = SatinOptions(width=8.0, random_width=0.2, random_phase=True, max_stitch_length=3.0, seed=4)
    a, b = satin_stitch(line(), options), satin_stitch(line(), options)
    assert np.array_equal(a.points, b.points)
    other = satin_stitch(line(), SatinOptions(width=8.0, random_width=0.2, random_phase=True,
                                              max_stitch_length=3.0, seed=5))
    assert not np.array_equal(a.points, other.points)
    plain = satin_stitch(line(), SatinOptions(width=8.0, max_stitch_length=3.0))
    top = a.points[a.roles == BODY]
    assert np.abs(top[:, 1]).max() > np.abs(plain.points[plain.roles == BODY][:, 1]).max()


def corner(angle: float, leg: float = 12.0) -> Stroke:
    """Two straight legs meeting at `angle` degrees between them (180: straight on)."""
    turn = np.radians(180.0 - angle)
    return Stroke.from_polyline(np.array([[-leg, 0.0], [0.0, 0.0], [leg * np.cos(turn), leg * np.sin(turn)]]))


@pytest.mark.parametrize("style", ["satin", "zigzag"])
@pytest.mark.parametrize("angle", [30, 45, 60, 90, 120, 150, 170])
def test_corners_are_never_piled_up_slit_or_pierced_twice(style, angle):
    plan = plan_embroidery(Drawing((corner(angle),), 30, 30, "mm", 2.0),
                           PlanOptions(style=style_options(style, width=2.0)))
    density = needle_density(plan.points[plan.kinds == STITCH])
    stats = embroidery_stats(plan)
    # at most 6 within 0.5 mm, or the stats name the place
    assert density.maximum <= 6 or any(f"{p.x:.1f}, {p.y:.1f}" in " ".join(stats.warnings) for p in density.places)
    assert len(repeated_holes(plan)) == 0
    if style == "satin":
        half = SatinOptions(width=2.0).sewn_width(np.array([2.0]))[0] / 2
        assert slits(plan, 0, lambda s: np.full(len(s), half), 0.4, corners=np.zeros((1, 2))) == []


def test_a_retraced_spike_is_sewn_once():
    out_and_back = Stroke.from_polyline(np.array([[0.0, 0.0], [10.0, 0.0], [0.0, 0.0], [0.0, 10.0]]))
    plan = plan_of(out_and_back, SatinOptions(width=2.0, underlay="none"))
    top = plan.points[(plan.kinds == STITCH) & (plan.roles == BODY)]
    on_spike = top[(top[:, 0] > 2.0)]
    # one column's rows (every 0.2 mm over 8 mm): not two layers
    assert len(on_spike) < 60


def test_five_formats_same_bytes_every_run(tmp_path):
    drawing = Drawing((Stroke(spiral(0, 0, 3.0, 12.0, 1.5).control, None,
                              np.array([[0.0, 1.0], [0.5, 3.0], [1.0, 1.5]])),), 30, 30, "mm", 2.0)
    for ext in FORMATS:
        a, b = tmp_path / f"a.{ext}", tmp_path / f"b.{ext}"
        write_embroidery(plan_embroidery(drawing, PlanOptions(style=SatinOptions(random_width=0.1))), a)
        write_embroidery(plan_embroidery(drawing, PlanOptions(style=SatinOptions(random_width=0.1))), b)
        assert a.read_bytes() == b.read_bytes()


def test_the_command_line_sews_a_brush_drawing_as_wide_as_it_is_drawn(tmp_path):
    from click.testing import CliRunner
    from PIL import Image

    from benchmarks.common.render import render_profile, to_uint8
    from fabrication.cli import main
    from fabrication.embroidery.read import read_embroidery

    # a line 900 px long whose ink swells from 12 to 36 px and back, at 90 mm: 1.2-3.6 mm
    drawn = Drawing((line(length=900.0).transformed(np.array([[1.0, 0, 50.0], [0, 1.0, 500.0]])),), 1000, 1000,
                    "px", 36.0)
    profile = (np.array([0.0, 0.5, 1.0]), np.array([12.0, 36.0, 12.0]))
    Image.fromarray(to_uint8(render_profile(drawn, profile))).save(tmp_path / "brush.png")
    result = CliRunner().invoke(main, ["embroider", str(tmp_path / "brush.png"), "-o", str(tmp_path / "b.pes"),
                                       "--style", "satin", "--underlay", "edge+zigzag", "--random-width", "5%",
                                       "--seed", "2", "--hoop", "130x180"])
    assert result.exit_code == 0, result.output
    back = read_embroidery(tmp_path / "b.pes").plan
    needles = back.points[back.kinds == STITCH]
    across = np.ptp(needles[:, 1][np.abs(needles[:, 0]) < 3.0])  # the middle, mm
    assert across == pytest.approx(3.6, rel=0.15)  # +-5 % random width on top of the drawn 3.6 mm
    result = CliRunner().invoke(main, ["embroider", str(tmp_path / "brush.png"), "-o", str(tmp_path / "c.pes"),
                                       "--style", "satin", "--min-width", "3mm", "--max-width", "2mm"])
    assert result.exit_code == 2 and "--min-width" in result.output


@pytest.mark.parametrize("name, stroke, width", [
    ("tight spiral", spiral(0, 0, 2.0, 9.0, 3.0, n=48), 2.0),
    ("loops of a narrow line", Stroke.from_polyline(np.c_[8.0 * np.linspace(0, 3, 600) + 6.0 * np.cos(
        np.linspace(0, 6 * np.pi, 600)), -9.0 * np.sin(np.linspace(0, 6 * np.pi, 600))]), 0.6),
    ("swelling brush line", Stroke(spiral(0, 0, 3.0, 12.0, 1.5).control, None,
                                   np.array([[0.0, 1.0], [0.5, 4.0], [1.0, 1.5]])), 2.0),
])
def test_tight_bends_and_narrow_columns_keep_the_density_limit_and_pierce_no_hole_twice(name, stroke, width):
    from benchmarks.metrics.stitches import worst_density

    plan = plan_of(stroke, width=width)
    assert worst_density(plan) <= 6, name  # every needle point counted, tacks and locks too
    assert len(repeated_holes(plan)) == 0, name
    if width < 1.0:  # a walk down the middle of so narrow a column only crowds it
        assert not (plan.roles == UNDERLAY).any()


def test_crowding_is_relieved_underlay_first_then_by_insetting_top_points():
    from fabrication.embroidery.crowding import relieve_crowding

    # A straight column's rail points 0.2 mm apart on one side (7 within 0.5 mm of the
    # middle one), then an underlay walk through them.
    rail = np.c_[np.arange(9) * 0.2, np.ones(9)]
    walk = np.c_[np.arange(0.0, 1.7, 0.4), np.full(5, 0.8)]
    points = np.vstack([walk, rail])
    roles = np.r_[np.full(5, UNDERLAY), np.full(9, BODY)]
    inward = np.r_[np.zeros((5, 2)), np.tile([0.0, -1.0], (9, 1))]  # each top point may go 1 mm in

    def sides(rows, at):
        return np.sign(np.round(at[:, 1] - 0.4, 6)).astype(int)

    relieved, keep = relieve_crowding(points, roles, inward, sides, max_gap=6.0)
    assert needle_density(relieved[keep]).maximum <= 6
    assert not keep[5:].all() or (relieved[5:, 1] < 1.0).any()  # top points kept, some inset
    assert keep[5:].all()  # top points are never left out for density
    assert not keep[1:4].all()  # underlay went first
    moved = np.linalg.norm(relieved - points, axis=1) > 0
    assert np.all(relieved[moved, 0] == points[moved, 0])  # inset straight towards the centre


def test_a_needle_re_entering_the_underlays_last_hole_leaves_that_hole_out_rather_than_open_a_slit():
    from fabrication.embroidery.crowding import REENTER, relieve_crowding

    # A 2 mm column's top points every 0.2 mm (spacing 0.4), sides alternating, after an edge
    # walk that ends 0.2 mm from the first top point on the right: the needle would re-enter
    # that hole. Insetting the top point clear of it takes it 0.75 mm short of its rail, a
    # gap of 0.4 mm between its neighbours' stitches there (a slit).
    top = np.c_[np.arange(12) * 0.2, np.where(np.arange(12) % 2 == 0, 1.0, -1.0)]
    walk = np.array([[2.0, -0.8], [1.0, -0.8], [0.2, -0.8]])
    points = np.vstack([walk, top])
    roles = np.r_[np.full(3, UNDERLAY), np.full(12, BODY)]
    inward = np.r_[np.zeros((3, 2)), np.c_[np.zeros(12), -top[:, 1]]]

    def sides(rows, at):
        return np.where(np.abs(at[:, 1]) < 0.15, 0, np.sign(at[:, 1])).astype(int)

    unchecked, _ = relieve_crowding(points, roles, inward, sides, max_gap=6.0)
    assert unchecked[4, 1] > -0.5  # without the spacing, the top point goes short (as before)
    relieved, keep = relieve_crowding(points, roles, inward, sides, max_gap=6.0, spacing=0.4)
    assert np.array_equal(relieved[3:], points[3:]) and keep[3:].all()  # every top point where its row puts it
    assert not keep[2]  # the walk's last hole, under the top stitches, is left out instead
    right = relieved[keep & (relieved[:, 1] < 0)]
    gaps = np.linalg.norm(right[1:] - right[:-1], axis=1)
    assert gaps.min() >= REENTER  # and nothing re-enters a hole on its side


@pytest.mark.parametrize("radius, width, sweep", [(3.0, 3.0, 180), (3.0, 3.0, 270), (2.0, 2.0, 180)])
def test_a_columns_last_point_inside_a_bend_keeps_its_reach_so_the_end_is_not_slit(radius, width, sweep):
    # Inside a bend the needle points crowd and step deeper one after another, up to half
    # the row's width; the last one inside went as deep as its steps said and bared the end.
    angle = np.radians(np.linspace(0.0, sweep, sweep // 5 + 1))
    arc = Stroke.from_polyline(radius * np.c_[np.cos(angle), np.sin(angle)])
    options = SatinOptions(width=width)
    plan = plan_of(arc, options)
    half = options.sewn_width(np.array([width]))[0] / 2
    top = plan.points[(plan.kinds == STITCH) & (plan.roles == BODY)]
    inside = top[np.linalg.norm(top, axis=1) < radius]
    # at most a short stitch's inset (a share of the width) short of the rail, on the 0.1 mm grid
    assert radius - np.linalg.norm(inside[-1]) >= half - options.short_stitch_inset * width - 0.1
    assert slits(plan, 0, lambda s: np.full(len(s), half), options.spacing, inset=2 * options.short_stitch_inset) == []


def test_the_varying_width_sets_capital_s_is_sewn_without_a_slit_where_it_hooks():
    # The broad-nib S of benchmarks/satin_quality.py: where the spine meets the lower bowl the
    # line runs up a spur and back and jogs 1 mm sideways through two rounded corners. The
    # spur's last rows took their direction from the corner's own rounding (the last 0.05 mm
    # of the curve) and lost their inside; then a needle inset clear of the underlay's last
    # hole bared the ground beside it: one slit each time.
    from benchmarks.sets.brush import capital_set
    from benchmarks.common.render import render_truth, to_uint8
    from benchmarks.satin_quality import column_slits
    from fabrication.placement import PlacementOptions, place
    from vectorize.pipeline import vectorize_image

    s = next(gt for gt in capital_set(2, 0) if gt.name.endswith("-S"))
    placed = place(vectorize_image(to_uint8(render_truth(s))).drawing, PlacementOptions(size=90.0))
    style = style_options("satin")
    plan = plan_embroidery(placed, PlanOptions(style=style))
    assert column_slits(plan, style) == 0
    assert needle_density(plan.points[plan.kinds == STITCH]).maximum <= 6
    assert len(repeated_holes(plan)) == 0


def test_a_split_corner_ends_the_first_column_at_the_corner_and_caps_the_second():
    plan = plan_embroidery(Drawing((corner(30.0),), 30, 30, "mm", 2.0), PlanOptions(style=SatinOptions(width=2.0)))
    top = (plan.kinds == STITCH) & (plan.roles == BODY)
    first = top & (plan.params < 0.5 - 1e-6)
    # nothing of the first leg (along +x) beyond the corner but its overlap under the second
    assert plan.points[first, 0].max() <= plan.sewn.strokes[0].points_at(0.5)[0] + 0.3 + 0.1
    second = top & (plan.params >= 0.5)
    tip = plan.sewn.strokes[0].points_at(0.5)
    beyond = plan.points[second][plan.points[second, 0] > tip[0] + 0.3]
    assert len(beyond) >= 3  # the cap over the corner's outside
    assert np.linalg.norm(beyond - tip, axis=1).max() <= 1.0 + 0.15  # within the round pen's tip


def test_warnings_name_every_place_or_how_many_there_are():
    from fabrication.embroidery.quality import Place, where

    three = tuple(Place(x=float(i), y=0.0, count=7) for i in range(3))
    assert where(three) == "at (0.0, 0.0) mm (7), (1.0, 0.0) mm (7), (2.0, 0.0) mm (7)"
    many = tuple(Place(x=float(i), y=0.0, count=7) for i in range(15))
    text = where(many)
    assert text.startswith("at 15 places, the first 12: (0.0, 0.0) mm (7)") and "(11.0, 0.0)" in text
    assert "(12.0, 0.0)" not in text


def test_a_columns_last_rows_stay_square_to_it_at_a_corner():
    from fabrication.embroidery.columns import column_rows
    from fabrication.embroidery.sampling import dense_curve

    stroke = corner(30.0)  # the first leg runs along +x for 12 mm, then turns back
    curve = dense_curve(stroke)
    rows = column_rows(stroke, curve, lambda s: np.full(len(s), 1.0), 0.0, 12.0, 0.4)
    # none swings round towards the next leg (the corner point's own tangent is the next leg's)
    assert np.abs(rows.normal[:, 0]).max() < np.sin(np.radians(1.0))
    assert rows.right_points[:, 0].max() <= 1e-6 and rows.left_points[:, 0].max() <= 1e-6

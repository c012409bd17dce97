"""Whole-design rules: locks, minimum and maximum stitch, trims, hoops, stats and density."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks.sets.embroidery_designs import design, spiral
from benchmarks.metrics.stitches import lock_figure_ok, sewn_stitches, stroke_rows
from fabrication.embroidery.hooping import check_plan_in_hoop, fit_to_hoop
from fabrication.embroidery.locks import LOCK_FORMS, LockOptions, lock_points, tack_points
from fabrication.embroidery.needles import BODY, LOCK, TACK, TRAVEL
from fabrication.embroidery.plan import (JUMP, STITCH, TRIM, PlanOptions, StitchPlan, plan_embroidery,
                                         style_options, style_reach)
from fabrication.embroidery.running import RunningOptions
from fabrication.embroidery.stats import embroidery_stats
from fabrication.embroidery.thread import parse_color
from fabrication.embroidery.zigzag import ZigzagOptions
from fabrication.placement import PlacementOptions, place
from machines.hoops import Hoop, hoop_named
from onestroke.errors import InputError
from vectorize.drawing import Drawing
from vectorize.stroke import Stroke


def _line(*pts):
    return Stroke.from_polyline(np.array(pts, dtype=float))


def test_half_stitch_lock_walks_back_along_the_path():
    path = np.array([[0.0, 0.0], [2.5, 0.0], [5.0, 0.0]])
    assert np.allclose(lock_points(path), [[4.25, 0], [3.5, 0], [4.25, 0], [5.0, 0]])
    assert np.allclose(tack_points(path), [[0, 0], [0.75, 0], [1.5, 0], [0.75, 0]])
    # A path shorter than the lock length: the lock spans the path.
    short = np.array([[0.0, 0.0], [0.8, 0.0]])
    assert np.allclose(lock_points(short), [[0.4, 0], [0, 0], [0.4, 0], [0.8, 0]])
    assert np.allclose(lock_points(path, LockOptions(form="back_forth")),
                       [[3.5, 0], [5, 0], [3.5, 0], [5, 0]])
    for form in LOCK_FORMS:
        assert np.all(np.diff(LOCK_FORMS[form]) != 0)  # never a zero-length lock stitch
    with pytest.raises(InputError):
        LockOptions(form="bowtie")


@pytest.mark.parametrize("form", list(LOCK_FORMS))
def test_lock_forms_in_a_plan_never_have_zero_length(form):
    plan = plan_embroidery(design(), PlanOptions(lock=LockOptions(form=form)))
    assert np.hypot(*sewn_stitches(plan).T).min() > 0


def test_short_stitches_are_merged_away_outside_locks():
    # A wobbly line with 0.05-0.25 mm pieces and a long stitch length chosen so that the
    # running stitch must follow the pieces: min-stitch merging has to act.
    x = np.cumsum(np.r_[0, np.tile([0.05, 0.25, 0.1], 40)])
    y = np.tile([0.0, 0.3], len(x))[:len(x)]
    stroke = _line(*np.c_[x, y])
    for minimum in (0.3, 1.0):
        plan = plan_embroidery(Drawing((stroke,), 20, 2, "mm"),
                               PlanOptions(style=RunningOptions(corner_angle=170), min_stitch=minimum))
        lengths = np.hypot(*sewn_stitches(plan).T)
        roles = plan.roles[np.flatnonzero(plan.stitch_mask)]
        assert lengths.min() > 0
        assert lengths[~np.isin(roles, (TACK, LOCK))].min() >= minimum - 1e-9
        rows = stroke_rows(plan)[0]
        # The tack and lock keep their figure, unless made lighter on this crowded wobble.
        lighter = {t.lock for t in plan.lighter}
        assert False in lighter or lock_figure_ok(plan.points[rows[:5]])
        assert True in lighter or lock_figure_ok(plan.points[rows[-5:]])


def test_long_needle_down_moves_are_split_into_stitches_not_jumps():
    # Two strokes 2.9 mm apart are joined by a stitch; a running stitch of 10 mm with a
    # 4 mm maximum gets split on the 0.1 mm grid into real stitches.
    drawing = Drawing((_line([0, 0], [30, 0]), _line([30, 2.9], [0, 2.9])), 30, 3, "mm")
    plan = plan_embroidery(drawing, PlanOptions(style=RunningOptions(stitch_length=10.0), max_stitch=4.0))
    assert not (plan.kinds != STITCH).any()
    assert np.abs(sewn_stitches(plan)).max() <= 4.0 + 1e-9
    assert np.allclose(plan.points * 10, np.rint(plan.points * 10))
    with pytest.raises(InputError):
        PlanOptions(max_stitch=0.5)


def test_trim_only_when_strokes_are_far_apart():
    near = Drawing((_line([0, 0], [10, 0]), _line([12.9, 0], [20, 0])), 20, 1, "mm")
    far = Drawing((_line([0, 0], [10, 0]), _line([13.5, 0], [20, 0])), 20, 1, "mm")
    plan_near, plan_far = plan_embroidery(near), plan_embroidery(far)
    assert not (plan_near.kinds != STITCH).any()
    rows = stroke_rows(plan_near)[1]
    assert plan_near.roles[rows[0]] == TRAVEL  # a short travel stitch, then the tack
    assert list(plan_far.kinds[plan_far.kinds != STITCH]) == [TRIM, JUMP]
    trim = int(np.flatnonzero(plan_far.kinds == TRIM)[0])
    assert plan_far.roles[trim - 1] == LOCK and np.allclose(plan_far.points[trim], [10, 0])
    assert np.allclose(plan_far.points[trim + 1], [13.5, 0])
    custom = plan_embroidery(near, PlanOptions(trim_distance=1.0))
    assert (custom.kinds == TRIM).sum() == 1


def test_strokes_too_short_to_sew_are_skipped_and_counted():
    drawing = Drawing((_line([0, 0], [10, 0]), _line([20, 0], [20.1, 0])), 20, 1, "mm")
    plan = plan_embroidery(drawing)
    assert plan.skipped == 1 and set(np.unique(plan.strokes[plan.kinds == STITCH])) == {0}
    with pytest.raises(InputError):
        plan_embroidery(Drawing((_line([0, 0], [0.1, 0]),), 1, 1, "mm"))
    with pytest.raises(InputError):
        plan_embroidery(Drawing((_line([0, 0], [10, 0]),), 10, 1, "px"))


def test_style_options_by_name():
    assert isinstance(style_options("zigzag", width=3.0, stitch_length=9.0), ZigzagOptions)
    assert style_options("zigzag", width=3.0).width == 3.0
    assert style_options("RUNNING", stitch_length=None).stitch_length == 2.5
    with pytest.raises(InputError, match="unknown stitch style 'cross'"):
        style_options("cross")
    assert style_reach(ZigzagOptions(width=3.0, pull_compensation=0.4)) == pytest.approx(1.7)


def test_hoop_check_refuses_or_fits():
    drawing = Drawing((spiral(0, 0, 5.0, 40.0, 2.0),), 100, 100, "mm")
    big = place(drawing, PlacementOptions(size=120.0))
    hoop = hoop_named("4x4")
    with pytest.raises(InputError, match=r"hoop 100x100 \(4x4\) holds 100 x 100 mm"):
        fit_to_hoop(big, hoop)
    style = ZigzagOptions(width=3.0)
    fitted = fit_to_hoop(big, hoop, reach=style_reach(style), fit=True)
    plan = plan_embroidery(fitted, PlanOptions(style=style))
    check_plan_in_hoop(plan, hoop)
    xmin, ymin, xmax, ymax = plan.bounds()
    assert max(xmax - xmin, ymax - ymin) > 95.0  # scaled to fill the hoop, not shrunk to nothing
    small = place(drawing, PlacementOptions(size=60.0))
    assert fit_to_hoop(small, hoop) is small
    custom = hoop_named("70x50")
    with pytest.raises(InputError):
        check_plan_in_hoop(plan_embroidery(small), custom)


def test_stats_count_time_thread_and_size():
    plan = plan_embroidery(design())
    stats = embroidery_stats(plan, stitches_per_minute=600, trim_seconds=10)
    needles = int((plan.kinds == STITCH).sum())
    assert stats.stitches == needles and stats.trims == 2 and stats.jumps == 2
    assert stats.seconds == pytest.approx(needles / 600 * 60 + 2 * 10)
    assert stats.thread_length == pytest.approx(np.hypot(*sewn_stitches(plan).T).sum())
    # Thread is at least the drawing's length (plus locks and travel), and not much more.
    assert design().length < stats.thread_length < design().length * 1.1
    xmin, ymin, xmax, ymax = plan.bounds()
    assert (stats.width, stats.height) == pytest.approx((xmax - xmin, ymax - ymin))
    assert not stats.too_dense and stats.warnings == ()
    assert any(line.startswith("stitches") for line in stats.lines())


def test_bobbin_thread_is_estimated_beside_the_top_thread():
    """Running stitches: the bobbin lies under every stitch (as long as the top thread).
    A zigzag column: a third of its body stitches, the whole of its walks and locks."""
    line = Drawing((_line([0, 0], [40, 0]),), 40, 1, "mm")
    running = plan_embroidery(line, PlanOptions())
    stats = embroidery_stats(running)
    assert stats.bobbin_length == pytest.approx(stats.thread_length)
    assert "top" in stats.lines()[2] and "bobbin" in stats.lines()[2]
    zigzag = plan_embroidery(line, PlanOptions(style=ZigzagOptions()))
    column = embroidery_stats(zigzag, column=True)
    a, b = zigzag.stitches()
    length = np.hypot(*(b - a).T)
    body = zigzag.roles[zigzag.stitch_mask] == BODY
    assert column.bobbin_length == pytest.approx(length[body].sum() / 3 + length[~body].sum())
    assert 0.3 * column.thread_length < column.bobbin_length < 0.5 * column.thread_length
    assert "1/3" in column.bobbin_rule and "1/3" in column.lines()[2]


def test_density_warning_above_six_needle_points_within_half_a_millimetre():
    def plan_of(points, roles=None):
        n = len(points)
        return StitchPlan(points=np.asarray(points, float), kinds=np.zeros(n, np.uint8),
                          roles=np.full(n, BODY, np.uint8) if roles is None else np.asarray(roles, np.uint8),
                          params=np.linspace(0, 1, n), strokes=np.zeros(n, int))
    six = [[0, 0], [0.3, 0], [0, 0.3], [0.3, 0.3], [0.2, 0.1], [0.1, 0.4], [5, 5]]
    seven = six[:6] + [[0.15, 0.15], [5, 5]]
    assert embroidery_stats(plan_of(six)).max_density == 6
    assert not embroidery_stats(plan_of(six)).too_dense
    stats = embroidery_stats(plan_of(seven))
    assert stats.too_dense and stats.max_density == 7 and stats.dense_points == 7
    assert "too dense" in stats.warnings[0]
    # Every needle point counts: tacks and locks are no exception.
    locked = embroidery_stats(plan_of(seven, [TACK, TACK, LOCK, LOCK, BODY, BODY, BODY, BODY]))
    assert locked.too_dense and locked.max_density == 7
    # The warning names the place (mm) and what to change.
    assert "at (0.0, 0.0) mm (7)" in stats.warnings[0] and "longer stitch" in stats.warnings[0]
    # A zigzag at 0.1 mm spacing is too dense; the default 0.4 mm on a straight line is not.
    line = Drawing((_line([0, 0], [20, 0]),), 20, 1, "mm")
    assert embroidery_stats(plan_embroidery(line, PlanOptions(style=ZigzagOptions(spacing=0.1)))).too_dense
    assert not embroidery_stats(plan_embroidery(line, PlanOptions(style=ZigzagOptions()))).too_dense


def test_thread_colours():
    assert parse_color("#c81e28") == (200, 30, 40)
    assert parse_color("c81e28") == (200, 30, 40)
    assert parse_color("navy") == (0, 0, 128)
    with pytest.raises(InputError, match="'blurple' is not a colour"):
        parse_color("blurple")
    with pytest.raises(InputError):
        PlanOptions(color=(300, 0, 0))


def _dots(n):
    return tuple(_line([i * 5.0, 0.0], [i * 5.0 + 1.5, 0.0]) for i in range(n))


EDGE_CASES = {
    "no strokes": (Drawing((), 10, 10, "mm"), InputError),
    "one point": (Drawing((Stroke(np.zeros((1, 4, 2))),), 1, 1, "mm"), InputError),
    "shorter than a stitch": (Drawing((_line([0, 0], [0.2, 0]),), 1, 1, "mm"), InputError),
    "a lone speck": (Drawing((_line([0, 0], [0.35, 0]),), 1, 1, "mm"), InputError),
    "just over the minimum stroke": (Drawing((_line([0, 0], [1.05, 0]),), 1, 1, "mm"), None),
    "closed loop": (Drawing((spiral(0, 0, 10, 10, 1.0),), 20, 20, "mm"), None),
    "300 short strokes": (Drawing(_dots(300), 1500, 1, "mm"), None),
    "pixels, not placed": (Drawing((_line([0, 0], [10, 0]),), 10, 1, "px"), InputError),
}


@pytest.mark.parametrize("name", list(EDGE_CASES))
@pytest.mark.parametrize("style", ["running", "triple", "zigzag", "arrows"])
def test_edge_cases(name, style):
    drawing, error = EDGE_CASES[name]
    options = PlanOptions(style=style_options(style))
    if error is not None:
        with pytest.raises(error):
            plan_embroidery(drawing, options)
        return
    plan = plan_embroidery(drawing, options)
    lengths = np.hypot(*sewn_stitches(plan).T)
    assert lengths.min() > 0 and np.abs(sewn_stitches(plan)).max() <= 12.1 + 1e-9
    assert len(stroke_rows(plan)) == len(drawing.strokes)
    if name == "300 short strokes":
        assert (plan.kinds == TRIM).sum() == 299  # 5 mm apart: lock, trim, jump, tack each time


def test_embroider_pipeline_places_fits_stitches_and_measures():
    from fabrication.embroidery.pipeline import EmbroideryJob, embroider

    px = Drawing((spiral(300, 300, 20, 200, 2.0),), 600, 600, "px")
    result = embroider(px)  # 90 mm in the 4x4 hoop, running stitch
    xmin, ymin, xmax, ymax = result.drawing.bounds()
    assert max(xmax - xmin, ymax - ymin) == pytest.approx(90.0, abs=1e-6)
    assert result.fit_scale == 1.0 and result.stats.stitches == int((result.plan.kinds == STITCH).sum())
    job = EmbroideryJob(placement=PlacementOptions(size=150.0), hoop=hoop_named("4x4"), fit=True,
                        plan=PlanOptions(style=ZigzagOptions(width=11.0)), stitches_per_minute=800)
    fitted = embroider(px, job)
    assert fitted.fit_scale < 0.7 and any("scaled down" in w for w in fitted.warnings)
    assert any("lie loose" in w and "--stitch-width" in w for w in fitted.warnings)
    check_plan_in_hoop(fitted.plan, hoop_named("4x4"))
    assert fitted.stats.stitches_per_minute == 800
    with pytest.raises(InputError, match="hoop 100x100"):
        embroider(px, EmbroideryJob(placement=PlacementOptions(size=150.0)))
    with pytest.raises(InputError):
        EmbroideryJob(stitches_per_minute=0)


def _random_drawing(seed: int) -> Drawing:
    """Random cubic strokes: smooth, kinked, tiny and long ones, some close together."""
    rng = np.random.default_rng(seed)
    strokes = []
    for _ in range(rng.integers(1, 5)):
        k = int(rng.integers(1, 8))
        scale = float(rng.choice([0.5, 5.0, 30.0]))
        start = rng.uniform(-30, 30, 2)
        control = start + np.cumsum(rng.normal(0, scale, (k, 4, 2)), axis=1)
        control[1:, 0] = control[:-1, 3]  # segments join
        strokes.append(Stroke(control))
    return Drawing(tuple(strokes), 100, 100, "mm")


@pytest.mark.parametrize("seed", range(10))
@pytest.mark.parametrize("style", ["running", "triple", "zigzag", "arrows"])
def test_random_drawings_keep_every_rule(seed, style):
    drawing = place(_random_drawing(seed), PlacementOptions(size=80.0))
    options = PlanOptions(style=style_options(style))
    try:
        plan = plan_embroidery(drawing, options)
    except InputError as error:
        assert "long enough" in str(error)
        return
    deltas = sewn_stitches(plan)
    lengths = np.hypot(*deltas.T)
    assert lengths.min() > 0 and np.abs(deltas).max() <= 12.1 + 1e-9
    roles = plan.roles[np.flatnonzero(plan.stitch_mask)]
    assert lengths[~np.isin(roles, (TACK, LOCK))].min() >= 0.3 - 1e-9
    assert np.allclose(plan.points * 10, np.rint(plan.points * 10))
    trims = np.flatnonzero(plan.kinds == TRIM)
    assert (plan.kinds[trims + 1] == JUMP).all()
    # A lock before every trim and at the end, unless left out where it would have
    # crowded its place beyond the density limit.
    left_out = {(round(t.x, 1), round(t.y, 1)) for t in plan.lighter if t.lock and t.level == 2}
    ends = np.r_[trims - 1, np.flatnonzero(plan.kinds == STITCH)[-1]]
    for end in ends[plan.roles[ends] != LOCK]:
        assert tuple(np.round(plan.points[end], 1)) in left_out


def test_rows_after_a_jump_keep_their_own_parameter_when_long_stitches_are_split():
    # Found by the fuzz (a JSON drawing sewn as satin): splitting a long stitch anywhere in
    # the plan gave the first row after each jump or trim its NaN parameter, and the
    # repeated-hole check then met NaN on the curve.
    from fabrication.embroidery.grid import split_long
    from fabrication.embroidery.quality import needle_sides, repeated_holes

    units = np.array([[0, 0], [200, 0], [200, 0], [900, 0], [910, 0]])
    kinds = np.array([STITCH, STITCH, TRIM, JUMP, STITCH])
    params = np.array([0.0, 0.5, np.nan, np.nan, 1.2])
    new_units, new_params, source = split_long(units, kinds, params, 127)
    assert np.array_equal(new_units[source == 4], [[910, 0]]) and new_params[source == 4] == [1.2]
    assert np.isfinite(new_params[kinds[source] == STITCH]).all()
    assert np.allclose(new_params[source == 1], [0.5 * 1 / 2, 0.5])  # split in two, interpolated
    wide = Drawing((_line((0, 0), (30, 0)), _line((0, 30), (40, 30))), 40, 40, "mm", 20.0)
    plan = plan_embroidery(wide, PlanOptions(style=style_options("satin", max_width=12.0, max_stitch_length=12.7)))
    stitched = (plan.kinds == STITCH) & (plan.strokes >= 0)
    assert (plan.kinds == JUMP).any() and np.isfinite(plan.params[stitched]).all()
    assert np.isfinite(needle_sides(plan)).all() and len(repeated_holes(plan)) == 0


@pytest.mark.parametrize("style", ["running", "triple", "zigzag", "satin", "arrows"])
def test_zero_length_strokes_and_pieces_never_reach_the_checks_as_nan(style):
    from fabrication.embroidery.quality import needle_sides, repeated_holes

    dot = Stroke(np.array([[[10.0, 0.0]] * 4]))  # a zero-length stroke next to the next one
    pieces = Stroke(np.array([[[10.5, 0.0]] * 4, [[10.5, 0.0], [14.0, 0.0], [17.0, 0.0], [20.0, 0.0]],
                              [[20.0, 0.0]] * 4]))  # zero-length pieces at both ends
    far = Stroke(np.array([[[40.0, 20.0]] * 4]))  # and one alone, far from the others
    drawing = Drawing((_line([0, 0], [10, 0]), dot, pieces, far), 40, 20, "mm", 2.0)
    plan = plan_embroidery(drawing, PlanOptions(style=style_options(style)))
    stitched = (plan.kinds == STITCH) & (plan.strokes >= 0)
    assert np.isfinite(plan.params[stitched]).all() and np.isfinite(plan.points).all()
    assert np.isfinite(needle_sides(plan)).all()
    repeated_holes(plan)  # runs on every row without NaN
    assert any("stroke 4" in line for line in plan.dropped)  # the lone dot is left out, named

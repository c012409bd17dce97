"""What an embroiderer checks (issue 13): no piled-up holes, no knots on specks, loose
stitches warned about, and the short-stroke rule; measured on real plans over a table of
drawings and styles."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks.sets.embroidery_designs import STYLE_NAMES, design, spiral
from benchmarks.metrics.stitches import needle_runs, repeated_penetrations, worst_density
from fabrication.embroidery.needles import LOCK, TACK, TRAVEL
from fabrication.embroidery.pipeline import EmbroideryJob, embroider
from fabrication.embroidery.plan import STITCH, PlanOptions, plan_embroidery, style_options
from fabrication.embroidery.stats import embroidery_stats
from fabrication.placement import PlacementOptions
from machines.hoops import hoop_named
from vectorize.drawing import Drawing
from vectorize.stroke import Stroke


def _line(a, b) -> Stroke:
    return Stroke.from_polyline(np.array([a, b], dtype=float))


def _loops() -> Drawing:
    """Three loops of a cursive line (like examples/loops.png): tight curves, a crossing."""
    t = np.linspace(0.0, 3 * 2 * np.pi, 600)
    x, y = 8.0 * t / (2 * np.pi) + 6.0 * np.cos(t), -9.0 * np.sin(t)
    return Drawing((Stroke.from_polyline(np.c_[x, y]),), 40, 20, "mm")


DRAWINGS = {
    "design": design,
    "tight spiral": lambda: Drawing((spiral(0, 0, 2.0, 9.0, 3.0, n=48),), 20, 20, "mm"),
    "loops": _loops,
    "hairpin": lambda: Drawing((Stroke.from_polyline(np.array([[0, 0], [20, 0], [20, 0.8], [0, 0.8]])),),
                               20, 1, "mm"),
}


@pytest.mark.parametrize("drawing", list(DRAWINGS))
@pytest.mark.parametrize("style", STYLE_NAMES)
def test_no_repeated_holes_and_no_dense_places_every_needle_point_counted(drawing, style):
    plan = plan_embroidery(DRAWINGS[drawing](), PlanOptions(style=style_options(style)))
    assert repeated_penetrations(plan) == 0
    density = worst_density(plan)
    assert density <= 6
    # The stats report the same worst density, and no warning when it is fine.
    stats = embroidery_stats(plan)
    assert stats.max_density == density and not stats.too_dense


def test_the_penetration_check_sees_a_bean_stitch_in_the_same_holes():
    """The measure is not blind: the classic bean stitch (0, 1, 0, 1, 2, 1, 2 ...) re-enters
    its holes two penetrations later, and is caught."""
    plan = plan_embroidery(Drawing((_line([0, 0], [20, 0]),), 20, 1, "mm"),
                           PlanOptions(style=style_options("running")))
    rows = np.flatnonzero(plan.roles == 0)  # body rows
    bean = np.concatenate([[rows[0]], np.ravel([[i, i - 1, i] for i in rows[1:]])])
    order = np.concatenate([np.arange(rows[0]), bean, np.arange(rows[-1] + 1, len(plan))])
    from dataclasses import replace

    copied = replace(plan, points=plan.points[order], kinds=plan.kinds[order], roles=plan.roles[order],
                     params=plan.params[order], strokes=plan.strokes[order], blocks=plan.blocks[order])
    assert repeated_penetrations(copied) > 0


@pytest.mark.parametrize("style, options, flag", [
    ("running", dict(stitch_length=9.0), "--stitch-length"),
    ("triple", dict(stitch_length=9.0), "--stitch-length"),
    ("arrows", dict(size=8.0, width=6.0, spacing=12.0), "--arrow-size"),
    ("zigzag", dict(width=11.0), "--stitch-width"),
])
def test_long_stitches_are_warned_about_naming_the_option(style, options, flag):
    drawing = Drawing((_line([0, 0], [60, 0]), _line([60, 10], [0, 30])), 60, 30, "mm")
    job = EmbroideryJob(placement=PlacementOptions(size=60.0), hoop=hoop_named("130x180"),
                        plan=PlanOptions(style=style_options(style, **options)))
    result = embroider(drawing, job)
    assert any("snag" in w and flag in w for w in result.warnings), result.warnings
    quiet = embroider(drawing, EmbroideryJob(placement=PlacementOptions(size=60.0), hoop=hoop_named("130x180"),
                                             plan=PlanOptions(style=style_options(style))))
    assert not any("snag" in w for w in quiet.warnings)


def test_a_speck_next_to_a_stroke_is_joined_by_travel_stitches_without_a_knot():
    spur = _line([30.3, 0.2], [30.5, 0.5])  # 0.36 mm, 0.36 mm from the line's end
    drawing = Drawing((_line([0, 0], [30, 0]), spur, _line([30.5, 3], [30.5, 20])), 40, 20, "mm")
    plan = plan_embroidery(drawing, PlanOptions())
    needle = plan.kinds == STITCH
    # One tack per chain, one lock: the spur has neither of its own; its stitches travel.
    spur_rows = np.flatnonzero(needle & (plan.strokes == 1))
    assert len(spur_rows) and set(plan.roles[spur_rows]) <= {TRAVEL, LOCK}
    assert (plan.roles[needle] == LOCK).sum() == 2 * 4  # the line+spur chain, the last line
    assert (plan.roles[needle] == TACK).sum() == 5 + 4  # the second is reached by a travel stitch
    assert not plan.dropped
    # No knot: counting every needle point, locks included, around the spur.
    pts = plan.points[needle]
    around = np.linalg.norm(pts - np.array([30.4, 0.35]), axis=1) < 0.5
    assert around.sum() <= 6


def test_a_lone_speck_is_left_out_with_a_warning_naming_it():
    drawing = Drawing((_line([0, 0], [30, 0]), _line([10, 15], [10.4, 15.2])), 30, 20, "mm")
    result = embroider(drawing, EmbroideryJob(placement=PlacementOptions(size=30.0)))
    assert set(np.unique(result.plan.strokes[result.plan.kinds == STITCH])) == {0}
    assert any(w.startswith("stroke 2 ") and "--min-stroke" in w for w in result.warnings), result.warnings
    # Its tack, lock and trim are gone with it: one run of thread, no trim.
    assert len(needle_runs(result.plan)) == 1
    # --min-stroke 0 sews it as before, with its own tack and lock.
    kept = plan_embroidery(result.drawing, PlanOptions(min_stroke=0.0))
    assert (kept.kinds != STITCH).any() and not kept.dropped


def test_every_stroke_still_starts_with_a_tack_and_ends_with_a_lock():
    plan = plan_embroidery(design(), PlanOptions(style=style_options("zigzag")))
    for run in needle_runs(plan):
        roles = plan.roles[run]
        assert roles[1] == TACK and roles[-1] == LOCK


@pytest.mark.parametrize("style", STYLE_NAMES)
@pytest.mark.parametrize("angle", [0.0, 37.0])
def test_a_short_stroke_just_above_min_stroke_never_knots(style, angle):
    """A 1.2 mm stroke (--min-stroke is 1 mm) used to get a full tack, its body and a full
    lock: 8 needle points within 0.5 mm (running, arrows), 11 (triple), 8-13 (zigzag).
    The tack and lock now give way where they would crowd it: every needle point
    counted, at most 6 within 0.5 mm; the stroke is still sewn and still secured (a lock,
    or a body that goes back over itself)."""
    u = np.array([np.cos(np.radians(angle)), np.sin(np.radians(angle))])
    drawing = Drawing((_line([0.0, 0.0], 1.2 * u), _line([20.0, 0.0], [40.0, 0.0])), 40, 2, "mm")
    plan = plan_embroidery(drawing, PlanOptions(style=style_options(style)))
    assert worst_density(plan) <= 6
    assert embroidery_stats(plan).max_density == worst_density(plan)
    short = np.flatnonzero((plan.kinds == STITCH) & (plan.strokes == 0))
    assert len(short) >= 2 and not plan.dropped
    roles = plan.roles[short]
    # Secured: the thread passes over the stroke at least twice before the trim.
    along = plan.points[short] @ u
    assert (roles[-1] == LOCK) or np.sum(np.diff(along) < 0) >= 1
    # The long stroke keeps its full tack and lock.
    long_rows = np.flatnonzero((plan.kinds == STITCH) & (plan.strokes == 1))
    assert (plan.roles[long_rows[1:5]] == TACK).all() and (plan.roles[long_rows[-4:]] == LOCK).all()
    # What was made lighter is on record, at the short stroke. A zigzag this short has no
    # underlay (it would re-enter its own first hole), and its tack and lock fit in full.
    assert all(np.hypot(t.x, t.y) < 1.3 for t in plan.lighter)
    assert bool(plan.lighter) == (style != "zigzag")
    assert repeated_penetrations(plan) == 0


def test_a_dropped_speck_is_measured_to_the_nearest_stitch_of_its_thread():
    """The warning used to measure from the neighbouring strokes' ends only; it now gives
    the distance to the nearest needle point of the speck's thread, and says why a speck
    near the middle of a stroke is still left out."""
    line = _line([0.0, 0.0], [30.0, 0.0])
    beside = _line([15.0, 1.5], [15.4, 1.7])  # 1.5 mm from the line's middle, 15 mm from its ends
    far = _line([10.0, 12.0], [10.4, 12.2])
    other = _line([0.0, 25.0], [30.0, 25.0])
    drawing = Drawing((line, beside, far, other), 30, 25, "mm")
    plan = plan_embroidery(drawing, PlanOptions())
    assert len(plan.dropped) == 2
    needles = plan.points[plan.kinds == STITCH]
    near_beside = np.linalg.norm(needles - beside.points_at(np.linspace(0, 1, 9))[:, None], axis=2).min()
    near_far = np.linalg.norm(needles - far.points_at(np.linspace(0, 1, 9))[:, None], axis=2).min()
    assert near_beside < 3.0 < near_far
    first, second = plan.dropped
    assert first.startswith("stroke 2 ") and f"nearest stitch of its thread, {near_beside:.1f} mm" in first
    assert "sewn before and after it end more than --trim-distance 3 mm away" in first
    assert second.startswith("stroke 3 ") and f"every stitch of its thread (the nearest is {near_far:.1f} mm" in second


@pytest.mark.parametrize("style", ["running", "triple", "arrows"])
def test_a_retraced_spike_is_sewn_back_in_fresh_holes(style):
    """Out along a line and back along the same line (the vectorizer's retraced spikes):
    equal stitches on the way back used to pierce the holes of the way out (2 on the spike
    example drawing); triple stitch's base holes keep clear of its passes' holes too."""
    spike = Stroke.from_polyline(np.array([[0.0, 0.0], [8.0, 0.0], [13.0, 1.0], [8.0, 0.0], [8.0, 9.0]]))
    plan = plan_embroidery(Drawing((spike,), 13, 9, "mm"), PlanOptions(style=style_options(style)))
    assert repeated_penetrations(plan) == 0
    assert worst_density(plan) <= 6
    # The tip still gets its needle point.
    assert np.linalg.norm(plan.points - [13.0, 1.0], axis=1).min() < 0.08

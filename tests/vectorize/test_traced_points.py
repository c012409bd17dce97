"""The traced points as `fit_stroke` holds them (`vectorize.fit.traced`): one record per point,
whose marks travel with it when a closed line is opened at its top-left split."""

import numpy as np

from vectorize.fit.fitting import _opened
from vectorize.fit.retraces import Twin
from vectorize.fit.traced import POINT, point_records


def _square(side: int = 20) -> np.ndarray:
    """(4 * side + 1, 2) px: a closed square traced counter-clockwise one px a step from the
    middle of its bottom side, the first point repeated last."""
    corners = np.array([[0, side], [side, side], [side, 0], [0, 0], [0, side]], dtype=float) + 5.0
    way = np.concatenate([np.linspace(a, b, side, endpoint=False) for a, b in zip(corners[:-1], corners[1:])])
    way = np.roll(way, -side // 2, axis=0)
    return np.vstack([way, way[:1]])


def test_a_record_per_point_holds_its_marks_and_a_field_marks_the_points():
    xy = np.array([[0.0, 0.0], [1.0, 0.5], [2.0, 1.0]])
    points = point_records(xy, keep=np.array([1, 0, 1]), split=None, held=np.array([1.0, 3.0, 1.0]))
    assert points.dtype == POINT and points.shape == (3,)
    np.testing.assert_array_equal(points["xy"], xy)
    assert points["keep"].tolist() == [True, False, True]
    assert not points["split"].any() and not points["corner"].any() and not points["junction"].any()
    assert points["held"].tolist() == [1.0, 3.0, 1.0]
    corner = points["corner"]
    corner[1] = True  # a field is a view: marking it marks the point
    assert bool(points[1]["corner"]) and not bool(points[0]["corner"])


def test_a_closed_line_opens_at_its_top_left_split_with_every_mark_on_its_own_point():
    xy = _square()
    n = len(xy) - 1  # distinct points
    at_corner = np.isin(np.arange(len(xy)), [i for i in range(n) if xy[i][0] in (5.0, 25.0)
                                              and xy[i][1] in (5.0, 25.0)])
    rng = np.random.default_rng(0)
    keep = rng.random(len(xy)) > 0.2
    held = np.arange(len(xy), dtype=float)  # tells each point apart
    points = point_records(xy, keep=keep, split=at_corner, corner=at_corner, held=held)
    # A stretch the line draws twice, by point index: it must follow its points too.
    twins = [Twin((12, 14), (30, 32), False)]
    points["xy"][30:33] = points["xy"][12:15]
    opened, moved = _opened(points, twins)

    assert len(opened) == n + 1
    np.testing.assert_array_equal(opened["xy"][0], [5.0, 5.0])  # the top-left corner
    assert opened[0] == opened[-1]
    for record in opened[:-1]:
        # the point it was (held is its old index): every mark came along
        assert record == points[int(record["held"])]
    shift = int(opened["held"][0])
    assert moved == [Twin(((12 - shift) % n, (14 - shift) % n), ((30 - shift) % n, (32 - shift) % n), False)]

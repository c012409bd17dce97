"""The rules a generated drawing must pass (benchmarks/sets/drawings.py): unambiguous for a human,
hard for the vectorizer. `validate` returns the events and crossings it finds, or raises
`Rejected`."""

from __future__ import annotations

import numpy as np
import shapely
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from benchmarks.metrics.ground_truth import CANVAS, MARGIN, Event, Rejected
from benchmarks.metrics.table1 import ambiguous_junctions, close_passes, polyline_intersections
from vectorize.stroke import Stroke


def _curvature_ok(stroke: Stroke, spike_segments: set[int], min_radius: float) -> bool:
    c = stroke.control
    t = np.linspace(0, 1, 33)[None, :, None]
    u = 1 - t
    d1 = 3 * (u * u * (c[:, None, 1] - c[:, None, 0]) + 2 * u * t * (c[:, None, 2] - c[:, None, 1])
              + t * t * (c[:, None, 3] - c[:, None, 2]))
    d2 = 6 * (u * (c[:, None, 2] - 2 * c[:, None, 1] + c[:, None, 0]) + t * (c[:, None, 3] - 2 * c[:, None, 2]
                                                                               + c[:, None, 1]))
    speed = np.linalg.norm(d1, axis=2)
    cross = np.abs(d1[..., 0] * d2[..., 1] - d1[..., 1] * d2[..., 0])
    mask = np.ones(len(c), dtype=bool)
    if spike_segments:
        mask[list(spike_segments)] = False
    if np.any(speed[mask] < 1e-6):
        return False
    radius = speed[mask] ** 3 / np.maximum(cross[mask], 1e-12)
    return bool(radius.min() >= min_radius)


def _match_designed(found: np.ndarray, designed: list, extra: str, missing: str) -> None:
    """Every found point is a designed one and every designed point is found (within 0.5 px)."""
    for p in found:
        if not any(np.linalg.norm(p - d) < 0.5 for d in designed):
            raise Rejected(extra)
    for d in designed:
        if not any(np.linalg.norm(p - d) < 0.5 for p in found):
            raise Rejected(missing)


def validate(stroke: Stroke, closed: bool, width: float, designed: list, spikes: list) -> tuple[list, np.ndarray, list]:
    """Check the rules; return (events, crossing points, dont-care geometries) or raise Rejected."""
    w = width
    xmin, ymin, xmax, ymax = stroke.bounds()
    if xmin < MARGIN + w or ymin < MARGIN + w or xmax > CANVAS - MARGIN - w or ymax > CANVAS - MARGIN - w:
        raise Rejected("outside the canvas")
    spike_segments = {s[2] for s in spikes} | {s[2] + 1 for s in spikes}
    if not _curvature_ok(stroke, spike_segments, 0.75 * w):
        raise Rejected("tight bend")
    poly = stroke.flatten(0.05)
    if spikes and ambiguous_junctions(poly):
        raise Rejected("a spike next to a free end: which branch is retraced is ambiguous")
    inter = polyline_intersections([poly], [closed])
    _match_designed(inter.multiple, [e for k, e, _ in designed if k == "triple"], "three passes meet",
                    "designed triple point missing")
    if np.any(inter.crossing_angles < 5.0):
        raise Rejected("crossing shallower than 5 degrees")
    _match_designed(inter.touches, [e for k, e, _ in designed if k == "touch"], "accidental touch",
                    "designed touch did not come out as a touch")
    for k, e, ang in designed:
        if k in ("shallow", "transversal"):
            hit = np.linalg.norm(inter.crossings - e, axis=1) < 0.5 if len(inter.crossings) else np.array([False])
            if not hit.any():
                raise Rejected("designed crossing missing")

    events: list[Event] = []
    for p, ang in zip(inter.crossings, inter.crossing_angles):
        events.append(Event("crossing", p, float(ang), w / (2 * np.sin(np.radians(ang) / 2))))
    for k, e, ang in designed:
        if k in ("touch", "near-touch"):
            events.append(Event(k, np.asarray(e, dtype=float)))
        elif k == "triple":  # ang: the smallest angle between two of its three passes
            events.append(Event(k, np.asarray(e, dtype=float), ang, w / (2 * np.sin(np.radians(ang) / 2))))

    # contacts: two samples closer than one width that are more than 3 widths apart along the line
    spacing = w / 4
    s, pts, pairs = close_passes(stroke, closed, w)
    # spikes: the retrace itself and the line passing its base are not contacts
    spike_ranges = []
    seg_len = np.array([Stroke(stroke.control[k:k + 1]).length for k in range(stroke.segment_count)])
    seg_start = np.concatenate([[0], np.cumsum(seg_len)])
    for gid, (base, tip, seg) in enumerate(spikes):
        lo, hi = seg_start[seg] - 2 * w, seg_start[seg + 2] + 2 * w
        spike_ranges.append((lo, hi))
        events.append(Event("spike-base", base, radius=w, group=1000 + gid))
        events.append(Event("spike-tip", tip, radius=0.5 * w, group=1000 + gid))
        # nothing else may come near the spike's shaft
        shaft = shapely.LineString([base, tip])
        far = (s < lo - 4 * w) | (s > hi + 4 * w)
        if closed:
            far &= (s > hi + 4 * w - stroke.length) & (s < lo - 4 * w + stroke.length)
        if far.any():
            dist = shapely.distance(shaft, shapely.points(pts[far]))
            if np.min(dist) < 2.5 * w:
                raise Rejected("line passes near a spike")
    if spike_ranges:
        internal = np.zeros(len(pairs), dtype=bool)
        for lo, hi in spike_ranges:
            a_in = (s[pairs[:, 0]] >= lo) & (s[pairs[:, 0]] <= hi)
            b_in = (s[pairs[:, 1]] >= lo) & (s[pairs[:, 1]] <= hi)
            internal |= a_in & b_in
        pairs = pairs[~internal]
    if not closed:
        events.append(Event("end", pts[0], radius=0.5 * w, group=2000))
        events.append(Event("end", pts[-1], radius=0.5 * w, group=2001))
    meeting_events = [e for e in events if e.kind in ("crossing", "touch", "near-touch", "triple")]
    if len(pairs):
        idx = np.unique(pairs)
        cp = pts[idx]
        near = cKDTree(cp).query_pairs(2.0 * spacing, output_type="ndarray")
        g = coo_matrix((np.ones(len(near)), (near[:, 0], near[:, 1])), shape=(len(cp), len(cp)))
        ncl, label = connected_components(g, directed=False)
        radius = {}
        for c in range(ncl):
            cluster = cp[label == c]
            inside = [m for m, e in enumerate(meeting_events)
                      if np.min(np.linalg.norm(cluster - e.point, axis=1)) <= w]
            if len(inside) != 1:
                raise Rejected("ink merges where no single crossing or touch explains it")
            m = inside[0]
            radius[m] = max(radius.get(m, 0.0), float(np.max(np.linalg.norm(cluster - meeting_events[m].point,
                                                                              axis=1))))
        for m, e in enumerate(meeting_events):
            if e.kind in ("touch", "near-touch"):
                r = radius.get(m, 0.0)
                if r == 0.0 and e.kind == "near-touch":
                    raise Rejected("near-touch does not merge")
                if r > 8 * w:
                    raise Rejected("touch merges over too long a run")
                idx_e = events.index(e)
                events[idx_e] = Event(e.kind, e.point, e.angle, max(r, 0.5 * w), e.group)
    # separation of events: merge zones at least 3 widths apart
    for i in range(len(events)):
        for j in range(i + 1, len(events)):
            ei, ej = events[i], events[j]
            if ei.group >= 0 and ei.group == ej.group:
                continue
            if ei.kind == "end" and ej.kind == "end":
                continue
            need = ei.radius + ej.radius + 3 * w
            if np.linalg.norm(ei.point - ej.point) < need:
                raise Rejected(f"{ei.kind} and {ej.kind} too close")
    # the whole ink-merge zone of a touch: the output's two passes share one blob of ink there
    dont_care = [shapely.Point(*e.point).buffer(e.radius) for e in events
                 if e.kind in ("touch", "near-touch", "triple")]
    dont_care += [shapely.LineString([b, t]) for b, t, _ in spikes]
    dont_care += list(inter.retraces)
    return events, inter.crossings, dont_care

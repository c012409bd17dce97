"""Phone photos of pen drawings on paper: the geometry (a slight perspective) and the picture
(uneven light, a shadow, paper texture, lens blur, sensor noise, colour, JPEG).

`photographed(gt, rng)` moves a ground truth into the photo's frame: the page seen from a
little off-axis, a homography that moves each canvas corner by up to 4 % of the side
(inward or outward, then fitted back inside the canvas margin). Centre lines are flattened
(0.05 px) and mapped point by point; the ink width follows the local scale of the map
(sqrt of its Jacobian determinant) as meta "width_profile" (see benchmarks/common/render.py);
crossings, events, don't-care zones and the minimum traversal length move with it.

`photo_image(gray, rng)` takes the render (flat ink on white, in the photo's frame) to what
the phone stores (`conditions.py` calls it for the condition "photo"):

- paper reflectance 0.82-0.95 with texture (fine grain and longer fibres, about 2 %), ink
  reflectance 0.06-0.22 (a ballpoint or felt pen, sometimes blue-black);
- light: a linear falloff across the page to 65-90 %, vignetting (corners about 15 % darker)
  and the soft shadow of the phone or a hand (a half-plane with a 20-80 px penumbra, light
  down to 55-80 %);
- the camera: a slight defocus (Gaussian 0.5-1.0 px), luminance noise (about 1.5 %), a warm
  white balance, JPEG at quality 70-90 with chroma subsampling. RGB uint8 out.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import shapely
from scipy import ndimage

from benchmarks.common.render import through_jpeg
from benchmarks.metrics.ground_truth import CANVAS, MARGIN, GroundTruth
from benchmarks.metrics.table1 import FLATTEN_TOLERANCE
from vectorize.drawing import Drawing
from vectorize.stroke import Stroke, arc_lengths

TILT = 0.04  # largest corner move, share of the canvas side


def random_homography(rng: np.random.Generator) -> np.ndarray:
    """A 3x3 homography of the canvas that moves each corner by up to TILT of its side."""
    from skimage.transform import ProjectiveTransform

    src = np.array([[0, 0], [CANVAS, 0], [CANVAS, CANVAS], [0, CANVAS]], dtype=float)
    dst = src + rng.uniform(-TILT, TILT, (4, 2)) * CANVAS
    if hasattr(ProjectiveTransform, "from_estimate"):
        return ProjectiveTransform.from_estimate(src, dst).params
    t = ProjectiveTransform()
    t.estimate(src, dst)
    return t.params


def apply_homography(h: np.ndarray, pts: np.ndarray) -> np.ndarray:
    pts = np.asarray(pts, dtype=float).reshape(-1, 2)
    q = np.c_[pts, np.ones(len(pts))] @ h.T
    return q[:, :2] / q[:, 2:]


def local_scale(h: np.ndarray, pts: np.ndarray, step: float = 0.5) -> np.ndarray:
    """sqrt(|det J|) of the homography at `pts` (central differences)."""
    dx = (apply_homography(h, pts + [step, 0]) - apply_homography(h, pts - [step, 0])) / (2 * step)
    dy = (apply_homography(h, pts + [0, step]) - apply_homography(h, pts - [0, step])) / (2 * step)
    return np.sqrt(np.abs(dx[:, 0] * dy[:, 1] - dx[:, 1] * dy[:, 0]))


def _fit_inside(h: np.ndarray, pts: np.ndarray, width: float) -> np.ndarray:
    """`h` followed by the similarity that brings the mapped points inside the margin (only
    when they leave it)."""
    q = apply_homography(h, pts)
    lo, hi = q.min(axis=0), q.max(axis=0)
    room = CANVAS - 2 * (MARGIN + width + 2)
    s = min(1.0, room / max((hi - lo).max(), 1e-9))
    centre = (lo + hi) / 2
    shift = np.clip(CANVAS / 2 - s * centre, MARGIN + width + 2 - s * lo, CANVAS - MARGIN - width - 2 - s * hi)
    return np.array([[s, 0, shift[0]], [0, s, shift[1]], [0, 0, 1.0]]) @ h


def photographed(gt: GroundTruth, rng: np.random.Generator) -> GroundTruth:
    """`gt` as the photo's frame sees it (module doc); kind "photo", meta condition "photo"."""
    poly = gt.stroke.flatten(FLATTEN_TOLERANCE)
    h = _fit_inside(random_homography(rng), poly, gt.width)
    mapped = apply_homography(h, poly)
    if gt.closed:
        mapped[-1] = mapped[0]
    stroke = Stroke.from_polyline(mapped)
    s = arc_lengths(mapped)
    profile = (s / s[-1], gt.width * local_scale(h, poly))
    if "width_profile" in gt.meta:  # a brush's width, foreshortened too
        from benchmarks.common.render import profile_widths

        base = profile_widths(gt.meta["width_profile"], arc_lengths(poly) / gt.stroke.length)
        profile = (profile[0], base * profile[1] / gt.width)

    def move(g):
        if isinstance(g, shapely.Geometry):
            return shapely.transform(g, lambda xy: apply_homography(h, xy))
        return apply_homography(h, g).reshape(np.shape(g))

    meta = {**gt.meta, "condition": "photo", "width_profile": profile, "source": gt.name,
            "homography": h.tolist()}
    for key in ("min_length", "route_min"):
        if key in meta:
            meta[key] = meta[key] * stroke.length / gt.stroke.length
    drawing = Drawing((stroke,), gt.drawing.width, gt.drawing.height, unit=gt.drawing.unit,
                      stroke_width=float(np.max(profile[1])))
    return replace(gt, name=f"photo-{gt.name}", kind="photo", drawing=drawing,
                   intersections=move(gt.intersections).reshape(-1, 2),
                   events=tuple(replace(e, point=move(e.point)) for e in gt.events),
                   dont_care=tuple(move(z) for z in gt.dont_care), meta=meta)


def photo_image(gray: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """The phone's JPEG of a page whose flat render is `gray` ((H, W) in [0, 1]): (H, W, 3)
    uint8 (module doc)."""
    h, w = gray.shape
    yy, xx = np.mgrid[0:h, 0:w] / max(h, w)
    grain = ndimage.gaussian_filter(rng.normal(size=(h, w)), 0.7)
    fibres = ndimage.gaussian_filter(rng.normal(size=(h, w)), (1.0, 6.0))
    paper = rng.uniform(0.82, 0.95) * (1.0 + 0.02 * grain / (grain.std() + 1e-12)
                                       + 0.015 * fibres / (fibres.std() + 1e-12))
    ink = rng.uniform(0.06, 0.22)
    reflect = ink + (paper - ink) * gray
    angle = rng.uniform(0, 2 * np.pi)
    ramp = np.cos(angle) * (xx - 0.5) + np.sin(angle) * (yy - 0.5)
    light = 1.0 - (1.0 - rng.uniform(0.65, 0.9)) * (ramp - ramp.min()) / (np.ptp(ramp) + 1e-12)
    light *= 1.0 - 0.3 * ((xx - 0.5) ** 2 + (yy - 0.5) ** 2)
    # the shadow of the phone or a hand: a half-plane with a soft edge over part of the page
    edge_angle = rng.uniform(0, 2 * np.pi)
    side = np.cos(edge_angle) * (xx - 0.5) + np.sin(edge_angle) * (yy - 0.5) - rng.uniform(0.1, 0.35)
    penumbra = rng.uniform(20.0, 80.0) / max(h, w)
    shade = 1.0 / (1.0 + np.exp(-side / (penumbra / 4)))
    light *= 1.0 - (1.0 - rng.uniform(0.55, 0.8)) * shade
    lum = ndimage.gaussian_filter(reflect * light, rng.uniform(0.5, 1.0))
    lum = lum + rng.normal(0.0, 0.015, lum.shape) * np.sqrt(np.clip(lum, 0.0, 1.0))
    tint = np.array([1.0, 0.97, 0.88]) if rng.uniform() < 0.5 else np.array([1.0, 0.98, 0.93])
    rgb = lum[..., None] * tint
    if rng.uniform() < 0.3:  # blue-black ink: the ink's own colour where it covers the paper
        rgb = rgb * (1.0 - 0.5 * (1.0 - gray[..., None]) * np.array([0.5, 0.35, 0.0]))
    rgb8 = np.clip(np.round(rgb * 255.0), 0, 255).astype(np.uint8)
    return through_jpeg(rgb8, int(rng.integers(70, 91)), subsampling=2)

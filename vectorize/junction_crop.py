"""Image crops around degree-4 junctions, the input of the intersection CNN.

The same function cuts the crops at inference (`vectorize.cnn_classifier`) and in the
synthetic training data (`vectorize.training.synth`), so the network sees at run time
exactly the kind of picture it was trained on.

Each junction gets two square crops of `CropSpec.size` px, both centred on the junction
and both scaled to the drawing's stroke width w:

- near (channel 0): `near_span` w wide — the contact itself (how wide the merged ink is,
  whether the strokes swap sides);
- far (channel 1): `far_span` w wide — where the four branches go. Shallow crossings need
  this: at 5 degrees two strokes of width w only separate ~w / sin(5 deg) = 11 w away.

Both crops are rotated so that the principal axis of the ink around the junction lies
along x. That removes most of the orientation variety the small network would otherwise
have to learn; the remaining symmetries (90-degree turns and flips) are exact and are
used for test-time augmentation. Values are ink strength normalised per junction: 0 =
paper (also outside the image), 1 = the darkest ink of the near crop.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
from scipy import ndimage

from onestroke.errors import InputError


@dataclass(frozen=True, kw_only=True)
class CropSpec:
    """Geometry of the junction crops; stored in the model's metadata and checked on load.

    size: side of each crop in px; near_span, far_span: crop sides in stroke widths;
    axis_sigma: Gaussian window (in stroke widths) of the ink moments that orient the crop.
    """

    size: int = 48
    near_span: float = 8.0
    far_span: float = 32.0
    axis_sigma: float = 4.0

    def to_dict(self) -> dict:
        return asdict(self)


def _prefilter(gray: np.ndarray, ratio: float) -> tuple[np.ndarray, float]:
    """Anti-alias `gray` for sampling at `ratio` image px per crop px.

    Returns the filtered image and the factor f by which it was block-reduced (a pixel
    (i, j) of the result covers pixels [f i, f i + f) of the input).
    """
    f = max(1, int(np.floor(ratio)))
    img = gray
    if f >= 2:
        h, w = img.shape
        ph, pw = (-h) % f, (-w) % f
        # White padding: outside the image is paper.
        img = np.pad(img, ((0, ph), (0, pw)), constant_values=1.0)
        img = img.reshape(img.shape[0] // f, f, img.shape[1] // f, f).mean(axis=(1, 3))
    residual = ratio / f
    if residual > 1.0:
        img = ndimage.gaussian_filter(img, sigma=0.5 * residual, mode="constant", cval=1.0)
    return img.astype(np.float32, copy=False), float(f)


def _sample(img: np.ndarray, f: float, xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
    """Bilinear samples of a (possibly f-reduced) image at image-px coordinates."""
    coords = np.stack([(ys + 0.5) / f - 0.5, (xs + 0.5) / f - 0.5])
    return ndimage.map_coordinates(img, coords, order=1, mode="constant", cval=1.0)


def _unit_grid(size: int) -> tuple[np.ndarray, np.ndarray]:
    """Pixel-centre offsets of a size x size crop in units of the crop side, in (-0.5, 0.5)."""
    u = (np.arange(size) + 0.5) / size - 0.5
    return np.meshgrid(u, u)  # gx varies along columns (x), gy along rows (y)


def principal_angles(gray: np.ndarray, centers: np.ndarray, stroke_width: float,
                     spec: CropSpec) -> np.ndarray:
    """Angle (rad) of the ink's principal axis around each centre; (N, 2) -> (N,)."""
    n_axis = 33
    span = 6.0 * spec.axis_sigma * stroke_width
    ratio = span / n_axis
    img, f = _prefilter(gray, ratio)
    gx, gy = _unit_grid(n_axis)
    ox, oy = gx * span, gy * span
    xs = centers[:, 0, None, None] + ox
    ys = centers[:, 1, None, None] + oy
    vals = _sample(img, f, xs.ravel(), ys.ravel()).reshape(xs.shape)
    paper = np.percentile(vals, 90, axis=(1, 2))[:, None, None]
    ink = np.clip(paper - vals, 0.0, None)
    weight = ink * np.exp(-(ox**2 + oy**2) / (2.0 * (spec.axis_sigma * stroke_width) ** 2))
    sxx = (weight * ox * ox).sum(axis=(1, 2))
    syy = (weight * oy * oy).sum(axis=(1, 2))
    sxy = (weight * ox * oy).sum(axis=(1, 2))
    return 0.5 * np.arctan2(2.0 * sxy, sxx - syy)


def crop_junctions(gray: np.ndarray, centers: np.ndarray, stroke_width: float,
                   spec: CropSpec = CropSpec()) -> np.ndarray:
    """Near and far crops around each junction centre.

    Parameters
    ----------
    gray : (H, W) float in [0, 1], 1 = paper, 0 = ink (not thresholded).
    centers : (N, 2) junction positions, x right, y down, in px of `gray`.
    stroke_width : the drawing's stroke width in px (> 0).
    spec : crop geometry; must match the one the model was trained with.

    Returns
    -------
    (N, 2, size, size) float32: channel 0 near crop, channel 1 far crop, ink strength
    normalised to 0 = paper, 1 = darkest ink near the junction.
    """
    gray = np.asarray(gray, dtype=np.float32)
    centers = np.asarray(centers, dtype=float).reshape(-1, 2)
    if gray.ndim != 2 or gray.size == 0:
        raise InputError(f"gray image must be a non-empty 2-D array, got shape {gray.shape}")
    if not (np.isfinite(stroke_width) and stroke_width > 0):
        raise InputError(f"stroke width {stroke_width!r} must be a positive number of px")
    n, s = len(centers), spec.size
    out = np.zeros((n, 2, s, s), dtype=np.float32)
    if n == 0:
        return out
    angles = principal_angles(gray, centers, stroke_width, spec)
    c, si = np.cos(angles)[:, None, None], np.sin(angles)[:, None, None]
    gx, gy = _unit_grid(s)
    for ch, span in enumerate((spec.near_span, spec.far_span)):
        side = span * stroke_width
        img, f = _prefilter(gray, side / s)
        # Rotate the crop frame so its x axis runs along the principal axis.
        ox, oy = gx * side, gy * side
        xs = centers[:, 0, None, None] + c * ox - si * oy
        ys = centers[:, 1, None, None] + si * ox + c * oy
        out[:, ch] = _sample(img, f, xs.ravel(), ys.ravel()).reshape(n, s, s)
    # Normalise contrast per junction (pen, pencil, grey scans): paper level from the far
    # crop, ink level from the near crop, where the junction's own ink always is.
    paper = np.percentile(out[:, 1], 75, axis=(1, 2))
    ink = np.percentile(out[:, 0], 2, axis=(1, 2))
    contrast = np.maximum(paper - ink, 0.05)
    out = (paper[:, None, None, None] - out) / contrast[:, None, None, None]
    return np.clip(out, 0.0, 1.0).astype(np.float32)


def dihedral_copies(crops: np.ndarray) -> np.ndarray:
    """The 8 rotations-by-90-degrees and flips of each crop: (N, C, S, S) -> (8, N, C, S, S)."""
    copies = []
    for flip in (False, True):
        base = crops[..., ::-1] if flip else crops
        for k in range(4):
            copies.append(np.rot90(base, k=k, axes=(-2, -1)))
    return np.ascontiguousarray(np.stack(copies))

"""Image crops around degree-4 junctions, the input of the intersection CNN.

The same function cuts the crops at inference (`vectorize.junctions.cnn_classifier`) and in the
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


def _reduce(img: np.ndarray, f: int, sigma: float) -> np.ndarray:
    """Block-mean by f (image size a multiple of f), then Gaussian blur (white outside)."""
    if f >= 2:
        img = img.reshape(img.shape[0] // f, f, img.shape[1] // f, f).mean(axis=(1, 3))
    if sigma > 0.0:
        img = ndimage.gaussian_filter(img, sigma=sigma, mode="constant", cval=1.0)
    return img.astype(np.float32, copy=False)


def _sample_filtered(gray: np.ndarray, xs: np.ndarray, ys: np.ndarray, ratio: float) -> np.ndarray:
    """Bilinear samples of `gray` anti-aliased for `ratio` image px per sample spacing.

    xs, ys: (N, M) sample positions in image px (x right, y down) for N junctions. The
    image is block-reduced by f = floor(ratio) on a grid anchored at pixel (0, 0), then
    blurred with sigma = ratio / f / 2 (if > 1 px); outside the image is white paper.
    Filtering runs on a window around each junction's samples, or on the whole image when
    that is smaller: both give the same values, because windows are aligned to the block
    grid and padded past the blur kernel's reach.
    """
    f = max(1, int(np.floor(ratio)))
    residual = ratio / f
    sigma = 0.5 * residual if residual > 1.0 else 0.0
    reach = (int(4.0 * sigma + 0.5) if sigma > 0 else 0) + 2  # scipy's kernel radius + bilinear
    rx, ry = (xs + 0.5) / f - 0.5, (ys + 0.5) / f - 0.5  # positions in reduced pixels
    lo_x = np.floor(rx.min(axis=1)).astype(int) - reach
    hi_x = np.ceil(rx.max(axis=1)).astype(int) + reach + 1
    lo_y = np.floor(ry.min(axis=1)).astype(int) - reach
    hi_y = np.ceil(ry.max(axis=1)).astype(int) + reach + 1
    h, w = gray.shape
    whole_area = (-(-h // f) + 2 * reach) * (-(-w // f) + 2 * reach)
    if np.sum((hi_x - lo_x) * (hi_y - lo_y)) >= whole_area:
        lo_x[:], lo_y[:] = -reach, -reach
        hi_x[:], hi_y[:] = -(-w // f) + reach, -(-h // f) + reach
        windows = [(0, 0, 0, 0)]  # one shared window: the whole (padded) image
    else:
        windows = list(zip(lo_x, hi_x, lo_y, hi_y))
    out = np.empty(xs.shape, dtype=np.float32)
    cache: dict = {}
    for i in range(len(xs)):
        x0, x1, y0, y1 = int(lo_x[i]), int(hi_x[i]), int(lo_y[i]), int(hi_y[i])
        key = windows[0] if len(windows) == 1 else (x0, x1, y0, y1)
        if key not in cache:
            # The window in image px, white where it leaves the image.
            win = np.ones(((y1 - y0) * f, (x1 - x0) * f), dtype=np.float32)
            sy0, sy1 = max(y0 * f, 0), min(y1 * f, h)
            sx0, sx1 = max(x0 * f, 0), min(x1 * f, w)
            if sy1 > sy0 and sx1 > sx0:
                win[sy0 - y0 * f:sy1 - y0 * f, sx0 - x0 * f:sx1 - x0 * f] = gray[sy0:sy1, sx0:sx1]
            cache = {key: _reduce(win, f, sigma)}  # keep only the current window
        img = cache[key]
        coords = np.stack([ry[i] - y0, rx[i] - x0])
        out[i] = ndimage.map_coordinates(img, coords, order=1, mode="constant", cval=1.0)
    return out


def _unit_grid(size: int) -> tuple[np.ndarray, np.ndarray]:
    """Pixel-centre offsets of a size x size crop in units of the crop side, in (-0.5, 0.5)."""
    u = (np.arange(size) + 0.5) / size - 0.5
    return np.meshgrid(u, u)  # gx varies along columns (x), gy along rows (y)


def principal_angles(gray: np.ndarray, centers: np.ndarray, stroke_width: float,
                     spec: CropSpec) -> np.ndarray:
    """Angle (rad) of the ink's principal axis around each centre; (N, 2) -> (N,)."""
    n_axis = 33
    span = 6.0 * spec.axis_sigma * stroke_width
    gx, gy = _unit_grid(n_axis)
    ox, oy = gx * span, gy * span
    xs = centers[:, 0, None, None] + ox
    ys = centers[:, 1, None, None] + oy
    n = len(centers)
    vals = _sample_filtered(gray, xs.reshape(n, -1), ys.reshape(n, -1), span / n_axis).reshape(xs.shape)
    paper = np.percentile(vals, 90, axis=(1, 2))[:, None, None]
    ink = np.clip(paper - vals, 0.0, None)
    weight = ink * np.exp(-(ox**2 + oy**2) / (2.0 * (spec.axis_sigma * stroke_width) ** 2))
    sxx = (weight * ox * ox).sum(axis=(1, 2))
    syy = (weight * oy * oy).sum(axis=(1, 2))
    sxy = (weight * ox * oy).sum(axis=(1, 2))
    return 0.5 * np.arctan2(2.0 * sxy, sxx - syy)


def checked_crop_input(gray, centers, stroke_width: float) -> tuple[np.ndarray, np.ndarray]:
    """The image as float32 (H, W) and the crop centres as (N, 2); InputError for an empty
    or non-2-D image or a stroke width that is not a positive number of px."""
    gray = np.asarray(gray, dtype=np.float32)
    centers = np.asarray(centers, dtype=float).reshape(-1, 2)
    if gray.ndim != 2 or gray.size == 0:
        raise InputError(f"gray image must be a non-empty 2-D array, got shape {gray.shape}")
    if not (np.isfinite(stroke_width) and stroke_width > 0):
        raise InputError(f"stroke width {stroke_width!r} must be a positive number of px")
    return gray, centers


def crop_junctions(gray: np.ndarray, centers: np.ndarray, stroke_width: float,
                   spec: CropSpec = CropSpec()) -> np.ndarray:
    """Near and far crops around each junction centre.

    Parameters
    ----------
    gray : (H, W) float in [0, 1], 1 = paper, 0 = ink (not thresholded).
    centers : (N, 2) junction positions, x right, y down, in px of `gray`; pixel (row i,
        column j) has its centre at (x, y) = (j, i), as in scikit-image and the medial axis.
    stroke_width : the drawing's stroke width in px (> 0).
    spec : crop geometry; must match the one the model was trained with.

    Returns
    -------
    (N, 2, size, size) float32: channel 0 near crop, channel 1 far crop, ink strength
    normalised to 0 = paper, 1 = darkest ink near the junction.
    """
    gray, centers = checked_crop_input(gray, centers, stroke_width)
    n, s = len(centers), spec.size
    out = np.zeros((n, 2, s, s), dtype=np.float32)
    if n == 0:
        return out
    angles = principal_angles(gray, centers, stroke_width, spec)
    c, si = np.cos(angles)[:, None, None], np.sin(angles)[:, None, None]
    gx, gy = _unit_grid(s)
    for ch, span in enumerate((spec.near_span, spec.far_span)):
        side = span * stroke_width
        # Rotate the crop frame so its x axis runs along the principal axis.
        ox, oy = gx * side, gy * side
        xs = centers[:, 0, None, None] + c * ox - si * oy
        ys = centers[:, 1, None, None] + si * ox + c * oy
        out[:, ch] = _sample_filtered(gray, xs.reshape(n, -1), ys.reshape(n, -1), side / s).reshape(n, s, s)
    # Normalise contrast per junction (pen, pencil, grey scans): paper level from the far
    # crop, ink level from the near crop, where the junction's own ink always is.
    paper = np.percentile(out[:, 1], 75, axis=(1, 2))
    ink = np.percentile(out[:, 0], 2, axis=(1, 2))
    contrast = np.maximum(paper - ink, 0.05)
    out = (paper[:, None, None, None] - out) / contrast[:, None, None, None]
    return np.clip(out, 0.0, 1.0).astype(np.float32)


def _block_factors(stroke_width: float, spec: CropSpec) -> list[int]:
    """The block-reduction factors `_sample_filtered` uses for the orienting window and
    both crops at this stroke width."""
    n_axis_ratio = 6.0 * spec.axis_sigma * stroke_width / 33  # `principal_angles`' sampling
    ratios = [n_axis_ratio, spec.near_span * stroke_width / spec.size, spec.far_span * stroke_width / spec.size]
    return [max(1, int(np.floor(r))) for r in ratios]


def masked_window(gray: np.ndarray, ink: np.ndarray, margin: float, align: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """The part of `gray` covered by discs, everything else paper.

    Parameters
    ----------
    gray : (H, W) float in [0, 1], 1 = paper.
    ink : (K, 3) disc centres x, y and radii, px (`vectorize.junctions.junction_ink.own_ink`).
    margin : px added to every radius (the anti-aliased edge beyond the outline).
    align : the window's corner lies on multiples of this many px (block grids stay put).

    Returns
    -------
    window : (h, w) float32, 1 outside the discs and outside `gray`.
    corner : (2,) x, y px of the window's pixel (0, 0) in `gray`.
    """
    xy, r = ink[:, :2], ink[:, 2] + margin
    lo = np.floor((xy - r[:, None]).min(axis=0) / align).astype(int) * align
    hi = np.ceil((xy + r[:, None]).max(axis=0)).astype(int) + 1
    window = np.ones((hi[1] - lo[1], hi[0] - lo[0]), dtype=np.float32)
    h, w = gray.shape
    x0, y0, x1, y1 = max(lo[0], 0), max(lo[1], 0), min(hi[0], w), min(hi[1], h)
    if x1 <= x0 or y1 <= y0:
        return window, lo.astype(float)
    part = gray[y0:y1, x0:x1]
    rows, cols = np.nonzero(part < 1.0)  # only ink can be masked away
    px, py = (cols + x0).astype(float), (rows + y0).astype(float)
    keep = np.zeros(len(rows), dtype=bool)
    for start in range(0, len(xy), 32):
        # The discs come along lines, so 32 in a row lie close together: only the pixels
        # in their bounding box are tested against them.
        c, rr = xy[start:start + 32], r[start:start + 32]
        lo_c, hi_c = (c - rr[:, None]).min(axis=0), (c + rr[:, None]).max(axis=0)
        near = np.flatnonzero((px >= lo_c[0]) & (px <= hi_c[0]) & (py >= lo_c[1]) & (py <= hi_c[1]))
        d2 = (px[near, None] - c[None, :, 0]) ** 2 + (py[near, None] - c[None, :, 1]) ** 2
        keep[near] |= (d2 <= rr[None, :] ** 2).any(axis=1)
    window[rows[keep] + y0 - lo[1], cols[keep] + x0 - lo[0]] = part[rows[keep], cols[keep]]
    return window, lo.astype(float)


def crop_own_ink(gray: np.ndarray, centers: np.ndarray, inks: list[np.ndarray], stroke_width: float,
                 spec: CropSpec = CropSpec(), margin: float = 1.5) -> np.ndarray:
    """`crop_junctions` of each junction with only its own ink on paper.

    inks: per junction (K, 3) discs x, y, radius px of its ink (the rest of the image is
    masked to paper); margin: px added to every radius. The crops are those of the masked
    image: windows are aligned to the crops' block grids. Returns (N, 2, size, size) float32.
    """
    gray, centers = checked_crop_input(gray, centers, stroke_width)
    align = int(np.lcm.reduce(_block_factors(stroke_width, spec)))
    out = np.zeros((len(centers), 2, spec.size, spec.size), dtype=np.float32)
    for i, (center, ink) in enumerate(zip(centers, inks)):
        window, corner = masked_window(gray, np.asarray(ink, dtype=float).reshape(-1, 3), margin, align)
        out[i] = crop_junctions(window, (center - corner)[None], stroke_width, spec)[0]
    return out


def dihedral_copies(crops: np.ndarray) -> np.ndarray:
    """The 8 rotations-by-90-degrees and flips of each crop: (N, C, S, S) -> (8, N, C, S, S)."""
    copies = []
    for flip in (False, True):
        base = crops[..., ::-1] if flip else crops
        for k in range(4):
            copies.append(np.rot90(base, k=k, axes=(-2, -1)))
    return np.ascontiguousarray(np.stack(copies))

"""Preprocessing (paper 3.1): gray working image, optional blur, paper flattening, Li threshold,
ink components."""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from contextlib import nullcontext
from dataclasses import dataclass

import numpy as np
from scipy import ndimage
from scipy.spatial import cKDTree

from onestroke.errors import InputError
from onestroke.cores import idle_cores

MIN_SIDE = 16
# Paper darker than this (after shading) is not paper: the division stops there.
MIN_PAPER = 0.3
# Paper grain is taken to reach this many standard deviations below the paper level.
PAPER_SIGMAS = 4.5
MAX_PAPER_SIGMA = 0.1  # grain rougher than this is not paper (see paper_noise_floor)
# Ink touching the image edge with an inscribed radius above this fraction of the longest
# side (25 px of 1000: a band 50 px thick) is a frame around the drawing, not a line.
FRAME_RADIUS = 0.025


@dataclass(frozen=True, eq=False)
class InkImage:
    """The working image and its ink.

    gray: (H, W) float32 in [0, 1], 1 = paper (downscaled, blurred, shading divided out,
    specks and frame whitened);
    ink: (H, W) bool of the kept ink with small holes filled; threshold: the gray level of
    the ink boundary; scale: working px per input px; stroke_width: estimated ink width in
    px; frame: a dark frame along the image edge was ignored (see `frame_labels`).
    """

    gray: np.ndarray
    ink: np.ndarray
    threshold: float
    scale: float
    stroke_width: float
    frame: bool = False


GRAY_ROWS = 256  # rows of a colour image converted at a time (see `to_gray`)


def to_gray(image: np.ndarray) -> np.ndarray:
    """Luminance in [0, 1] with alpha composited over white: (H, W) float32.

    A colour image is converted GRAY_ROWS rows at a time: each pixel's value is what the
    whole image at once gives, but a phone photo (4000 x 3000 x 3 bytes) no longer needs two
    float copies of all its channels (290 MB) on the way to its 48 MB of gray."""
    image = np.asarray(image)
    if image.ndim == 3 and image.shape[2] in (2, 3, 4) and len(image) > GRAY_ROWS:
        out = np.empty(image.shape[:2], dtype=np.float32)
        for top in range(0, len(image), GRAY_ROWS):
            out[top:top + GRAY_ROWS] = _to_gray(image[top:top + GRAY_ROWS])
        return out
    return _to_gray(image)


def _to_gray(image: np.ndarray) -> np.ndarray:
    if image.dtype in (np.uint8, np.uint16):
        data = image.astype(np.float32)
        data /= np.float32(255.0 if image.dtype == np.uint8 else 65535.0)  # in place: one array, not two
    elif image.dtype == bool:
        data = (~image).astype(np.float32)
    else:
        data = np.clip(image.astype(np.float32), 0.0, 1.0)
    if data.ndim == 2:
        return data
    if data.ndim != 3 or data.shape[2] not in (2, 3, 4):
        raise InputError(f"image of shape {image.shape} is neither gray nor RGB(A)")
    if data.shape[2] in (2, 4):
        color, alpha = data[..., :-1], data[..., -1:]
        data = color * alpha + (1.0 - alpha)
    if data.shape[2] == 1:
        return data[..., 0]
    return (data[..., :3] @ np.array([0.2126, 0.7152, 0.0722], dtype=np.float32)).astype(np.float32)


def working_gray(image: np.ndarray, *, max_size: int, blur: float) -> tuple[np.ndarray, float]:
    """Gray image downscaled (anti-aliased) so its longest side is <= max_size, then blurred
    (`blurred`); and the scale."""
    gray, scale = downscaled_gray(image, max_size=max_size)
    return blurred(gray, blur), scale


def downscaled_gray(image: np.ndarray, *, max_size: int) -> tuple[np.ndarray, float]:
    """Gray image downscaled (anti-aliased) so its longest side is <= max_size: (H, W)
    float32 in [0, 1], and the scale (what a blur does not change)."""
    gray = to_gray(image)
    h, w = gray.shape
    if min(h, w) < MIN_SIDE:
        raise InputError(f"image is {w}x{h} px: too small for a drawing (need at least {MIN_SIDE} px a side)")
    scale = 1.0
    # skimage.transform and skimage.filters are imported where used: most inputs need
    # neither a downscale nor a blur, and a command pays for every import at start-up.
    if max(h, w) > max_size:
        from skimage.transform import rescale

        scale = max_size / max(h, w)
        gray = rescale(gray, scale, anti_aliasing=True, preserve_range=True).astype(np.float32)
    return gray, scale


GAUSS_TRUNCATE = 4.0  # skimage.filters.gaussian's: the kernel reaches int(4 sigma + 0.5) px


def blurred(gray: np.ndarray, blur: float, *, threads: int | None = None) -> np.ndarray:
    """`gray` (H, W) float32 blurred by a Gaussian of sigma `blur` px
    (`skimage.filters.gaussian`, edges extended), a new array; `gray` itself when blur is 0.

    Only the box around the pixels that are not pure white, grown by the kernel's reach, is
    filtered: beyond it every window is white, which the filter leaves exactly white (its
    weights sum to 1 within far less than a float32 step: checked on a white patch), and
    inside it the box's white edge extended is what the whole image has there. A clean
    drawing's paper is mostly such white; the filter over it was most of a blur's time.
    threads: 2 or more filters the box's top and bottom halves side by side (None: while
    the machine has a core to spare), each with the kernel's reach of rows beyond its half:
    every pixel of a half is then the same weighted sum of the same pixels (the filter goes
    down the columns, then along the rows)."""
    if blur <= 0:
        return gray
    from skimage.filters import gaussian

    def blur_of(part: np.ndarray) -> np.ndarray:
        return gaussian(part, sigma=blur, preserve_range=True, truncate=GAUSS_TRUNCATE).astype(np.float32, copy=False)

    reach = int(GAUSS_TRUNCATE * blur + 0.5) + 1
    patch = np.ones((2 * reach + 1, 2 * reach + 1), dtype=np.float32)
    if not np.all(blur_of(patch) == 1.0):
        return blur_of(gray)
    box = ink_box(gray != 1.0, reach)
    out = np.ones_like(gray)
    part = gray[box]
    half = len(part) // 2
    if (idle_cores() if threads is None else threads) > 1 and half > 4 * reach:
        with ThreadPoolExecutor(max_workers=1) as pool:
            top = pool.submit(blur_of, part[:half + reach])
            inside = out[box]
            inside[half:] = blur_of(part[half - reach:])[reach:]
            inside[:half] = top.result()[:half]
    else:
        out[box] = blur_of(part)
    return out


def flatten_paper(gray: np.ndarray) -> np.ndarray:
    """`gray` (H, W) divided by its local paper level, so that paper is ~1 everywhere:
    (H, W) float32 in [0, 1].

    Scans and photos of drawings are lit unevenly; one global threshold then cuts through
    the paper's gradient instead of between paper and ink. The paper level is a grey
    closing (lines darker than the paper vanish) over a window an eighth of the image's
    longest side, box-smoothed. On evenly lit paper this changes nothing; ink blobs wider
    than the window would be taken for paper, and no line drawing has those.
    """
    size = max(31, int(round(max(gray.shape) / 8)))
    top = gray.max()
    if in_every_window(gray == top, size):
        # Paper at one level (a clean drawing): the closing is that level everywhere, and so
        # is its smoothing, which the filter computes alike for any constant image.
        paper = ndimage.uniform_filter(np.full((1, 1), top, dtype=np.float64), size=size, mode="nearest")
        if paper[0, 0] == 1.0:  # white paper: the division changes nothing
            return np.clip(gray, 0.0, 1.0).astype(np.float32, copy=False)
    else:
        paper = ndimage.grey_closing(gray, size=(size, size), mode="nearest").astype(np.float64)
        paper = ndimage.uniform_filter(paper, size=size, mode="nearest")
    return np.clip(gray / np.maximum(paper, MIN_PAPER), 0.0, 1.0).astype(np.float32)


def in_every_window(mask: np.ndarray, size: int) -> bool:
    """Whether every `size` x `size` window (centred on a pixel, cut at the image edge) of
    `mask` (H, W) bool holds a True pixel: then a maximum filter of that size over an image
    whose maximum is where `mask` is True is that maximum everywhere.

    Tiles of (size + 1) // 2 px a side suffice to decide it: every window, cut at the edge
    or not, contains a whole tile (the last tile of a row or column may be shorter)."""
    step = (size + 1) // 2
    rows = np.logical_or.reduceat(mask, np.arange(0, mask.shape[0], step), axis=0)
    tiles = np.logical_or.reduceat(rows, np.arange(0, mask.shape[1], step), axis=1)
    return bool(tiles.all())


def paper_noise_floor(gray: np.ndarray) -> float | None:
    """The gray level below which paper grain almost never reaches: median - 4.5 sigma of
    the paper, with sigma from the lower quartile (a line drawing is mostly paper; the
    upper half may be clipped at white). None when the lower quartile is not paper grain
    (more than a quarter of the image is dark: a frame, a heavy drawing)."""
    top, count = gray.max(), gray.size
    if np.count_nonzero(gray == top) >= count - int(0.25 * (count - 1)):
        # Three quarters of the image at its brightest level (clean paper): both quantiles
        # are that level, sigma is 0, as np.percentile would find after sorting.
        return float(top)
    q25, median = np.percentile(gray, [25, 50])
    sigma = (median - q25) / 0.6745
    if sigma > MAX_PAPER_SIGMA:
        return None
    return float(median - PAPER_SIGMAS * sigma)


def ink_threshold(gray: np.ndarray, threshold: float | None) -> float:
    """The ink/paper gray level: the given one, or Li's minimum cross-entropy threshold,
    kept below the paper's grain (Li's criterion can settle inside the grain of a noisy
    scan when the ink is under 1 % of the page)."""
    lo, hi = float(gray.min()), float(gray.max())
    if hi - lo < 0.08:
        if hi < 0.5:
            raise InputError("the image is all ink: nothing but dark pixels (is it inverted?)")
        raise InputError("no ink found: the image is blank")
    if threshold is not None:
        return float(threshold)
    from skimage.filters import threshold_li

    level = float(threshold_li(gray, tolerance=1e-4))
    floor = paper_noise_floor(gray)
    if floor is None:
        return level
    return min(level, max(floor, lo + 0.5 * (level - lo)))


def estimate_stroke_width(ink: np.ndarray) -> float:
    """Typical ink width in px: twice the median distance-to-paper on the ink's ridge."""
    # Only the ink's bounding box (and one row or column of paper around it, where the
    # image has one) matters: every paper pixel beyond it is farther from the ink than the
    # paper row between them. The transform over the whole page costs 2-3 times more.
    ink = ink[ink_box(ink, 1)]
    rows, cols = _pixels(ink)
    distance = ink_depth(ink, rows, cols)
    # Ridge pixels: local maxima of the distance across the stroke (a 3 x 3 maximum filter,
    # its edges reflected as `ndimage.maximum_filter` does, read at the ink pixels only).
    h, w = ink.shape
    depth = distance[rows, cols]
    around = depth.copy()
    for dr in (-1, 0, 1):
        r = np.clip(rows + dr, 0, h - 1)
        for dc in (-1, 0, 1):
            if dr or dc:
                np.maximum(around, distance[r, np.clip(cols + dc, 0, w - 1)], out=around)
    values = depth[depth >= around - 1e-6]
    if values.size == 0:
        return 1.0
    return float(max(1.0, 2.0 * np.median(values) - 0.5))


def ink_depth(ink: np.ndarray, rows: np.ndarray | None = None, cols: np.ndarray | None = None) -> np.ndarray:
    """Distance from each ink pixel of `ink` (H, W) bool to the nearest paper pixel, 0 on
    paper: (H, W) float64, equal to `ndimage.distance_transform_edt(ink)`; rows, cols: the
    ink pixels (as `np.nonzero(ink)` gives them), when the caller has them.

    An ink pixel with paper beside it is 1 px from the paper, one with paper only on a
    diagonal sqrt(2) px (nothing is nearer than a neighbour). For the others, the nearest
    paper pixel has an ink pixel beside it (a paper pixel with paper on all four sides has a
    neighbour nearer that ink pixel), so a k-d tree of those edge pixels, asked only at the
    deeper ink, gives the transform; a line drawing's box is mostly paper, which the
    transform's full pass over the box spends most of its time on, and a thin line's ink is
    mostly within a diagonal of the paper.
    """
    if rows is None or cols is None:
        rows, cols = _pixels(ink)
    paper = ~ink
    edge = grow(ink, 1) & paper
    if not len(rows) or not edge.any():
        return ndimage.distance_transform_edt(ink)
    distance = np.zeros(ink.shape)
    # The same arithmetic as the transform: squared offsets (whole numbers) summed, rooted.
    beside = grow(paper, 1)[rows, cols]
    diagonal = grow(paper, 1, square=True)[rows, cols] & ~beside
    distance[rows[beside], cols[beside]] = np.sqrt(1.0)
    distance[rows[diagonal], cols[diagonal]] = np.sqrt(2.0)
    deep = ~(beside | diagonal)
    inside = _nearest_paper_near(paper, np.column_stack([rows[deep], cols[deep]]), distance)
    if len(inside):
        edges = np.column_stack(_pixels(edge))
        _, nearest = cKDTree(edges).query(inside)
        offset = (edges[nearest] - inside).astype(np.float64)
        np.multiply(offset, offset, offset)
        distance[inside[:, 0], inside[:, 1]] = np.sqrt(offset[:, 0] + offset[:, 1])
    return distance


# Offsets (dy, dx) a deep ink pixel's nearest paper is looked for at directly, nearest first
# (whole-number squared distances from 4, the nearest a pixel with no paper beside it or on a
# diagonal can have, to DIRECT_REACH squared); deeper ones go to the k-d tree.
DIRECT_REACH = 4
_dy, _dx = np.mgrid[-DIRECT_REACH:DIRECT_REACH + 1, -DIRECT_REACH:DIRECT_REACH + 1]
_d2 = (_dy * _dy + _dx * _dx).ravel()
_near = (_d2 >= 4) & (_d2 <= DIRECT_REACH * DIRECT_REACH)
_order = np.argsort(_d2[_near], kind="stable")
RING_OFFSETS = np.column_stack([_dy.ravel()[_near], _dx.ravel()[_near]])[_order]
RING_SQUARES = _d2[_near][_order]
del _dy, _dx, _d2, _near, _order


def _nearest_paper_near(paper: np.ndarray, inside: np.ndarray, distance: np.ndarray) -> np.ndarray:
    """Write into `distance` the distance of each ink pixel `inside` (K, 2) rows, cols whose
    nearest `paper` pixel (H, W) is within DIRECT_REACH px, found by looking at the offsets
    in order of distance (a pen line's ink is a few px deep: cheaper than the k-d tree, and
    the same numbers, the square root of the same whole number); returns the pixels left."""
    h, w = paper.shape
    reach = DIRECT_REACH
    padded = np.zeros((h + 2 * reach, w + 2 * reach), dtype=bool)  # beyond the edge: no paper
    padded[reach:h + reach, reach:w + reach] = paper
    width = w + 2 * reach
    flat = padded.ravel()
    at = (inside[:, 0] + reach) * width + inside[:, 1] + reach
    steps = RING_OFFSETS[:, 0] * width + RING_OFFSETS[:, 1]
    first = 0
    while first < len(steps) and len(at):
        last = first
        while last < len(steps) and RING_SQUARES[last] == RING_SQUARES[first]:
            last += 1
        hit = flat[at[:, None] + steps[None, first:last]].any(axis=1)
        found = inside[hit]
        distance[found[:, 0], found[:, 1]] = np.sqrt(float(RING_SQUARES[first]))
        inside, at = inside[~hit], at[~hit]
        first = last
    return inside


def grow(mask: np.ndarray, steps: int, *, square: bool = False) -> np.ndarray:
    """`mask` (H, W) bool dilated `steps` times by its 4 neighbours (square: its 8
    neighbours), nothing beyond the edges: equal to `ndimage.binary_dilation(mask,
    iterations=steps)` (with `structure=np.ones((3, 3))` when square), at a tenth of its
    cost on a line drawing's box (shifted ORs of whole rows instead of a pass per pixel)."""
    for _ in range(steps):
        out = mask.copy()
        out[1:] |= mask[:-1]
        out[:-1] |= mask[1:]
        if square:
            mask = out
            out = mask.copy()
        out[:, 1:] |= mask[:, :-1]
        out[:, :-1] |= mask[:, 1:]
        mask = out
    return mask


def _pixels(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rows and columns of the True pixels of `mask` (H, W), in raster order: `np.nonzero`,
    at a third of its cost on a mostly empty box."""
    return np.divmod(np.flatnonzero(mask), max(mask.shape[1], 1))


def ink_box(ink: np.ndarray, margin: int) -> tuple[slice, slice]:
    """The bounding box of the True pixels of `ink`, grown by `margin` px within the image."""
    rows = np.flatnonzero(ink.any(axis=1))
    cols = np.flatnonzero(ink.any(axis=0))
    if rows.size == 0:
        return slice(0, 0), slice(0, 0)
    return (slice(max(int(rows[0]) - margin, 0), int(rows[-1]) + margin + 1),
            slice(max(int(cols[0]) - margin, 0), int(cols[-1]) + margin + 1))


def frame_labels(labels: np.ndarray, count: int, longest: int | None = None) -> np.ndarray:
    """Labels of dark frame pieces: ink that touches the image edge and is thicker than any
    line (inscribed radius over `FRAME_RADIUS` of the longest side), such as the table
    around a photographed sheet or a scanner lid's shadow. (n,) int.

    `labels` may be a crop of the image's labels grown by one row or column of paper on each
    side that is not the image's edge (the paper rows then carry no label); `longest` is the
    image's longest side (default: the longest side of `labels`)."""
    edge = np.unique(np.concatenate([labels[0], labels[-1], labels[:, 0], labels[:, -1]]))
    edge = edge[edge > 0]
    if edge.size == 0:
        return edge
    depth = ndimage.distance_transform_edt(np.isin(labels, edge))
    radii = ndimage.maximum(depth, labels, edge)
    return edge[np.asarray(radii) > FRAME_RADIUS * (longest or max(labels.shape))]


def extract_ink(gray: np.ndarray, *, threshold: float | None,
                threads: int | None = None) -> tuple[np.ndarray, float, float, bool]:
    """The ink mask to vectorize, its threshold, the stroke width and whether a frame was
    ignored.

    Specks (pieces smaller than a stroke-width square) are noise and vanish silently; every
    other piece is kept (single-line mode bridges and selects pieces later, on the medial
    axis: `gaps.py`). Small holes (pores inside ink blobs, pinholes where strokes nearly
    touch) are filled. threads: 2 or more measures the width beside the labelling (None:
    while the machine has a core to spare, `onestroke.cores.idle_cores`); the same result.
    """
    level = ink_threshold(gray, threshold)
    ink = gray < level
    dark = np.count_nonzero(ink)
    if not dark:
        raise InputError("no ink found: no pixel is darker than the threshold")
    if dark / ink.size > 0.6:
        raise InputError(f"the image is {dark / ink.size:.0%} ink: it looks inverted or is not a line drawing")
    # Everything below works on the ink's bounding box grown by one row or column of paper
    # (where the image has one): beyond it there is only paper, connected to the image's
    # edge around the box, so the pieces, the frame, the holes and the width are the same as
    # over the whole image (see each step), at a fraction of the pixels.
    box = ink_box(ink, 1)
    kept, width, framed = _kept_ink(ink[box], max(ink.shape), threads=idle_cores() if threads is None else threads)
    ink = np.zeros_like(ink)
    ink[box] = kept
    return ink, level, width, framed


def _kept_ink(ink: np.ndarray, longest: int, *, threads: int = 1) -> tuple[np.ndarray, float, bool]:
    """`extract_ink` on the crop `ink` (H, W) bool of the dark pixels around the ink (paper
    or the image's edge on every side); longest: the image's longest side. Returns the kept
    ink of the crop, the stroke width and whether a frame was ignored. threads: 2 or more
    measures the width in a second thread while this one labels the pieces and, ahead of
    knowing it is needed, the paper (both stages let go of the GIL)."""
    with ThreadPoolExecutor(max_workers=1) if threads > 1 else nullcontext() as pool:
        # The width of all the dark pixels: the width wanted unless a frame is dropped.
        measured = pool.submit(estimate_stroke_width, ink) if pool is not None else None
        # Label numbers follow the raster order of each piece's first pixel, the same in a crop.
        labels, count = ndimage.label(ink, structure=np.ones((3, 3)))
        # The crop's outer rows and columns are the image's edge or paper (no label).
        frame = frame_labels(labels, count, longest)
        framed = 0 < frame.size < count  # a frame with nothing inside it stays: it is all there is
        if framed:
            ink = ink & ~np.isin(labels, frame)  # (a new mask: the other thread reads the old one)
            labels[~ink] = 0
        # The paper's pieces of this ink: those of the kept ink when no speck is dropped.
        ahead = ndimage.label(~ink) if measured is not None and not framed else None
        width = measured.result() if measured is not None and not framed else estimate_stroke_width(ink)
    # Areas counted over the ink pixels only (paper is label 0, which is not a piece).
    areas = np.bincount(labels[ink], minlength=count + 1)[1:]
    speck = max(4.0, width * width)
    keep = areas >= speck
    if not keep.any():
        raise InputError("no ink found: only specks smaller than a stroke")
    # A lookup by label (0: paper) is the same as np.isin and needs no sorting; with every
    # piece kept it is the ink itself.
    ink = ink.copy() if keep.all() else np.concatenate([[False], keep])[labels]
    # Holes are the 4-connected pieces of paper that do not reach the image edge (what
    # `binary_fill_holes` fills), found with one labelling instead of its dilation loop. A
    # piece reaching the crop's edge reaches the paper around the crop, and so the image's.
    paper, count = ahead if ahead is not None and keep.all() else ndimage.label(~ink)
    hole = np.ones(count + 1, dtype=bool)
    hole[0] = False  # ink
    hole[np.concatenate([paper[0], paper[-1], paper[:, 0], paper[:, -1]])] = False
    if not hole.any():
        return ink, width, framed  # all paper reaches the edge: nothing to fill
    if not hole[1] and hole[2:].all():
        # Only the first piece reaches the edge (the paper around the ink): every pixel of
        # a higher label is in a hole, and only those need counting and filling.
        inner = paper > 1
        labels = paper[inner]
        small = np.bincount(labels, minlength=count + 1) < max(2.0, 0.5 * width * width)
        small &= hole
        if small.any():
            ink[inner] |= small[labels]
        return ink, width, framed
    small = np.bincount(paper.ravel()) < max(2.0, 0.5 * width * width)
    small &= hole
    if small.any():
        ink |= small[paper]
    return ink, width, framed


def paper_gray(image: np.ndarray, *, max_size: int, blur: float,
               downscaled: tuple[np.ndarray, float] | None = None,
               threads: int | None = None) -> tuple[np.ndarray, float]:
    """The working gray image with the paper's shading divided out (H, W) float32, and the
    scale: what the threshold does not change (`binarize` without the ink). downscaled:
    `downscaled_gray` of this image and max_size, when the caller has it (a blur does not
    change it); threads: as `blurred`'s."""
    gray, scale = downscaled if downscaled is not None else downscaled_gray(image, max_size=max_size)
    return flatten_paper(blurred(gray, blur, threads=threads)), scale


def import_used_for(shape: tuple[int, ...], *, max_size: int, blur: float, li_threshold: bool) -> None:
    """Import what `paper_gray` and `ink_image` import where used (scikit-image's rescale,
    gaussian and Li's threshold, each only where needed: a command pays for every import)
    for an image of this shape at these settings, so that a thread running them afterwards
    imports nothing."""
    if max(shape[:2]) > max_size:
        from skimage.transform import rescale  # noqa: F401
    if blur > 0:
        from skimage.filters import gaussian  # noqa: F401
    if li_threshold:
        from skimage.filters import threshold_li  # noqa: F401


def ink_image(gray: np.ndarray, scale: float, *, threshold: float | None, threads: int | None = None) -> InkImage:
    """The ink of a `paper_gray` image at this threshold (None: Li's); threads: as
    `extract_ink`'s."""
    ink, level, width, framed = extract_ink(gray, threshold=threshold, threads=threads)
    # Whiten everything that is not kept ink (specks, a frame) and blacken filled holes, so
    # that the sub-pixel outline of the gray image matches the kept ink exactly.
    # Only the box around the ink changes: the dilation cannot reach beyond 2 px of the ink.
    box = ink_box(ink, 2)
    kept = ink[box]
    near = grow(kept, 2)
    part = np.where(near, gray[box], np.float32(1.0)).astype(np.float32, copy=False)
    part[(part < level) & ~kept] = 1.0
    part[kept & (part >= level)] = 0.0
    work = np.ones(gray.shape, dtype=np.float32)
    work[box] = part
    return InkImage(gray=work, ink=ink, threshold=level, scale=scale, stroke_width=width, frame=framed)


def binarize(image: np.ndarray, *, max_size: int, blur: float, threshold: float | None) -> InkImage:
    """Run the whole preprocessing stage."""
    gray, scale = paper_gray(image, max_size=max_size, blur=blur)
    return ink_image(gray, scale, threshold=threshold)

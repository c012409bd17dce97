"""The vectorizer: a raster (or SVG) line drawing in, ordered cubic Bézier strokes out.

Stages (paper, Sections 3.1-3.4, and 4.5 for `multi`): load and binarize -> outline ->
Voronoi medial axis with radii -> pruning -> simplification (degree-3 merging, Y-junctions)
-> intersection classification -> traversal with flip-and-retry -> filtering and spline
fitting. Each stage is a function in its own module; this one wires them together.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass, field

import numpy as np

from onestroke.errors import InputError
from vectorize.drawing import Drawing


@dataclass(frozen=True, kw_only=True)
class VectorizeOptions:
    """Options of the vectorizer.

    multi: multi-stroke mode (paper 4.5) instead of one single line.
    threshold: gray level in [0, 1] below which a pixel is ink (None: Li's method).
    blur: Gaussian sigma in px applied before thresholding (0: none).
    classifier: "cnn" (shipped model) or "geometric" (tangent continuity).
    max_size: longest side of the working image in px; larger inputs are downscaled.
    seed: seed of every random choice (retry search ties), for reproducible output.
    """

    multi: bool = False
    threshold: float | None = None
    blur: float = 0.0
    classifier: str = "cnn"
    max_size: int = 1000
    seed: int = 0
    keep_stages: bool = False

    def __post_init__(self) -> None:
        if self.threshold is not None and not 0.0 < self.threshold < 1.0:
            raise InputError(f"threshold {self.threshold!r} must lie strictly between 0 and 1")
        if self.blur < 0:
            raise InputError(f"blur sigma {self.blur!r} must be >= 0")
        if self.classifier not in ("cnn", "geometric"):
            raise InputError(f"unknown classifier {self.classifier!r}; use 'cnn' or 'geometric'")
        if self.max_size < 64:
            raise InputError(f"max_size {self.max_size!r} must be at least 64 px")


@dataclass(frozen=True)
class VectorizeReport:
    """What happened: counts, warnings and time, for the CLI and the benchmark.

    strokes: strokes produced; intersections: degree-4 nodes classified; y_junctions: sharp
    out-and-back features kept; dropped_components: ink pieces left out (single-line mode);
    gaps_bridged: pen gaps joined across (single-line mode, `gaps.py`);
    high_degree_junctions: nodes where three or more strokes meet (not resolved);
    scale: working px per input px (< 1 when downscaled); seconds: wall time per stage.
    """

    strokes: int = 0
    intersections: int = 0
    y_junctions: int = 0
    dropped_components: int = 0
    gaps_bridged: int = 0
    high_degree_junctions: int = 0
    retries: int = 0
    scale: float = 1.0
    stroke_width: float = 0.0
    warnings: tuple[str, ...] = ()
    seconds: dict = field(default_factory=dict)

    @property
    def total_seconds(self) -> float:
        return float(sum(self.seconds.values()))


@dataclass(frozen=True)
class VectorizeResult:
    """The drawing (px, in the input image's frame) and the report; `stages` for --debug;
    `graph`: the junctions and branches the edits act on (`vectorize.refine.GraphView`),
    when the run was given edits or a stage cache."""

    drawing: Drawing
    report: VectorizeReport
    stages: dict | None = None
    graph: object | None = None


@dataclass(frozen=True)
class InputFrame:
    """How the pipeline's input image sits in the frame the output is written in.

    scale: image px per output unit; offset: (2,) output position of the image's corner;
    width/height: the output canvas; reduced_from: (W, H) of an original image that was
    shrunk before the pipeline saw it (for the "downscaled" message), else None.
    """

    scale: float
    offset: tuple[float, float]
    width: float
    height: float
    reduced_from: tuple[int, int] | None = None


def vectorize_file(path: str | os.PathLike, options: VectorizeOptions = VectorizeOptions(), *,
                   edits=None, cache=None) -> VectorizeResult:
    """Vectorize a raster image or read an SVG (strokes as they are; outlines to centre lines).

    edits: a `vectorize.edits.Edits` to apply; cache: a `vectorize.refine.StageCache`
    reused between calls on the same file (each edit then re-runs only later stages).
    """
    path = str(path)
    if not os.path.exists(path):
        raise InputError(f"input file {path!r} does not exist")
    if os.path.isdir(path):
        raise InputError(f"input {path!r} is a directory, not an image")
    suffix = os.path.splitext(path)[1].lower()
    if suffix in (".svg", ".svgz"):
        return _vectorize_svg(path, options, edits, cache)
    if cache is not None and cache.loaded is not None and cache.loaded[0] == (path, options.max_size):
        image, frame = cache.loaded[1]
    else:
        from vectorize.image_io import load_image

        image, frame = load_image(path, max_size=options.max_size)
        if cache is not None:
            cache.loaded = ((path, options.max_size), (image, frame))
    return vectorize_image(image, options, frame=frame, edits=edits, cache=cache)


def _vectorize_svg(path: str, options: VectorizeOptions, edits=None, cache=None) -> VectorizeResult:
    from vectorize.svg_read import read_svg

    start = time.perf_counter()
    content = read_svg(path)
    if content.is_outline:
        from vectorize.outline_svg import rasterize_rings

        gray, scale, offset = rasterize_rings(content.outline_rings, size=options.max_size)
        frame = InputFrame(scale, (float(offset[0]), float(offset[1])), content.width, content.height)
        return vectorize_image(gray, options, frame=frame, edits=edits, cache=cache)
    drawing = content.as_drawing()
    ignored = ("edits apply to raster drawings only: the SVG's strokes were kept as they are",) \
        if edits is not None and edits.items else ()
    report = VectorizeReport(strokes=len(drawing.strokes), stroke_width=drawing.stroke_width,
                             warnings=ignored, seconds={"read svg": time.perf_counter() - start})
    return VectorizeResult(drawing, report)


def vectorize_image(image: np.ndarray, options: VectorizeOptions = VectorizeOptions(), *,
                    frame: InputFrame | None = None, edits=None, cache=None) -> VectorizeResult:
    """Vectorize a raster image: (H, W) gray or (H, W, 3|4) colour, uint8, uint16 or float in
    [0, 1] (1 = paper), or an (H, W) bool ink mask (True = ink; note that a PIL mode "1"
    image as an array is the opposite, True = white: convert it to "L" first).

    The drawing comes out in the image's pixels (pixel i covers [i, i + 1)), or in `frame`.
    """
    from vectorize.vectorizer import run_pipeline

    return run_pipeline(image, options, frame=frame, edits=edits, cache=cache)

"""The vectorizer: a raster (or SVG) line drawing in, ordered cubic Bézier strokes out.

Stages (paper, Sections 3.1-3.4, and 4.5 for `multi`): load and binarize -> outline ->
Voronoi medial axis with radii -> pruning -> simplification (degree-3 merging, Y-junctions)
-> intersection classification -> traversal with flip-and-retry -> filtering and spline
fitting. Each stage is a function in its own module; this one wires them together.
"""

from __future__ import annotations

import os
import time

import numpy as np

from onestroke.errors import InputError
from vectorize.options import InputFrame, VectorizeOptions, VectorizeReport, VectorizeResult

__all__ = ["InputFrame", "VectorizeOptions", "VectorizeReport", "VectorizeResult", "vectorize_file",
           "vectorize_image"]


def import_stages_for(path: str | os.PathLike, *, li_threshold: bool = False) -> None:
    """Import the modules that vectorizing the file `path` uses, which `vectorize_file`
    otherwise imports as it reaches them: a raster drawing's stages (reading an SVG of
    strokes needs none of scipy, so for an SVG nothing), and with `li_threshold` (a run that
    leaves the threshold to Li's method) scikit-image's filters. For a caller that wants them
    loaded before the work starts, such as a command that then leaves the loaded objects out
    of the garbage collector's passes (`fabrication.cli.heap`)."""
    if os.path.splitext(str(path))[1].lower() in (".svg", ".svgz"):
        return
    from vectorize.fit import fitting  # noqa: F401 - imported for its side effect
    from vectorize import vectorizer  # noqa: F401
    from vectorize.raster import image_io  # noqa: F401

    if li_threshold:
        from skimage.filters import threshold_li  # noqa: F401 - what `binarize.ink_threshold` imports


class Binarizing:
    """A raster file read, and its binarize stage (`binarize.paper_gray` and `ink_image` at
    some options) running in a second thread: `image`, `frame` as `load_image` gives them,
    `result()` the `InkImage` (waits for it; raises what the stage raised)."""

    def __init__(self, image: np.ndarray, frame: InputFrame, options: VectorizeOptions) -> None:
        from concurrent.futures import ThreadPoolExecutor

        from vectorize.raster.binarize import ink_image, paper_gray

        def binarized():
            gray, scale = paper_gray(image, max_size=options.max_size, blur=options.blur, threads=1)
            return ink_image(gray, scale, threshold=options.threshold, threads=1)

        self.image, self.frame, self.options = image, frame, options
        self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="binarize")
        self._future = self._pool.submit(binarized)
        self._pool.shutdown(wait=False)  # the thread ends with its one task

    def result(self):
        return self._future.result()


def binarize_beside(path: str | os.PathLike, options: VectorizeOptions) -> Binarizing | None:
    """Read the raster file `path` here and start its binarize stage in a second thread, for
    a caller with other work to do meanwhile (`onestroke vectorize` imports the later
    stages' libraries, which holds the GIL; the binarizing is mostly numpy and scipy.ndimage
    loops that let go of it), to pass to `vectorize_file(..., binarizing=...)`. The thread
    imports nothing (what the stage imports where used is imported here first), so it never
    waits on the caller's imports. None where it would gain nothing: an SVG, or a machine
    without a core to spare (`onestroke.cores.idle_cores`)."""
    from onestroke.cores import idle_cores
    from onestroke.paths import check_input_file

    path = check_input_file(path, expect="an image or an SVG")
    if os.path.splitext(path)[1].lower() in (".svg", ".svgz") or idle_cores() < 2:
        return None
    from vectorize.raster.binarize import import_used_for

    image, frame = _raster(path, options)
    import_used_for(np.asarray(image).shape, max_size=options.max_size, blur=options.blur,
                    li_threshold=options.threshold is None)
    return Binarizing(image, frame, options)


def start_vectorizing(path: str | os.PathLike, options: VectorizeOptions, *, edits: bool) -> Binarizing | None:
    """What a command does before `vectorize_file(path, options, binarizing=...)`: start the
    binarize stage on a spare core (`binarize_beside`; not with edits, which may change the
    threshold and blur), then import the later stages (`import_stages_for`; scikit-image's
    Li threshold where the run leaves the threshold to it) while it runs. Returns the
    `binarizing` to pass on, or None."""
    binarizing = None if edits else binarize_beside(path, options)
    import_stages_for(path, li_threshold=options.threshold is None and not edits)
    return binarizing


def vectorize_file(path: str | os.PathLike, options: VectorizeOptions = VectorizeOptions(), *,
                   edits=None, cache=None, progress=None, binarizing: Binarizing | None = None) -> VectorizeResult:
    """Vectorize a raster image or read an SVG (strokes as they are; outlines to centre lines).

    edits: a `vectorize.refine.edits.Edits` to apply; cache: a `vectorize.refine.refine.StageCache`
    reused between calls on the same file (each edit then re-runs only later stages).
    progress: an `onestroke.progress.ProgressCallback` for reading a large SVG. binarizing:
    `binarize_beside(path, options)`, the file read and being binarized (not with edits or a
    cache).
    """
    if binarizing is not None:
        if binarizing.options != options:
            raise ValueError("the file was binarized at other options")
        return vectorize_image(binarizing.image, options, frame=binarizing.frame, edits=edits, cache=cache,
                               binarized=binarizing.result)
    from onestroke.paths import check_input_file

    path = check_input_file(path, expect="an image or an SVG")
    suffix = os.path.splitext(path)[1].lower()
    if suffix in (".svg", ".svgz"):
        return _vectorize_svg(path, options, edits, cache, progress)
    image, frame = _raster(path, options, cache)
    return vectorize_image(image, options, frame=frame, edits=edits, cache=cache)


def _raster(path: str, options: VectorizeOptions, cache=None):
    """(image, frame) of a raster file, read once per cache."""
    if cache is not None and cache.loaded is not None and cache.loaded[0] == (path, options.max_size):
        return cache.loaded[1]
    from vectorize.raster.image_io import load_image

    image, frame = load_image(path, max_size=options.max_size)
    if cache is not None:
        cache.loaded = ((path, options.max_size), (image, frame))
    return image, frame


def threshold_mask_file(path: str | os.PathLike, options: VectorizeOptions = VectorizeOptions(), *,
                        cache=None) -> tuple[np.ndarray, float]:
    """`front_stages.threshold_mask` of a raster file: (H, W) bool working px (the whole
    image, downscaled to `options.max_size`) and the threshold level. An SVG has no
    threshold: `InputError`."""
    from vectorize.front_stages import threshold_mask

    path = str(path)
    if os.path.splitext(path)[1].lower() in (".svg", ".svgz"):
        raise InputError("an SVG drawing has no threshold: its strokes are read, not binarized")
    image, _ = _raster(path, options, cache)
    return threshold_mask(image, options, cache)


def _vectorize_svg(path: str, options: VectorizeOptions, edits=None, cache=None,
                   progress=None) -> VectorizeResult:
    from vectorize.svg.svg_read import read_svg

    start = time.perf_counter()
    content = read_svg(path, progress=progress)
    if content.is_outline:
        from vectorize.svg.outline_svg import rasterize_rings

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
                    frame: InputFrame | None = None, edits=None, cache=None, binarized=None) -> VectorizeResult:
    """Vectorize a raster image: (H, W) gray or (H, W, 3|4) colour, uint8, uint16 or float in
    [0, 1] (1 = paper), or an (H, W) bool ink mask (True = ink; note that a PIL mode "1"
    image as an array is the opposite, True = white: convert it to "L" first).

    The drawing comes out in the image's pixels (pixel i covers [i, i + 1)), or in `frame`.
    binarized: as `vectorizer.run_pipeline`'s.
    """
    from vectorize.vectorizer import run_pipeline

    return run_pipeline(image, options, frame=frame, edits=edits, cache=cache, binarized=binarized)

"""The pipeline's front (paper 3.1 and the start of 3.2): the raster image binarized, outlined,
its medial axis computed, pruned and (single-line) its pen gaps bridged; the stages that only
threshold, blur and mode change, which the studio's cache keeps between edits after them.
Positions are working px (the binarized image's pixel centres at integers, x right, y down)."""

from __future__ import annotations

import sys
from functools import partial
from importlib import import_module
from typing import TYPE_CHECKING

import numpy as np

from onestroke.cores import idle_cores
from onestroke.errors import InputError
from vectorize.axis.gaps import bridge_gaps, keep_largest_piece
from vectorize.axis.medial_axis import medial_axis
from vectorize.axis.pruning import prune, trim_free_ends
from vectorize.junctions.classifiers import make_classifier
from vectorize.options import InputFrame, VectorizeOptions
from vectorize.raster.binarize import InkImage, downscaled_gray, ink_image, ink_threshold, paper_gray
from vectorize.raster.outline import outline_rings
from vectorize.stage_clock import StageClock

if TYPE_CHECKING:  # the studio's refinement is imported where edits or a session ask for it
    from collections.abc import Callable

    from vectorize.refine.edits import Edits
    from vectorize.refine.refine import StageCache

# Vanishing-angle thresholds (notes: 0.95 single-line, 0.90 multi-line).
PRUNE_SINGLE, PRUNE_MULTI = 0.95, 0.90
# No line drawing in a working image of <= max_size px has this many closed outlines or
# medial-axis branch points (a dense 2000 px scribble: ~500 crossings); noise has tens of
# thousands, and simplifying those takes hours.
MAX_OUTLINES, MAX_BRANCH_POINTS = 5000, 4000
# Outline samples bound the Voronoi diagram's work: the example drawings have 4,500-18,000;
# a 400 px square of noise has 367,000 in 2,400 outlines, which qhull takes minutes over.
# One long line is not noise: TSP art (a closed line 40,000-50,000 px long, 2-3 px wide,
# outlined every 0.3 px) has 300,000 samples in a handful of outlines, and its medial axis
# takes about 4 s. So past MAX_OUTLINE_SAMPLES the ink is refused only when it is also
# broken into more than LONG_LINE_OUTLINES outlines, and always past MAX_LONG_LINE_SAMPLES.
MAX_OUTLINE_SAMPLES = 150_000
LONG_LINE_OUTLINES = 500
MAX_LONG_LINE_SAMPLES = 600_000
# Outline samples up to which the crossing CNN is started beside qhull (`_cnn_beside`): qhull
# takes ~2.5 us a sample, so up to ~50 ms in one thread against ~25-30 ms in two tiles, while
# onnxruntime's import and the session take ~30 ms of this thread.
CNN_BESIDE_SAMPLES = 20_000


def refuse_noise(count: int, what: str, limit: int, threshold: float, given: bool) -> None:
    """Raise `InputError` when the ink has more `what` than any line drawing has: the
    threshold cut through paper texture or noise (and the search would take hours).
    A threshold the user already chose is not suggested again (lowering it step by step
    rarely helps); blur is what removes grain."""
    if count > limit:
        hint = ("try --blur 2 (more for coarse grain) with that threshold, or clean the scan" if given
                else f"try --blur 2 (more for coarse grain), or a --threshold well below {threshold:.2f}")
        raise InputError(f"the ink has {count} {what}: that is paper texture or noise, not a line "
                         f"drawing; {hint}")


def refuse_ragged(count: int, what: str, options: VectorizeOptions, threshold: float) -> None:
    """Raise `InputError` when the graph has more odd-degree nodes (`what`: its loose ends, or
    its loose ends and forks once simplified) than `options.max_odd_nodes`. A single line
    pairs them by route inspection's matching (its work grows as their cube); in multi-stroke
    mode each pair is a stroke to classify, order and fit. A ragged or grainy edge gives
    hundreds of them (spurs), a line drawing tens."""
    if count > options.max_odd_nodes:
        hint = ("try another --threshold (or the automatic one) or --blur 1, or clean the scan"
                if options.threshold is not None else "try --blur 1, or clean the scan")
        work = "strokes to end there" if options.multi else "for the line to pair up"
        raise InputError(f"the ink has {count} {what} {work} at threshold {threshold:.2f}, more than the "
                         f"{options.max_odd_nodes} an interactive run takes: that is a ragged edge or noise, "
                         f"not a line drawing; {hint}")


def working_paper(image: np.ndarray, options: VectorizeOptions, cache: StageCache | None = None):
    """(gray, scale) of `binarize.paper_gray` at the options' blur and size: the working image
    the threshold cuts, from the cache when one is given (and stored there)."""
    def paper():
        if cache is None:
            return paper_gray(image, max_size=options.max_size, blur=options.blur)
        # The downscaled gray is the same at every blur: a blur change starts from it.
        scaled = cache.stage("gray", (options.max_size,), lambda: downscaled_gray(image, max_size=options.max_size))
        return paper_gray(image, max_size=options.max_size, blur=options.blur, downscaled=scaled)

    return paper() if cache is None else cache.stage("paper", (options.blur, options.max_size), paper)


def threshold_mask(image: np.ndarray, options: VectorizeOptions, cache: StageCache | None = None):
    """(mask, level): (H, W) bool of the working pixels darker than the threshold (the options'
    or Li's level), what the threshold catches before specks, a frame and pinholes are
    cleaned; the studio shows it while a threshold or blur slider moves."""
    gray, _ = working_paper(image, options, cache)
    level = ink_threshold(gray, options.threshold)
    return gray < level, level


def axis_stages(image: np.ndarray, options: VectorizeOptions, clock: StageClock, cache: StageCache | None = None,
                binarized: Callable[[], InkImage] | None = None):
    """Binarize, outline and medial axis: the stages that threshold and blur change, and the
    mode does not. Returns (ink, rings, graph before pruning): the `InkImage`, the outline
    rings ((M, 2) working px each) and the `MedialGraph` (working px). binarized: gives the
    binarize stage's result for this image and options, computed elsewhere
    (`pipeline.binarize_beside`)."""
    # Every piece of ink is kept here; in single-line mode the pieces of a line broken by
    # pen gaps are bridged later, and only then is the largest kept.
    if binarized is not None:
        ink = binarized()
    else:
        gray, scale = working_paper(image, options, cache)
        ink = ink_image(gray, scale, threshold=options.threshold)
    clock.lap("binarize")
    w = ink.stroke_width
    spacing = float(np.clip(w / 8.0, 0.3, 1.0))
    # Straight sides sampled every half width: the axis between them zigzags by <= w / 32.
    rings = outline_rings(ink.gray, ink.threshold, spacing, sparse=w / 2.0)
    clock.lap("outline")
    refuse_noise(len(rings), "outlines (pieces and holes)", MAX_OUTLINES, ink.threshold,
                 options.threshold is not None)
    samples = sum(len(ring) for ring in rings)
    refuse_noise(samples, "outline samples", MAX_OUTLINE_SAMPLES if len(rings) > LONG_LINE_OUTLINES
                 else MAX_LONG_LINE_SAMPLES, ink.threshold, options.threshold is not None)
    # A process's first call imports the fitting stage's libraries (scipy.interpolate and
    # scipy.optimize, ~0.1 s, holding the GIL) while qhull triangulates in another thread,
    # and starts the crossing CNN there where the line likely crosses itself.
    later = [] if "vectorize.fit.fitting" in sys.modules else [partial(import_module, "vectorize.fit.fitting")]
    if _cnn_beside(len(rings), samples, options.classifier, idle_cores()):
        later.append(_start_cnn)
    graph = medial_axis(rings, ink.gray, ink.threshold, beside=partial(_each, later) if later else None)
    clock.lap("medial axis")
    return ink, rings, graph


def _cnn_beside(rings: int, samples: int, classifier, cores: int) -> bool:
    """Whether to start the crossing CNN (onnxruntime's import and the model's session,
    ~30 ms of CPU holding the GIL, otherwise paid in the classification stage) in this
    thread while qhull triangulates in another: where a core is spare (`cores`), the
    `classifier` is the CNN and onnxruntime is not loaded yet, and the ink's outline of
    `samples` points has three `rings` or more. A line that closes two loops or more meets
    itself somewhere (the two loops' centre lines form a graph with a node of degree 3 or
    more), and those junctions are classified by the ONNX networks; one hole (an O) needs
    none. Up to `CNN_BESIDE_SAMPLES`: beyond that, qhull in two tiles saves more than the
    overlap (`medial_axis` makes one tile per spare core while this thread works).
    A guess of what the classification stage will ask for: the output is the same either way."""
    return (classifier == "cnn" and rings >= 3 and samples <= CNN_BESIDE_SAMPLES and cores > 1
            and "onnxruntime" not in sys.modules)


def _start_cnn() -> None:
    """Import onnxruntime and start the crossing CNN's session (`make_classifier`'s cached
    one). A failure (the model missing or damaged, onnxruntime not loading) is left to the
    classification stage, which meets it again only if the drawing needs the CNN."""
    try:
        make_classifier("cnn").session  # noqa: B018 - started for its side effect
    except Exception:  # noqa: BLE001 - a guess must not fail a drawing that needs no CNN
        pass


def _each(steps: list[Callable[[], object]]) -> None:
    """Run `steps` in order."""
    for step in steps:
        step()


def output_matrix(ink_scale: float, frame: InputFrame) -> np.ndarray:
    """2x3 working px -> output units, for the working image's `ink_scale` (working px per
    input px) and the input's `frame`."""
    scale = ink_scale * frame.scale  # working px per output unit
    # Working pixel centres sit at integers (scikit-image); in SVG and in the input's pixel
    # frame pixel i covers [i, i + 1), so its centre is at i + 0.5.
    return np.array([[1 / scale, 0, frame.offset[0] + 0.5 / scale],
                     [0, 1 / scale, frame.offset[1] + 0.5 / scale]])


def front_stages(image: np.ndarray, options: VectorizeOptions, clock: StageClock, cache: StageCache | None = None,
                 frame: InputFrame | None = None, edits: Edits | None = None,
                 binarized: Callable[[], InkImage] | None = None):
    """Binarize, outline, medial axis, pruning and (single-line) gap bridging: the stages
    that only threshold, blur and mode change (and the edits' "unbridge" positions, in
    `frame`). Returns (ink, rings, graph, bridges, dropped, unbridged), bridges: the pen
    gaps bridged, each as its two ends (working px); unbridged: the bridges the edits
    refused (`vectorize.refine.refine.Unbridging.refused`).

    With `cache`, the stages before pruning are shared between the modes (a copy of the
    cached graph is pruned) and the paper-flattened gray between thresholds."""
    if cache is None:
        ink, rings, graph = axis_stages(image, options, clock, binarized=binarized)
    else:
        key = (options.threshold, options.blur, options.max_size)
        ink, rings, graph = cache.stage("axis", key, lambda: axis_stages(image, options, clock, cache))
        graph = graph.copy()
    w = ink.stroke_width
    prune(graph, threshold=PRUNE_MULTI if options.multi else PRUNE_SINGLE, stroke_width=w)
    trim_free_ends(graph, stroke_width=w)
    clock.lap("pruning")
    branch_points = sum(1 for incident in graph.incident.values() if len(incident) >= 3)
    refuse_noise(branch_points, "branch points", MAX_BRANCH_POINTS, ink.threshold,
                 options.threshold is not None)
    bridges: list = []
    dropped = 0
    refuse = None
    if not options.multi:
        if edits is not None and edits.of("unbridge"):
            from vectorize.refine.refine import Unbridging

            refuse = Unbridging(edits, output_matrix(ink.scale, frame or pixel_frame(image)))
        bridge_gaps(graph, stroke_width=w, made=bridges, refuse=refuse)
        dropped = keep_largest_piece(graph)
    if options.max_odd_nodes is not None:
        # Simplification merges forks into crossings but keeps every loose end: a graph
        # with too many of them is refused before that work.
        ends = sum(1 for incident in graph.incident.values() if len(incident) == 1)
        refuse_ragged(ends, "loose ends", options, ink.threshold)
    return ink, rings, graph, tuple(bridges), dropped, tuple(refuse.refused) if refuse is not None else ()


def pixel_frame(image: np.ndarray) -> InputFrame:
    """The input's own pixels as the output frame."""
    shape = np.asarray(image).shape
    return InputFrame(1.0, (0.0, 0.0), float(shape[1]), float(shape[0]))

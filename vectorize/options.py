"""Options, report and result of the vectorizer, and how its input sits in the output frame.

Their own module so that the entry points (`pipeline`) and the stages (`vectorizer`) both
import them without importing each other.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from onestroke.errors import InputError
from onestroke.ranges import Range, check_ranges, ranged
from vectorize.drawing import Drawing

# Ranges of the options a user sets (edits files and the studio's sliders use them too).
# The gray level is a fraction of paper white (paper = 1 after shading correction).
THRESHOLD = Range(0.0, 1.0, name="--threshold", low_open=True, high_open=True)
# A Gaussian sigma on the working image (longest side about 1000-2000 px).
BLUR = Range(0.0, 25.0, unit="px", name="--blur")
MAX_SIZE = Range(64, None, unit="px", name="max_size", integer=True)
# A budget, not a range of sizes: route inspection's exact matching (networkx's blossom, pure
# Python) grows as the cube of the odd nodes it pairs, multi-stroke mode's strokes and
# crossings with them. The studio sets one
# (`fabrication.studio.budgets`); the CLI and batch leave it unset and take the time.
MAX_ODD_NODES = Range(2, None, name="max_odd_nodes", integer=True)


@dataclass(frozen=True, kw_only=True)
class VectorizeOptions:
    """Options of the vectorizer.

    multi: multi-stroke mode (paper 4.5) instead of one single line.
    threshold: gray level in (0, 1) below which a pixel is ink (None: Li's method).
    blur: Gaussian sigma in px applied before thresholding (0: none), 0-25 px.
    classifier: "cnn" (shipped model), "geometric" (tangent continuity), or any object with
        the `vectorize.junctions.intersections.IntersectionClassifier` method `classify`.
    max_size: longest side of the working image in px; larger inputs are downscaled.
    seed: seed of every random choice (retry search ties), for reproducible output.
    whole_image_confidence: the CNN also reads each crossing from the whole image, for the
        confidence the studio and the --debug overlay show (`JunctionVerdict.confidence`;
        `cnn_classifier.CnnClassifier.classify`); the verdicts, and so the drawing, are the
        same either way, and the classification's network work halves without it.
    max_odd_nodes: refuse (`InputError`, after simplification) a graph with more odd-degree
        nodes (loose ends and forks) than this (None: no limit): route inspection's matching
        grows as their cube, multi-stroke mode's strokes with them.
    """

    multi: bool = False
    threshold: float | None = ranged(None, THRESHOLD)
    blur: float = ranged(0.0, BLUR)
    classifier: object = "cnn"
    max_size: int = ranged(1000, MAX_SIZE)
    seed: int = 0
    keep_stages: bool = False
    whole_image_confidence: bool = False
    max_odd_nodes: int | None = ranged(None, MAX_ODD_NODES)

    def __post_init__(self) -> None:
        check_ranges(self)
        if isinstance(self.classifier, str) and self.classifier not in ("cnn", "geometric"):
            raise InputError(f"unknown classifier {self.classifier!r}; use 'cnn' or 'geometric'")
        if not isinstance(self.classifier, str) and not callable(getattr(self.classifier, "classify", None)):
            raise InputError(f"classifier {self.classifier!r} has no classify method")


@dataclass(frozen=True)
class VectorizeReport:
    """What happened: counts, warnings and time, for the CLI and the benchmark.

    strokes: strokes produced; intersections: degree-4 nodes classified; y_junctions: sharp
    out-and-back features kept; dropped_components: ink pieces left out (single-line mode);
    gaps_bridged: pen gaps joined across (single-line mode, `gaps.py`);
    high_degree_junctions: nodes where three or more strokes meet (not resolved);
    odd_nodes: odd-degree nodes of the branch graph that route inspection paired by retraced
    paths or left as the line's ends (single-line mode);
    scale: working px per input px (< 1 when downscaled); threshold: the ink/paper gray
    level used, in [0, 1] (Li's when none was given; None for an SVG of strokes); seconds:
    wall time per stage; cpu_seconds: CPU time of the process (all threads) per stage.
    """

    strokes: int = 0
    intersections: int = 0
    y_junctions: int = 0
    dropped_components: int = 0
    gaps_bridged: int = 0
    high_degree_junctions: int = 0
    retries: int = 0
    odd_nodes: int = 0
    scale: float = 1.0
    stroke_width: float = 0.0
    threshold: float | None = None
    warnings: tuple[str, ...] = ()
    seconds: dict = field(default_factory=dict)
    cpu_seconds: dict = field(default_factory=dict)

    @property
    def total_seconds(self) -> float:
        return float(sum(self.seconds.values()))


@dataclass(frozen=True)
class VectorizeResult:
    """The drawing (px, in the input image's frame) and the report; `stages` for --debug;
    `graph`: the junctions and branches the edits act on (`vectorize.refine.refine.GraphView`),
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

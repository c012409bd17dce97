"""The per-file function of a batch: one drawing in, the content of each output file out.

`process_file` calls the same library functions as `onestroke vectorize`, `embroider` and
`laser` (vectorize once, then each target), so a batch writes the same bytes as the single
commands. It writes nothing itself: outputs come back as bytes for the caller (the batch's
client process) to write, which is what lets it run unchanged on a Dask worker elsewhere.
"""

from __future__ import annotations

import dataclasses
import hashlib
import os
import signal
import tempfile
import time
from dataclasses import dataclass

from fabrication.batch.report import FileStats
from vectorize.pipeline import VectorizeOptions

# Raster and SVG drawings a batch picks up from folders (lower-case, without the dot).
INPUT_EXTENSIONS = ("png", "jpg", "jpeg", "bmp", "gif", "tif", "tiff", "webp", "svg", "svgz")
DRAWING_EXTENSIONS = ("svg", "json")
LASER_EXTENSIONS = ("gcode", "nc", "gc", "ngc")


@dataclass(frozen=True, kw_only=True)
class DrawingTarget:
    """The vectorized drawing as .svg or .json (what `onestroke vectorize` writes)."""

    extension: str


@dataclass(frozen=True, kw_only=True)
class EmbroideryTarget:
    """An embroidery file: `job` (fabrication.embroidery.pipeline.EmbroideryJob) written in the
    format of `extension` (pes, dst, jef, exp, vp3); pes_version: None for the default."""

    extension: str
    job: object
    pes_version: int | None = None


@dataclass(frozen=True, kw_only=True)
class LaserTarget:
    """A G-code program for `profile` (machines.laser_profile.LaserProfile) with the toolpath
    and G-code options (fabrication.laser ToolpathOptions, GcodeOptions)."""

    extension: str
    profile: object
    toolpath: object
    gcode: object


Target = DrawingTarget | EmbroideryTarget | LaserTarget


@dataclass(frozen=True, kw_only=True)
class BatchJob:
    """What to make of every drawing: vectorizer options and one target per output extension."""

    vectorize: VectorizeOptions
    targets: tuple[Target, ...]

    def target(self, extension: str) -> Target:
        return next(t for t in self.targets if t.extension == extension)

    def key(self, extension: str) -> str:
        """A digest of everything that decides the bytes of one output (options, version):
        the manifest's test of "made with the same options"."""
        from importlib.metadata import PackageNotFoundError, version

        try:
            release = version("onestroke")
        except PackageNotFoundError:  # running from a source tree
            release = "source"
        text = f"{release}|{self.vectorize!r}|{self.target(extension)!r}"
        return hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]


@dataclass(frozen=True, kw_only=True)
class FileResult:
    """What became of one input: name (its path relative to its folder, posix), outputs
    ((extension, file content) per target made), stats, error (one line; None if it worked);
    worker_lost: the error is the worker's death, not the input's (a rerun tries it again)."""

    name: str
    outputs: tuple[tuple[str, bytes], ...] = ()
    stats: FileStats = FileStats()
    error: str | None = None
    worker_lost: bool = False


def die_with_parent(parent: int) -> None:
    """Have the kernel kill this process when `parent` ends, however it ends (SIGKILL
    included): Linux's PR_SET_PDEATHSIG. Elsewhere nothing is set up."""
    import ctypes
    import ctypes.util
    import sys

    if not sys.platform.startswith("linux"):
        return
    libc = ctypes.CDLL(ctypes.util.find_library("c") or None, use_errno=True)
    PR_SET_PDEATHSIG = 1  # <linux/prctl.h>
    libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    if os.getppid() != parent:  # the parent ended before the line above: nobody to work for
        os._exit(1)


def warm_up(job: BatchJob, *, ignore_interrupt: bool = True, parent: int | None = None) -> None:
    """Load the imports and the classifier model once per worker process (an initializer).

    ignore_interrupt: leave Ctrl-C to the client, which stops handing out files; a worker
    interrupted halfway would only lose its file. parent: the batch's process id; the worker
    ends with it (`die_with_parent`), so a killed batch leaves no worker behind.
    """
    if parent is not None:
        die_with_parent(parent)
    if ignore_interrupt:
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        import fabrication.embroidery.export  # noqa: F401  (pyembroidery and the stitch planner)
        import fabrication.embroidery.pipeline  # noqa: F401
        import fabrication.laser.program  # noqa: F401
        import vectorize.vectorizer  # noqa: F401

        if job.vectorize.classifier == "cnn":
            from vectorize.junctions.cnn_classifier import CnnClassifier

            CnnClassifier().session  # noqa: B018  (creates the cached onnxruntime session)
    except Exception:  # noqa: BLE001 - only a head start: each drawing's own run reports the error
        pass


def process_file(name: str, job: BatchJob, *, path: str | None = None, data: bytes | None = None,
                 extensions: tuple[str, ...] | None = None) -> FileResult:
    """Make the outputs of one drawing; never raises for a bad file (the error is returned).

    name: the input's relative path (reported, and its base name goes into G-code headers);
    path: the file to read, or data: its bytes (from a client on another machine);
    extensions: the targets to make (default: all of `job`'s).
    """
    started = time.perf_counter()
    wanted = tuple(t.extension for t in job.targets) if extensions is None else extensions
    local = None
    try:
        if data is None:
            return _process(name, path, job, wanted, started)
        with tempfile.TemporaryDirectory(prefix="onestroke-batch-") as folder:
            local = os.path.join(folder, os.path.basename(name))
            with open(local, "wb") as handle:
                handle.write(data)
            return _process(name, local, job, wanted, started)
    except Exception as error:  # a bad file is reported, never stops the batch
        from onestroke.errors import OnestrokeError

        text = str(error) if isinstance(error, OnestrokeError) else f"{type(error).__name__}: {error}"
        if local is not None:  # name the user's file, not the worker's copy of it
            text = text.replace(local, name)
        return FileResult(name=name, stats=FileStats(seconds=time.perf_counter() - started),
                          error=" ".join(text.split()))


def _named(job, name: str):
    """The job with the design name `onestroke embroider` gives this input: its file stem."""
    return dataclasses.replace(job, name=os.path.splitext(os.path.basename(name))[0])


def _process(name: str, path: str, job: BatchJob, wanted: tuple[str, ...], started: float) -> FileResult:
    from vectorize.pipeline import vectorize_file

    result = vectorize_file(path, job.vectorize)
    drawing, report = result.drawing, result.report
    warnings = list(report.warnings)
    outputs: list[tuple[str, bytes]] = []
    stitches = sew_seconds = laser_seconds = None
    for extension in wanted:
        target = job.target(extension)
        if isinstance(target, DrawingTarget):
            from vectorize.svg_write import drawing_to_json, drawing_to_svg

            text = drawing_to_svg(drawing) if extension == "svg" else drawing_to_json(drawing)
            outputs.append((extension, text.encode("utf-8")))
        elif isinstance(target, EmbroideryTarget):
            from fabrication.embroidery.export import embroidery_bytes
            from fabrication.embroidery.pipeline import embroider
            from machines.hoops import format_for_path

            sewn = embroider(drawing, _named(target.job, name))
            fmt = format_for_path(f"x.{extension}")
            outputs.append((extension, embroidery_bytes(sewn.plan, fmt, pes_version=target.pes_version)))
            warnings += [w for w in sewn.warnings if w not in warnings]
            if stitches is None:
                stitches, sew_seconds = sewn.stats.stitches, float(sewn.stats.seconds)
        else:
            from fabrication.laser.program import laser_program

            program = laser_program(drawing, target.profile, target.toolpath, target.gcode,
                                    name=os.path.basename(name))
            outputs.append((extension, program.text.encode("utf-8")))
            if program.toolpath.dropped:
                warnings.append(f"{program.toolpath.dropped} stroke(s) of zero length left out")
            if laser_seconds is None:
                laser_seconds = float(program.time.total_seconds)
    stats = FileStats(strokes=report.strokes, intersections=report.intersections, warnings=tuple(warnings),
                      stitches=stitches, sew_seconds=sew_seconds, laser_seconds=laser_seconds,
                      seconds=time.perf_counter() - started)
    return FileResult(name=name, outputs=tuple(outputs), stats=stats)

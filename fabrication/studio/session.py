"""One studio session: a drawing, its edits file and the library calls the page makes.

Everything the page shows or downloads comes from the same library functions the CLI
commands call (`vectorize_file` with edits, `embroidery_settings` + `embroider` +
`embroidery_bytes`, `laser_settings` + `laser_program`, `drawing_to_svg`/`_json`), so a
download is the same bytes as `onestroke embroider|laser|vectorize DRAWING --edits FILE`
with the same options.
"""

from __future__ import annotations

import os
import threading
from dataclasses import replace
from pathlib import Path

import numpy as np

from fabrication.job_options import embroidery_settings, laser_settings
from fabrication.studio import budgets
from onestroke.atomic import atomic_write_text
from onestroke.errors import Cancelled, InputError, OnestrokeError
from vectorize import VectorizeOptions, vectorize_file
from vectorize.refine.edits import Edits, edits_from_dict, read_edits
from vectorize.refine.refine import StageCache

EMBROIDERY_FORMATS = ("pes", "dst", "jef", "exp", "vp3")
# Page fields -> embroidery_settings / laser_settings keywords (the CLI's option names).
EMBROIDERY_FIELDS = ("style", "size", "hoop", "fit", "stitch_length", "tolerance", "stitch_width", "spacing",
                     "pull_comp", "repeats", "arrow_size", "min_stitch", "max_stitch", "trim_distance",
                     "lock_form", "color", "pes_version", "spm", "rotate")
LASER_FIELDS = ("size", "rotate", "origin", "feed", "power", "passes", "tolerance", "arcs", "keep_order",
                "air_assist", "return_home", "profile")
# A profile loaded from the page: a real one is ~1.5 kB; at most this many kept per session.
MAX_PROFILE_BYTES = 64 * 1024
MAX_LOADED_PROFILES = 32
# Points per px of curve sent to the page: enough for a smooth line, few enough to be quick.
CURVE_SPACING = 2.0


def _clean(values: dict, allowed: tuple[str, ...]) -> dict:
    """The page's option values, empty ones dropped (the CLI's defaults then apply)."""
    if not isinstance(values, dict):
        raise InputError("options must be a JSON object")
    unknown = sorted(set(values) - set(allowed))
    if unknown:
        raise InputError(f"unknown option(s): {', '.join(unknown)}")
    return {k: v for k, v in values.items() if v is not None and v != ""}


class Superseded(Exception):
    """A page asked for a newer state while this request waited for or ran the vectorizer."""


# The page's slider steps (static/index.html): the values a user reaches next from a
# setting, which the session computes in the background while it is idle
# (`warm_neighbours`).
THRESHOLD_STEP, BLUR_STEP, MAX_BLUR = 0.01, 0.25, 4.0


class StudioSession:
    """drawing: the input file; edits_path: where the page saves its edits; profile: an
    optional laser profile TOML; classifier: the vectorizer's crossing classifier; precompute:
    after each state, compute the neighbouring threshold and blur slider values in the
    background while no request waits (see `warm_neighbours`)."""

    def __init__(self, drawing: str | os.PathLike, *, edits_path: str | os.PathLike | None = None,
                 profile: str | os.PathLike | None = None, classifier: str = "cnn",
                 precompute: bool = False) -> None:
        self.drawing_path = Path(drawing)
        if self.drawing_path.is_dir():
            raise InputError(f"input {str(drawing)!r} is a directory, not an image")
        if not self.drawing_path.is_file():
            raise InputError(f"input file {str(drawing)!r} does not exist")
        self.edits_path = Path(edits_path) if edits_path else self.drawing_path.with_suffix(".edits.json")
        # The laser panel's choices: id -> (label, profile path or loaded LaserProfile). The
        # built-in ones and the command line's are read from their path at each use (as the
        # CLI does); those loaded from the page are kept parsed, never as a path.
        self.profiles: dict[str, tuple[str, object]] = {}
        from machines.laser_profile import bundled_laser_profiles, load_laser_profile

        for path in bundled_laser_profiles():
            self.profiles[f"built-in:{path.stem}"] = (f"built-in: {load_laser_profile(path).name}", path)
        if profile:
            self.profiles["command-line"] = (f"command line: {Path(profile).name}", Path(profile))
        self.default_profile = "command-line" if profile else next(iter(self.profiles))
        self.options = VectorizeOptions(classifier=classifier, whole_image_confidence=True)
        self.cache = StageCache()
        self.lock = threading.Lock()  # one vectorization at a time: the cache is not shared-safe
        self.sender = None
        self._tickets: dict[str, int] = {}  # page id -> number of its latest state request
        self.precompute = precompute
        # Bumped by every request that needs the vectorizer: background work in progress
        # stops at its next stage boundary and leaves the vectorizer to the request.
        self._generation = 0
        self._wanted: Edits | None = None  # the edits of the latest request
        self._warmer: threading.Thread | None = None
        self._shown: Edits | None = None  # the edits of the last state answered

    # -- edits -----------------------------------------------------------------------
    def saved_edits(self) -> Edits:
        """The edits file if it exists, else no edits."""
        return read_edits(self.edits_path) if self.edits_path.is_file() else Edits()

    def save_edits(self, data: dict) -> Edits:
        edits = edits_from_dict(data)
        atomic_write_text(self.edits_path, edits.to_json())
        return edits

    # -- vectorization ---------------------------------------------------------------
    def vectorize(self, edits: Edits, *, superseded=None, generation: int | None = None):
        """The vectorization with these edits. superseded: a callable; when it says True
        before or during the run (checked between stages), `Superseded` is raised instead
        of the rest of the work. generation: background work (`warm_neighbours`) passes the
        generation it was started in and stops as soon as a request arrives; a request
        (None) stops background work first, unless that is computing these very edits."""
        if generation is None:
            self._wanted = edits
            self._generation += 1

        def stale() -> bool:
            if superseded is not None and superseded():
                return True
            # Background work goes on only while no request waits, or the one that waits
            # wants what it is computing.
            return generation is not None and generation != self._generation and self._wanted != edits

        with self.lock:
            if stale():
                raise Superseded
            self.cache.cancel = stale
            # A graph too ragged for the page's pace is refused before its junctions and route.
            budget = budgets.MULTI_ODD_NODES if edits.applied_to(self.options).multi else budgets.ODD_NODES
            try:
                return vectorize_file(self.drawing_path, replace(self.options, max_odd_nodes=budget),
                                      edits=edits, cache=self.cache)
            except Cancelled:
                raise Superseded from None
            finally:
                self.cache.cancel = None

    def neighbours(self, edits: Edits, previous: Edits | None = None,
                   automatic: float | None = None) -> list[Edits]:
        """The settings one slider step away from `edits` (blur within the slider's range),
        the direction of the last move first. automatic: the threshold the vectorizer chose
        when `edits` leave it automatic; the page puts the slider there (rounded to its
        step), so the first drag sends one step either side of it, and unticking
        "automatic" sends that position itself: those are warmed too."""
        found = []
        moved = {}
        if previous is not None:
            for name in ("threshold", "blur"):
                old, new = getattr(previous, name), getattr(edits, name)
                if old is not None and new is not None and new != old:
                    moved[name] = 1 if new > old else -1
        unticked = round(automatic, 2) if edits.threshold is None and automatic is not None else None
        position = edits.threshold if edits.threshold is not None else unticked
        if position is not None:
            for sign in (moved.get("threshold", 1), -moved.get("threshold", 1)):
                value = round(position + sign * THRESHOLD_STEP, 2)
                if 0.0 < value < 1.0:
                    found.append(replace(edits, threshold=value))
        blur = edits.blur if edits.blur is not None else self.options.blur
        for sign in (moved.get("blur", 1), -moved.get("blur", 1)):
            value = round(blur + sign * BLUR_STEP, 2)
            if 0.0 <= value <= MAX_BLUR:
                found.append(replace(edits, blur=value))
        if unticked is not None and 0.0 < unticked < 1.0:
            found.append(replace(edits, threshold=unticked))
        return found

    def warm_neighbours(self, edits: Edits, previous: Edits | None = None,
                        automatic: float | None = None) -> threading.Thread:
        """Compute the neighbouring slider values of `edits` in a background thread, so that
        the next step of a slider is answered from the cache. The answer is the same as
        without it (the cache holds what a fresh run computes); any request stops it."""
        generation = self._generation

        def work() -> None:
            for neighbour in self.neighbours(edits, previous, automatic):
                if generation != self._generation:
                    return
                try:
                    self.vectorize(neighbour, generation=generation)
                except (Superseded, OnestrokeError):
                    pass  # stopped by a request, or a setting that fails: asked for, it says why

        self._warmer = threading.Thread(target=work, name="studio-warm", daemon=True)
        self._warmer.start()
        return self._warmer

    def idle(self, timeout: float | None = None) -> bool:
        """Wait for background work to finish; True if there is none left."""
        warmer = self._warmer
        if warmer is not None:
            warmer.join(timeout)
        return warmer is None or not warmer.is_alive()

    def stop_background(self, timeout: float = 10.0) -> bool:
        """Stop background work (it ends at its next stage boundary) and wait for it: the
        process must not exit while a thread is inside the vectorizer's native code
        (onnxruntime, qhull), which aborts it ("terminate called without an active
        exception"). True if none is left."""
        self.precompute = False
        self._generation += 1
        return self.idle(timeout)

    def ticket(self, page: str):
        """A state request of page `page`: a callable saying whether the page has asked for
        another state since. A slider dragged over several values while a re-run takes a
        second queues a request per value; only the latest is worth the vectorizer's time.
        (Called on the server's event loop: one at a time.)"""
        number = self._tickets.get(page, 0) + 1
        self._tickets[page] = number
        return lambda: self._tickets.get(page) != number

    def state(self, edits: Edits, *, superseded=None) -> dict:
        """What the page draws: curve samples in drawing order, junctions, branches, report."""
        result = self.vectorize(edits, superseded=superseded)
        drawing, report = result.drawing, result.report
        strokes = []
        for stroke in drawing.strokes:
            count = max(2, int(np.ceil(stroke.length / CURVE_SPACING)) + 1)
            points = stroke.points_at_lengths(np.linspace(0.0, stroke.length, count))
            strokes.append({"points": np.round(points, 2).tolist(), "closed": bool(stroke.is_closed),
                            "length": round(float(stroke.length), 2)})
        settings = edits.applied_to(self.options)
        answer = {
            "name": self.drawing_path.name, "width": drawing.width, "height": drawing.height,
            "classifier": self.options.classifier if isinstance(self.options.classifier, str) else "custom",
            "stroke_width": round(float(drawing.stroke_width), 3), "strokes": strokes,
            "graph": result.graph.to_dict() if result.graph is not None else {"junctions": [], "branches": []},
            "report": {"strokes": report.strokes, "intersections": report.intersections,
                       "dropped": report.dropped_components, "warnings": list(report.warnings),
                       "threshold": None if report.threshold is None else round(float(report.threshold), 3),
                       "seconds": round(float(report.total_seconds), 3)},
            "settings": {"threshold": settings.threshold, "blur": settings.blur, "multi": settings.multi},
            "edits": edits.to_dict(),
        }
        if self.precompute:
            self.warm_neighbours(edits, self._shown, report.threshold)
        self._shown = edits
        return answer

    def mask(self, threshold: float | None, blur: float) -> bytes:
        """PNG (working px, the whole image) of the pixels darker than `threshold` (None:
        Li's) at `blur`, black on transparent: what the page lays under the curve while a
        threshold or blur slider moves. Values out of their declared ranges: `InputError`."""
        from io import BytesIO

        from PIL import Image

        from vectorize.pipeline import threshold_mask_file

        options = Edits(threshold=threshold, blur=blur).applied_to(self.options)
        if self.lock.acquire(blocking=False):  # with the stage cache: the next re-run starts from it
            try:
                mask, _ = threshold_mask_file(self.drawing_path, options, cache=self.cache)
            finally:
                self.lock.release()
        else:  # the vectorizer is busy with this drawing: without the cache it holds
            mask, _ = threshold_mask_file(self.drawing_path, options)
        alpha = mask.astype(np.uint8) * 255
        buffer = BytesIO()
        Image.fromarray(np.dstack([np.zeros_like(alpha), alpha]), mode="LA").save(buffer, format="PNG")
        return buffer.getvalue()

    # -- make it ---------------------------------------------------------------------
    PANEL_MODULES = ("fabrication.embroidery.pipeline", "fabrication.embroidery.export", "fabrication.player",
                     "fabrication.laser.program", "machines.hoops", "machines.job_time", "vectorize.svg_write")

    def warm(self) -> None:
        """Import what the make-it panels and downloads use (about 1 s of CPU), so that the
        first click on the Embroidery or Laser tab answers as fast as the next ones. The
        CLI runs it in the background once the page is served."""
        import importlib

        for name in self.PANEL_MODULES:
            importlib.import_module(name)

    def embroidery(self, edits: Edits, values: dict, extension: str = "pes"):
        """(settings, result) of `onestroke embroider` for these option values."""
        from fabrication.embroidery.pipeline import embroider

        if extension not in EMBROIDERY_FORMATS:
            raise InputError(f"unknown embroidery format {extension!r}; use one of {', '.join(EMBROIDERY_FORMATS)}")
        values = _clean(values, EMBROIDERY_FIELDS)
        if extension != "pes":
            values.pop("pes_version", None)
        # The input's stem names the design in the file, as `onestroke embroider` does.
        settings = embroidery_settings(output=f"design.{extension}", source=str(self.drawing_path), **values)
        drawing = self.vectorize(edits).drawing
        # Too many steps along the curve for the page's pace: refused before stitching.
        return settings, embroider(drawing, replace(settings.job, max_steps=budgets.STEPS))

    def embroidery_preview(self, edits: Edits, values: dict) -> dict:
        """The stitches for the player (`fabrication.player`), stats lines and warnings."""
        from fabrication.player import stitch_player_data

        settings, result = self.embroidery(edits, values)
        job, stats, hoop = settings.job, result.stats, result.hoop
        data = stitch_player_data(result.plan, title=self.drawing_path.stem, stats=stats,
                                  stitches_per_minute=job.stitches_per_minute, trim_seconds=job.trim_seconds,
                                  hoop=(-hoop.width / 2, -hoop.height / 2, hoop.width / 2, hoop.height / 2))
        return {"player": data.to_dict(), "stats": stats.lines(), "stitches": stats.stitches,
                "seconds": stats.seconds, "warnings": list(settings.warnings) + list(result.warnings)}

    # -- laser profiles --------------------------------------------------------------
    def profile_list(self) -> dict:
        """The laser panel's profile choices and the default one."""
        return {"profiles": [{"id": key, "label": label} for key, (label, _) in self.profiles.items()],
                "default": self.default_profile}

    def add_profile(self, file_name: str, text: str) -> dict:
        """Parse and check a profile TOML the page read from a file the user picked; offer it.
        The file name only labels it: nothing is read from a path the page names."""
        import hashlib

        from machines.laser_profile import laser_profile_from_text

        if not isinstance(text, str) or not isinstance(file_name, str):
            raise InputError("a profile upload needs the file's name and text")
        data = text.encode("utf-8", "replace")
        size = len(data)
        if size > MAX_PROFILE_BYTES:
            raise InputError(f"profile file of {size} bytes is too large (at most {MAX_PROFILE_BYTES // 1024} kB)")
        name = " ".join(Path(file_name.replace("\\", "/")).name.split())[:80] or "profile.toml"
        try:
            profile = laser_profile_from_text(text, source=f"laser profile {name!r}")
        except InputError as error:
            raise InputError(" ".join(str(error).split())) from None  # one line for the panel
        key = "loaded:" + hashlib.sha256(data).hexdigest()[:12]
        if key not in self.profiles and sum(k.startswith("loaded:") for k in self.profiles) >= MAX_LOADED_PROFILES:
            raise InputError(f"at most {MAX_LOADED_PROFILES} profiles can be loaded in one session")
        self.profiles[key] = (f"{name}: {profile.name}", profile)
        return dict(self.profile_list(), id=key, name=profile.name)

    def laser(self, edits: Edits, values: dict):
        """(settings, program) of `onestroke laser` for these option values; `profile`: the
        id of one of `profiles` (default: as `onestroke studio` was started)."""
        from fabrication.laser.program import laser_program

        values = _clean(values, LASER_FIELDS)
        key = str(values.pop("profile", self.default_profile))
        if key not in self.profiles:
            raise InputError(f"--profile {key!r} is not one of this studio's profiles")
        source = self.profiles[key][1]
        if isinstance(source, Path):
            values["profile_path"] = str(source)
        else:
            values["profile"] = source
        settings = laser_settings(**values)
        drawing = self.vectorize(edits).drawing
        program = laser_program(drawing, settings.profile, settings.toolpath, settings.gcode,
                                name=self.drawing_path.name)
        return settings, program

    def laser_preview(self, edits: Edits, values: dict) -> dict:
        """The G-code's moves for the player on the planner's time axis, and the estimate."""
        from machines.job_time import format_duration
        from fabrication.player import laser_program_player_data

        settings, program = self.laser(edits, values)
        time = program.time
        data = laser_program_player_data(program, title=self.drawing_path.stem, profile=settings.profile)
        return {"player": data.to_dict(), "seconds": time.total_seconds,
                "time": format_duration(time.total_seconds), "naive": format_duration(time.naive_seconds),
                "burn_length": round(float(time.burn_length), 1), "travel_length": round(float(time.travel_length), 1),
                "lines": program.sent, "profile": settings.profile.name,  # the lines Send streams
                "warnings": list(settings.warnings)}

    def export(self, kind: str, edits: Edits, values: dict) -> tuple[str, str, bytes]:
        """(file name, media type, content) of one download."""
        from fabrication.embroidery.export import embroidery_bytes
        from machines.hoops import load_embroidery_profile
        from vectorize.svg_write import drawing_to_json, drawing_to_svg

        stem = self.drawing_path.stem
        if kind in ("svg", "json"):
            drawing = self.vectorize(edits).drawing
            if kind == "svg":
                return f"{stem}.svg", "image/svg+xml", drawing_to_svg(drawing).encode()
            return f"{stem}.json", "application/json", drawing_to_json(drawing).encode()
        if kind == "edits":
            return f"{stem}.edits.json", "application/json", edits.to_json().encode()
        if kind in EMBROIDERY_FORMATS:
            settings, result = self.embroidery(edits, values, kind)
            fmt = load_embroidery_profile().format_for(f"design.{kind}")
            data = embroidery_bytes(result.plan, fmt, pes_version=settings.pes_version)
            return f"{stem}.{kind}", "application/octet-stream", data
        if kind == "gcode":
            _, program = self.laser(edits, values)
            return f"{stem}.gcode", "text/plain", program.text.encode()
        raise InputError(f"unknown export {kind!r}")

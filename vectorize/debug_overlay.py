"""Debug overlays (`--debug DIR`): one PNG per stage, so a person can see why a result
came out as it did. Drawn in the working image's pixels."""

from __future__ import annotations

import colorsys
import os
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

from onestroke.atomic import atomic_open, make_folder
from vectorize.options import VectorizeResult

# The files write_debug_images may write, in stage order (the CLI refuses a --debug folder
# where one of them is an input).
STAGE_IMAGES = ("1-binary.png", "2-medial-axis.png", "3-graph.png", "4-intersections.png", "5-curve.png")
DEGREE_COLORS = {1: (0, 160, 0), 2: (120, 120, 120), 3: (230, 120, 0), 4: (200, 0, 200)}


def parameter_color(t: float) -> tuple[int, int, int]:
    """Colour of curve parameter t in [0, 1]: blue at the start through green to red."""
    r, g, b = colorsys.hsv_to_rgb(0.66 * (1.0 - float(t)), 0.9, 0.85)
    return int(r * 255), int(g * 255), int(b * 255)


def _base(gray: np.ndarray, fade: float = 0.6) -> Image.Image:
    light = (255 - (1.0 - gray) * 255 * (1.0 - fade)).clip(0, 255).astype(np.uint8)
    return Image.fromarray(light).convert("RGB")


def _save(image: Image.Image, path: Path) -> None:
    with atomic_open(path, "wb") as handle:
        image.save(handle, format="PNG")


def _draw_graph(draw: ImageDraw.ImageDraw, graph, *, degrees: bool) -> None:
    for branch in graph.branches.values():
        draw.line([tuple(p) for p in branch.points], fill=(30, 90, 220), width=1)
    for node, pos in graph.positions.items():
        degree = graph.degree(node)
        color = DEGREE_COLORS.get(degree, (220, 0, 0))
        r = 3 if degrees else 2
        draw.ellipse([pos[0] - r, pos[1] - r, pos[0] + r, pos[1] + r], fill=color)
        if degrees and degree != 2:
            draw.text((pos[0] + 4, pos[1] - 12), str(degree), fill=color)


def write_debug_images(result: VectorizeResult, folder: str | os.PathLike) -> list[Path]:
    """Write the stage overlays of a result made with `keep_stages=True` (and
    `whole_image_confidence=True` for the confidence the junctions image prints, as --debug
    asks); returns the paths."""
    stages = result.stages or {}
    folder = make_folder(folder)
    written: list[Path] = []
    if "ink" not in stages:
        return written
    ink = stages["ink"]

    binary = Image.fromarray(np.where(ink.ink, 0, 255).astype(np.uint8))
    _save(binary, folder / STAGE_IMAGES[0])
    written.append(folder / STAGE_IMAGES[0])

    image = _base(ink.gray)
    draw = ImageDraw.Draw(image)
    for ring in stages["rings"]:
        draw.line([tuple(p) for p in np.vstack([ring, ring[:1]])], fill=(0, 170, 170), width=1)
    _draw_graph(draw, stages["pruned"], degrees=False)
    _save(image, folder / STAGE_IMAGES[1])
    written.append(folder / STAGE_IMAGES[1])

    image = _base(ink.gray)
    draw = ImageDraw.Draw(image)
    _draw_graph(draw, stages["simplified"], degrees=True)
    simple = stages["simple"]
    for node in simple.y_feet:
        pos = stages["simplified"].positions[node]
        draw.text((pos[0] + 4, pos[1] + 2), "Y", fill=(230, 120, 0))
    _save(image, folder / STAGE_IMAGES[2])
    written.append(folder / STAGE_IMAGES[2])

    image = _base(ink.gray, fade=0.3)
    draw = ImageDraw.Draw(image)
    for node, junction in stages["junctions"].items():
        verdict = stages["verdicts"][node]
        c = junction.center
        color = (0, 150, 0) if verdict.is_crossing else (200, 0, 160)
        for d in junction.directions:
            draw.line([tuple(c), tuple(c + d * 3 * junction.width)], fill=color, width=2)
        label = f"{'X' if verdict.is_crossing else 'T'} {verdict.confidence:.2f}"
        draw.text((c[0] + 6, c[1] + 6), label, fill=color)
    _save(image, folder / STAGE_IMAGES[3])
    written.append(folder / STAGE_IMAGES[3])

    image = _base(ink.gray, fade=0.85)
    draw = ImageDraw.Draw(image)
    strokes = stages["working_strokes"]
    total = sum(s.length for s in strokes) or 1.0
    done = 0.0
    for stroke in strokes:
        points = stroke.sample_evenly(1.0)
        seg = np.linalg.norm(np.diff(points, axis=0), axis=1)
        along = done + np.concatenate([[0.0], np.cumsum(seg)])
        for i in range(len(points) - 1):
            draw.line([tuple(points[i]), tuple(points[i + 1])], fill=parameter_color(along[i] / total), width=3)
        s = stroke.start
        draw.ellipse([s[0] - 5, s[1] - 5, s[0] + 5, s[1] + 5], outline=(0, 0, 0), width=2)
        done += stroke.length
    _save(image, folder / STAGE_IMAGES[4])
    written.append(folder / STAGE_IMAGES[4])
    return written

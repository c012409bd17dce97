"""`vpype onestroke`: real vpype pipelines, their SVG compared with `onestroke vectorize`'s curve."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import svgelements as se
from PIL import Image

from tests.bridges.readback import curve_points, onestroke, svg_curves
from tests.drawings import alpha_loop, circle, render_polylines

VPYPE = shutil.which("vpype", path=str(Path(sys.executable).parent)) or shutil.which("vpype")
pytestmark = pytest.mark.skipif(VPYPE is None, reason="needs vpype: pip install '.[vpype]'")
EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "loops.png"
PX_PER_MM = 96 / 25.4


def vpype(*args, cwd) -> None:
    result = subprocess.run([VPYPE, *map(str, args)], capture_output=True, text=True, cwd=cwd)
    assert result.returncode == 0, result.stderr


def polylines(path: Path) -> list[np.ndarray]:
    """The lines vpype wrote, in document order: (N, 2) px each (svgelements applies the viewBox).
    vpype writes a closed line as a <polygon>: its first point is repeated at the end."""
    lines = []
    for element in se.SVG.parse(str(path), reify=True).elements():
        if isinstance(element, (se.Polyline, se.Polygon)):
            points = np.array([[p.x, p.y] for p in element.points], dtype=float)
            lines.append(np.vstack([points, points[:1]]) if isinstance(element, se.Polygon) else points)
    return lines


def follows(points: np.ndarray, curve: np.ndarray, tolerance: float) -> bool:
    """True when `points` lie within `tolerance` of `curve` (K, 4, 2) and run along it from its
    start to its end, each point at or after the previous one (the drawing order)."""
    dense = curve_points(curve, samples=2000)  # about 0.03 px apart
    step = np.linalg.norm(np.diff(dense, axis=0), axis=1)
    at = 0
    for point in points:
        # Look ahead along the curve up to a little more than the next point is away.
        reach = np.searchsorted(np.cumsum(step[at:]), np.linalg.norm(point - dense[at]) + 2 * tolerance + 1.0)
        window = dense[at:at + reach + 2]
        distance = np.linalg.norm(window - point, axis=1)
        if distance.min() > tolerance:
            return False
        at += int(distance.argmin())
    return np.linalg.norm(points[0] - dense[0]) <= tolerance and at >= len(dense) - 2


def test_readme_pipeline_writes_the_clis_curve(tmp_path):
    # The README's pipeline, on the README's drawing.
    vpype("onestroke", "--size", "90mm", EXAMPLE, "write", "loops-vpype.svg", cwd=tmp_path)
    made = onestroke("vectorize", EXAMPLE, "-o", tmp_path / "loops.svg", "--size", "90mm")
    assert made.returncode == 0, made.stderr
    lines, curves = polylines(tmp_path / "loops-vpype.svg"), svg_curves(tmp_path / "loops.svg")
    assert len(lines) == len(curves) == 1
    # Flattened within 0.05 mm, coordinates written to 4 decimals of a px, the curve read back
    # from the CLI's 3 decimals of a mm.
    assert follows(lines[0], curves[0], tolerance=0.05 * PX_PER_MM + 0.01)
    assert not follows(lines[0][::-1], curves[0], tolerance=0.05 * PX_PER_MM + 0.01)
    # The page is the CLI's page (the design at 90 mm plus half the ink width around it), and
    # the pen width is the measured ink width.
    page = se.SVG.parse(str(tmp_path / "loops-vpype.svg"))
    cli = se.SVG.parse(str(tmp_path / "loops.svg"))
    assert page.width == pytest.approx(cli.width, abs=0.01) and page.height == pytest.approx(cli.height, abs=0.01)
    pen = next(e for e in page.elements() if isinstance(e, se.Polyline)).stroke_width
    ink = next(e for e in cli.elements() if isinstance(e, se.Path)).stroke_width
    assert pen == pytest.approx(ink, rel=1e-3)


def test_multi_stroke_order_kept_through_order_keeping_commands(tmp_path):
    png = tmp_path / "two.png"
    Image.fromarray(render_polylines([circle(120, 130, 70), alpha_loop()[:250] * 0.5 + 160], width=6)).save(png)
    made = onestroke("vectorize", png, "-o", tmp_path / "two.svg", "--multi")
    assert made.returncode == 0, made.stderr
    curves = svg_curves(tmp_path / "two.svg")
    # Without --size the drawing keeps its pixels (1 px = 1 CSS px): no scaling at all.
    vpype("onestroke", "--multi", png, "linesimplify", "--tolerance", "0.01mm",
          "write", "two-vpype.svg", cwd=tmp_path)
    lines = polylines(tmp_path / "two-vpype.svg")
    assert len(lines) == len(curves) == 2
    for line, curve in zip(lines, curves):
        assert follows(line, curve, tolerance=(0.05 + 0.01) * PX_PER_MM + 0.01)


def test_bad_input_is_one_line_from_vpype(tmp_path):
    blank = tmp_path / "blank.png"
    Image.new("L", (200, 200), 255).save(blank)
    for args, message in ((["--threshold", "2", EXAMPLE], "Error: --threshold 2 must be above 0 to below 1"),
                          ([blank], "Error: no ink found: the image is blank")):
        result = subprocess.run([VPYPE, "onestroke", *map(str, args), "write", "x.svg"], capture_output=True,
                                text=True, cwd=tmp_path)
        assert result.returncode != 0
        assert result.stderr.strip() == message
        assert not (tmp_path / "x.svg").exists()

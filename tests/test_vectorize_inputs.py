"""Bad and unusual inputs: one-line errors with exit code 2 and no output file; SVG input."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from click.testing import CliRunner
from PIL import Image

from fabrication.cli import main
from tests.conftest import circle, figure_eight, render_polylines


def run_cli(*args):
    return CliRunner().invoke(main, list(map(str, args)))


def _bad_files(tmp_path):
    blank = tmp_path / "blank.png"
    Image.new("L", (200, 200), 255).save(blank)
    black = tmp_path / "black.png"
    Image.new("L", (200, 200), 0).save(black)
    tiny = tmp_path / "tiny.png"
    Image.new("L", (1, 1), 0).save(tiny)
    text = tmp_path / "notes.png"
    text.write_text("this is not an image\n")
    good = tmp_path / "good.png"
    Image.fromarray(render_polylines([circle()])).save(good)
    corrupt = tmp_path / "corrupt.png"
    corrupt.write_bytes(good.read_bytes()[: len(good.read_bytes()) // 2])
    folder = tmp_path / "folder.png"
    folder.mkdir()
    return {
        "missing": (tmp_path / "missing.png", "does not exist"),
        "not an image": (text, "not an image"),
        "corrupt": (corrupt, "damaged or truncated"),
        "blank": (blank, "no ink found"),
        "all ink": (black, "all ink"),
        "1x1": (tiny, "too small"),
        "directory": (folder, "directory"),
    }


@pytest.mark.parametrize("case", ["missing", "not an image", "corrupt", "blank", "all ink", "1x1", "directory"])
def test_bad_input_is_a_one_line_error_with_exit_code_2(tmp_path, case):
    path, words = _bad_files(tmp_path)[case]
    out = tmp_path / "out.svg"
    result = run_cli("vectorize", path, "-o", out)
    assert result.exit_code == 2, result.output
    message = result.output.strip()
    assert message.startswith("error:") and len(message.splitlines()) == 1
    assert words in message
    assert not out.exists()
    assert not list(tmp_path.glob(".out.svg*"))  # no temporary left behind


def test_bad_output_paths(tmp_path, write_png):
    source = write_png(render_polylines([circle()]))
    assert run_cli("vectorize", source, "-o", tmp_path / "out.pdf").exit_code == 2
    assert run_cli("vectorize", source, "-o", tmp_path / "no" / "such" / "dir.svg").exit_code == 2
    bad_threshold = run_cli("vectorize", source, "-o", tmp_path / "o.svg", "--threshold", "1.5")
    assert bad_threshold.exit_code == 2 and "threshold" in bad_threshold.output


def test_a_real_process_prints_no_traceback(tmp_path):
    process = subprocess.run([sys.executable, "-m", "fabrication.cli", "vectorize", str(tmp_path / "nope.png"),
                              "-o", str(tmp_path / "o.svg")], capture_output=True, text=True)
    assert process.returncode == 2
    assert "Traceback" not in process.stderr
    assert process.stderr.strip().count("\n") == 0


def test_huge_image_is_downscaled_and_says_so(tmp_path):
    path = tmp_path / "huge.png"
    small = render_polylines([figure_eight()], size=(400, 300), width=6)
    Image.fromarray(small).resize((8000, 6000), Image.BILINEAR).save(path)
    out = tmp_path / "huge.svg"
    result = run_cli("vectorize", path, "-o", out, "--classifier", "geometric")
    assert result.exit_code == 0, result.output
    assert "downscaled" in result.output and "8000x6000" in result.output
    from vectorize.svg.svg_read import read_svg

    content = read_svg(out)
    assert (content.width, content.height) == (8000, 6000)
    assert len(content.strokes) == 1
    xmin, ymin, xmax, ymax = content.strokes[0].bounds()
    assert xmin == pytest.approx(50 * 20, abs=40) and xmax == pytest.approx(350 * 20, abs=40)


def test_dropped_pieces_are_reported(tmp_path, write_png):
    lines = [np.array([[50.0, 100.0], [350.0, 120.0]]), np.array([[60.0, 300.0], [340.0, 280.0]])]
    source = write_png(render_polylines(lines))
    result = run_cli("vectorize", source, "-o", tmp_path / "o.svg", "--classifier", "geometric")
    assert result.exit_code == 0
    assert "1 separate ink piece(s) dropped" in result.output
    multi = run_cli("vectorize", source, "-o", tmp_path / "m.svg", "--multi", "--classifier", "geometric")
    assert multi.exit_code == 0 and "2 strokes" in multi.output


def test_svg_strokes_in_document_order_with_transforms(tmp_path):
    svg = tmp_path / "strokes.svg"
    svg.write_text(
        '<svg xmlns="http://www.w3.org/2000/svg" width="300" height="200" viewBox="0 0 300 200">'
        '<g transform="translate(100 50) scale(2)"><path d="M0 0 L10 0" stroke="black" fill="none"/></g>'
        '<polyline points="0,0 50,50 100,0" stroke="black" fill="none"/>'
        '<line x1="5" y1="150" x2="250" y2="150" stroke="black"/></svg>')
    from vectorize import vectorize_file

    drawing = vectorize_file(svg).drawing
    assert len(drawing.strokes) == 3
    first, second, third = drawing.strokes
    assert np.allclose(first.start, [100, 50]) and np.allclose(first.end, [120, 50])
    assert second.length == pytest.approx(2 * np.hypot(50, 50))
    assert np.allclose(third.end, [250, 150])


def test_filled_outline_svg_is_vectorized_to_its_centre_line(tmp_path):
    import shapely

    truth = figure_eight()
    shape = shapely.LineString(truth).buffer(4.0)

    def ring(r):
        return "M" + " L".join(f"{x:.3f} {y:.3f}" for x, y in np.asarray(r.coords)) + "Z"

    d = " ".join([ring(shape.exterior)] + [ring(i) for i in shape.interiors])
    svg = tmp_path / "outline.svg"
    svg.write_text(f'<svg xmlns="http://www.w3.org/2000/svg" width="400" height="400">'
                   f'<path fill="#000" fill-rule="evenodd" d="{d}"/></svg>')
    from scipy.spatial import cKDTree

    from vectorize import VectorizeOptions, vectorize_file
    from vectorize.stroke import Stroke

    result = vectorize_file(svg, VectorizeOptions(classifier="geometric"))
    assert result.report.strokes == 1 and result.report.intersections == 1
    dense = Stroke.from_polyline(truth).sample_evenly(0.05)
    error = cKDTree(dense).query(result.drawing.strokes[0].sample_evenly(2.0))[0]
    assert error.max() < 1.0
    assert result.drawing.stroke_width == pytest.approx(8.0, abs=1.0)


@pytest.mark.parametrize("mode", ["I;16", "RGBA", "LA", "P", "RGB-jpeg"])
def test_image_modes_all_read_as_the_same_drawing(tmp_path, mode):
    from vectorize import VectorizeOptions, vectorize_file

    gray = render_polylines([figure_eight()])
    if mode == "I;16":
        image = Image.fromarray(gray.astype(np.uint16) * 257)
    elif mode == "RGBA":  # ink as opacity over a transparent page
        rgba = np.zeros(gray.shape + (4,), np.uint8)
        rgba[..., 3] = 255 - gray
        image = Image.fromarray(rgba, "RGBA")
    elif mode == "RGB-jpeg":
        image = Image.fromarray(gray).convert("RGB")
    else:
        image = Image.fromarray(gray).convert(mode)
    path = tmp_path / ("d.jpg" if mode == "RGB-jpeg" else "d.png")
    image.save(path)
    result = vectorize_file(path, VectorizeOptions(classifier="geometric"))
    assert result.report.strokes == 1 and result.report.intersections == 1
    assert result.drawing.strokes[0].length == pytest.approx(1070, rel=0.02)


def shaded_scan(drawing: np.ndarray, seed: int = 0) -> np.ndarray:
    """`drawing` (uint8) as an unevenly lit scan, the benchmark's "scan" condition: paper
    0.68-0.98 across the page, gray ink, grain, JPEG. A global threshold cuts such a page
    in half."""
    from benchmarks.sets.conditions import condition_image

    image, _ = condition_image(None, drawing.astype(np.float64) / 255.0, "scan", np.random.default_rng(seed))
    return image


def test_unevenly_lit_scan_is_flattened_before_thresholding():
    from skimage.filters import threshold_li

    from vectorize import VectorizeOptions, vectorize_image
    from vectorize.raster.binarize import flatten_paper

    clean = render_polylines([figure_eight()], width=4.0)
    scan = shaded_scan(clean)
    raw = scan.astype(np.float32) / 255
    assert (raw < threshold_li(raw)).mean() > 0.2  # unflattened, the threshold splits the paper
    result = vectorize_image(scan, VectorizeOptions(seed=0))
    assert result.report.strokes == 1 and result.report.intersections == 1
    reference = vectorize_image(clean, VectorizeOptions(seed=0)).drawing.strokes[0]
    assert abs(result.drawing.strokes[0].length - reference.length) < 0.02 * reference.length
    # Evenly lit white paper is left as it is.
    white = clean.astype(np.float32) / 255
    assert np.abs(flatten_paper(white) - white).max() < 1e-6


def test_noise_is_refused_quickly_with_a_hint(tmp_path, write_png):
    import time

    speckle = np.where(np.random.default_rng(3).random((600, 600)) < 0.3, 0, 255).astype(np.uint8)
    out = tmp_path / "out.svg"
    start = time.perf_counter()
    result = run_cli("vectorize", write_png(speckle), "-o", out)
    assert time.perf_counter() - start < 30
    assert result.exit_code == 2, result.output
    message = result.output.strip()
    assert message.startswith("error:") and len(message.splitlines()) == 1
    assert "noise" in message and "--threshold" in message
    assert not out.exists()


def test_dark_frame_around_a_photographed_sheet_is_ignored():
    from vectorize import VectorizeOptions, vectorize_image

    sheet = shaded_scan(render_polylines([figure_eight()], width=4.0))
    photo = np.full((sheet.shape[0] + 120, sheet.shape[1] + 120), 45, dtype=np.uint8)  # the table
    photo[60:-60, 60:-60] = sheet
    result = vectorize_image(photo, VectorizeOptions(seed=0))
    assert result.report.strokes == 1 and result.report.intersections == 1
    assert any("dark frame" in w for w in result.report.warnings)
    stroke = result.drawing.strokes[0]
    assert stroke.is_closed
    assert np.allclose(stroke.bounds()[:2], np.array([50.0, 100.0]) + 60, atol=4)
    # A thin line that runs off the image edge is a line, not a frame.
    cropped = render_polylines([figure_eight()], width=4.0)[:, 60:340]
    result = vectorize_image(cropped, VectorizeOptions(seed=0))
    assert not any("dark frame" in w for w in result.report.warnings)
    assert result.report.strokes >= 1

"""SVG for other tools: Ink/Stitch's parameters (`vectorize --inkstitch`) and documents at
physical size for laser senders (`vectorize --size`), read back with svgelements and Inkscape."""

from __future__ import annotations

import re
import shutil
import subprocess
import tomllib
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
import shapely
from click.testing import CliRunner
from PIL import Image

from tests.bridges.readback import curve_points, svg_curves
from tests.drawings import alpha_loop, circle, render_polylines
from fabrication.bridges.inkstitch import satin_columns
from fabrication.cli import main
from vectorize.stroke import Stroke

PARAMS = tomllib.loads((Path(__file__).parent / "inkstitch_params.toml").read_text())
INKSTITCH = PARAMS["namespace"]
PX_PER_MM = 96 / 25.4
INKSCAPE = shutil.which("inkscape")


@pytest.fixture(scope="module")
def drawings(tmp_path_factory):
    """A single-line drawing and a two-piece one (400 x 400 px), with `onestroke vectorize`'s
    plain output (px) of each."""
    folder = tmp_path_factory.mktemp("svg")
    single, multi = folder / "loop.png", folder / "two.png"
    Image.fromarray(render_polylines([alpha_loop()], width=8)).save(single)
    Image.fromarray(render_polylines([circle(120, 130, 70), alpha_loop()[:250] * 0.5 + 160], width=6)).save(multi)
    for png, extra in ((single, []), (multi, ["--multi"])):
        result = CliRunner().invoke(main, ["vectorize", str(png), "-o", str(png.with_suffix(".svg")), *extra])
        assert result.exit_code == 0, result.output
    return {"folder": folder, "single": single, "multi": multi}


def vectorize(*args) -> None:
    result = CliRunner().invoke(main, ["vectorize", *map(str, args)])
    assert result.exit_code == 0, result.output


def similarity(source: np.ndarray, target: np.ndarray) -> tuple[float, float]:
    """(scale, largest residual) of the best target = scale * source + shift, point by point."""
    a, b = source.reshape(-1, 2), target.reshape(-1, 2)
    ac, bc = a - a.mean(axis=0), b - b.mean(axis=0)
    scale = float((ac * bc).sum() / (ac * ac).sum())
    return scale, float(np.abs(bc - scale * ac).max())


def inkstitch_attributes(path: Path) -> list[dict[str, str]]:
    """Each path's `inkstitch:` attributes (local name -> value), in document order."""
    paths = ET.parse(path).getroot().iter("{http://www.w3.org/2000/svg}path")
    return [{k.split("}")[1]: v for k, v in p.attrib.items() if k.startswith("{" + INKSTITCH + "}")} for p in paths]


def check_value(kind: dict, value: str) -> None:
    if kind["type"] == "float":
        float(value)
    elif kind["type"] == "int":
        int(value)
    elif kind["type"] == "boolean":
        assert value in ("true", "false")
    elif kind["type"] == "combo":
        assert value in kind["values"]


@pytest.mark.parametrize("stitch", ["running", "triple", "zigzag", "satin"])
def test_every_inkstitch_attribute_is_one_inkstitch_documents(drawings, tmp_path, stitch):
    out = tmp_path / f"{stitch}.svg"
    vectorize(drawings["multi"], "-o", out, "--multi", "--inkstitch", stitch, "--size", "90mm")
    text = out.read_text()
    assert f'xmlns:inkstitch="{INKSTITCH}"' in text.split("\n")[1]
    kinds = PARAMS["satin" if stitch == "satin" else "stroke"]
    written = inkstitch_attributes(out)
    assert written and all(written)
    for attributes in written:
        for name, value in attributes.items():
            assert name in kinds, f"inkstitch:{name} is not on the checked list for {stitch}"
            check_value(kinds[name], value)
    expected = {"running": ("running_stitch", None), "triple": ("running_stitch", "1"),
                "zigzag": ("zigzag_stitch", None), "satin": (None, None)}[stitch]
    if stitch != "satin":
        assert {a["stroke_method"] for a in written} == {expected[0]}
        assert ("bean_stitch_repeats" in written[0]) == (stitch == "triple")
    else:
        assert all(a["satin_column"] == "true" for a in written)
    # Inkscape reads it: every path is listed with its box.
    if INKSCAPE:
        queried = subprocess.run([INKSCAPE, "--query-all", str(out)], capture_output=True, text=True)
        assert queried.returncode == 0
        ids = {line.split(",")[0] for line in queried.stdout.splitlines()}
        assert {f"stroke-{i + 1}" for i in range(len(written))} <= ids


def test_inkstitch_document_is_in_mm_and_keeps_the_drawing_order(drawings, tmp_path):
    out = tmp_path / "running.svg"
    vectorize(drawings["multi"], "-o", out, "--multi", "--inkstitch", "running", "--size", "90mm")
    root = ET.parse(out).getroot()
    width, height = (float(root.get(k).removesuffix("mm")) for k in ("width", "height"))
    assert root.get("viewBox") == f"0 0 {root.get('width')[:-2]} {root.get('height')[:-2]}"
    curves = svg_curves(out)
    reference = svg_curves(drawings["multi"].with_suffix(".svg"))
    assert len(curves) == len(reference) == 2
    # Point for point the same curves, in the same order, only scaled (px -> mm at 90 mm).
    scale, residual = similarity(np.concatenate(reference), np.concatenate(curves))
    assert residual < 0.01 * PX_PER_MM
    box = np.concatenate([curve_points(c) for c in curves])
    ink = float(root.find("{http://www.w3.org/2000/svg}g").get("stroke-width"))
    assert max(np.ptp(box, axis=0)) / PX_PER_MM == pytest.approx(90, abs=0.5)
    assert max(width, height) == pytest.approx(90 + ink, abs=0.5)


def test_satin_columns_have_rails_either_side_and_rungs_across(drawings, tmp_path):
    out = tmp_path / "satin.svg"
    vectorize(drawings["single"], "-o", out, "--inkstitch", "satin", "--size", "60mm")
    plain = tmp_path / "plain.svg"
    vectorize(drawings["single"], "-o", plain, "--size", "60mm")
    centre = svg_curves(plain)[0]
    line = shapely.LineString(curve_points(centre))
    paths = ET.parse(out).getroot().iter("{http://www.w3.org/2000/svg}path")
    columns = [p.get("d") for p in paths]
    assert columns
    for d in columns:
        parts = [np.array(re.findall(r"-?\d+(?:\.\d+)?", piece), dtype=float).reshape(-1, 2)
                 for piece in d.split("M")[1:]]
        rails, rungs = parts[:2], parts[2:]
        assert rungs, "a satin column carries its rungs"
        widths = [float(v) for v in ET.parse(plain).getroot().find(
            ".//{http://www.w3.org/2000/svg}path").get("data-widths").split()[1::2]]
        for rail in rails:
            rail_px = rail[::3] * PX_PER_MM  # the polyline's corners (every third point of its cubics)
            distance = np.array([line.distance(shapely.Point(p)) for p in rail_px]) / PX_PER_MM
            # Half the ink width measured along the stroke, within the rounding of the files.
            assert min(widths) / 2 - 0.01 <= np.median(distance) <= max(widths) / 2 + 0.01
        for rung in rungs:
            crossing = [shapely.LineString(rung).intersection(shapely.LineString(r[::3])) for r in rails]
            assert all(isinstance(c, shapely.Point) for c in crossing), "a rung crosses each rail once"


def test_laser_svg_at_physical_size_one_path_per_stroke_in_order(drawings, tmp_path):
    out = tmp_path / "laser.svg"
    vectorize(drawings["multi"], "-o", out, "--multi", "--size", "80mm")
    text = out.read_text()
    assert "transform" not in text, "LightBurn and LaserGRBL read no transforms wrongly if there are none"
    root = ET.parse(out).getroot()
    assert root.get("width").endswith("mm") and root.get("height").endswith("mm")
    assert root.get("viewBox").startswith("0 0 ")
    paths = list(root.iter("{http://www.w3.org/2000/svg}path"))
    reference = svg_curves(drawings["multi"].with_suffix(".svg"))
    assert len(paths) == len(reference) == 2
    assert all(p.get("d").count("M") == 1 for p in paths), "one sub-path per path: one stroke each"
    curves = svg_curves(out)
    scale, residual = similarity(np.concatenate(reference), np.concatenate(curves))
    assert residual < 0.01 * PX_PER_MM
    box = np.concatenate([curve_points(c) for c in curves]) / PX_PER_MM
    assert max(np.ptp(box, axis=0)) == pytest.approx(80, abs=0.5)
    assert box.min() > 0, "the design lies on the page"
    if INKSCAPE:
        queried = subprocess.run([INKSCAPE, "--query-all", str(out)], capture_output=True, text=True)
        page = queried.stdout.splitlines()[0].split(",")
        assert float(page[3]) / PX_PER_MM == pytest.approx(float(root.get("width")[:-2]), abs=0.05)


@pytest.mark.parametrize("args,message", [
    (["-o", "x.json", "--inkstitch", "running"], "--inkstitch writes an SVG"),
    (["-o", "x.svg", "--size", "90mm", "--width", "30mm"], "give only one of --size, --width, --height"),
])
def test_page_options_are_refused_before_any_work(drawings, tmp_path, args, message):
    result = CliRunner().invoke(main, ["vectorize", str(drawings["single"]),
                                       *[str(tmp_path / a) if a.startswith("x.") else a for a in args]])
    assert result.exit_code == 2
    assert message in result.output
    assert list(tmp_path.iterdir()) == []


def test_the_cli_offers_every_stitch_the_bridge_writes():
    from fabrication.bridges.inkstitch import STITCHES
    from fabrication.cli.vectorize_cmd import vectorize as command

    choice = next(p for p in command.params if p.name == "inkstitch").type
    assert tuple(choice.choices) == STITCHES


def test_satin_rails_follow_the_ink_width_along_the_stroke():
    # A straight 40 mm stroke whose ink widens from 1 mm to 3 mm: the rails open with it.
    stroke = Stroke.from_polyline(np.array([[0.0, 0.0], [40.0, 0.0]])).with_widths([[0.0, 1.0], [1.0, 3.0]])
    (column,) = satin_columns(stroke, width=2.0)
    rails, rungs = column[:2], column[2:]
    for rail in rails:
        x, y = rail.control[:, 0, 0], rail.control[:, 0, 1]
        assert np.abs(np.abs(y) - (1.0 + 2.0 * x / 40.0) / 2).max() < 1e-9
    assert rails[0].control[0, 0, 1] * rails[1].control[0, 0, 1] < 0, "one rail each side"
    assert len(rungs) == 20  # every 2 mm
    plain = Stroke.from_polyline(np.array([[0.0, 0.0], [40.0, 0.0]]))  # no widths measured: `width`
    assert np.abs(np.abs(satin_columns(plain, width=2.0)[0][0].control[:, :, 1]) - 1.0).max() < 1e-9

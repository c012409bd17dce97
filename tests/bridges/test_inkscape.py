"""The Inkscape extension, run the way Inkscape 1.2 runs it, checked against `onestroke vectorize`.

Inkscape 1.2 cannot run an effect extension without its window: effects become actions only
in GUI mode (`inkscape --action-list` lists none, and `--actions=select-by-id:img1;
org.onestroke.vectorize;export-do` answers "could not find action", as it does for Inkscape's
own org.inkscape.color.grayscale), and in the GUI an effect with parameters opens its dialog. So the script runs as Inkscape's Script::execute runs it: Debian's
/usr/bin/python3 (the interpreter Inkscape's Debian package depends on, with python3-lxml) with
Inkscape's bundled inkex on PYTHONPATH, the extension's folder as working directory,
`--id=...` and one `--name=value` per parameter, a copy of the document as the last argument,
DOCUMENT_PATH naming the saved document, and the new document read from stdout. The real
`inkscape` binary then reads the result (`--query-all`) and renders it (`--export-type=png`).
"""

from __future__ import annotations

import base64
import functools
import json
import os
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
import shapely
import svgelements as se
from PIL import Image

import fabrication.bridges
from tests.bridges.readback import affine, moved, onestroke, rotation, svg_curves
from tests.chromium import ARTIFACTS
from tests.drawings import alpha_loop, circle, render_polylines

INKSCAPE = shutil.which("inkscape")
PYTHON = "/usr/bin/python3"  # Debian's, as Inkscape's package runs extensions with it
pytestmark = pytest.mark.skipif(INKSCAPE is None or not Path(PYTHON).exists(),
                                reason="needs Debian's inkscape and python3 (tests/conftest.py installs them as root)")
PX_PER_MM = 96 / 25.4
SVG = 'xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink"'


@functools.cache
def inkex_folder() -> str:
    """Inkscape's own extensions folder (where its inkex lives)."""
    data = subprocess.run([INKSCAPE, "--system-data-directory"], capture_output=True, text=True).stdout
    return str(Path(data.strip().splitlines()[-1]) / "extensions")


def run_extension(folder: Path, document: Path, ids: list[str], **params) -> subprocess.CompletedProcess:
    """Run the installed extension on `document` as Inkscape does (see the module's docstring)."""
    copy = document.with_name("ink_ext_XXXXXX.svg")  # Inkscape hands over a saved copy
    shutil.copyfile(document, copy)
    values = {"tab": "options", "threshold": 0, "blur": 0, "multi": "false", "classifier": "cnn",
              "keep": "true", "inkstitch": "none", **params}
    argv = [PYTHON, "onestroke_vectorize.py", *(f"--id={i}" for i in ids),
            *(f"--{k}={v}" for k, v in values.items()), str(copy)]
    env = {"PATH": "/usr/bin:/bin", "HOME": str(folder), "PYTHONPATH": inkex_folder(),
           "DOCUMENT_PATH": str(document), "SELF_CALL": "true", "INKSCAPE_PROFILE_DIR": str(folder)}
    return subprocess.run(argv, capture_output=True, text=True, cwd=folder, env=env)


@pytest.fixture(scope="module")
def work(tmp_path_factory):
    """A folder with the extension installed by `onestroke inkscape install --dir`, a drawing
    (400 x 400 px PNG) and the curve `onestroke vectorize` makes of it."""
    folder = tmp_path_factory.mktemp("inkscape")
    installed = onestroke("inkscape", "install", "--dir", folder / "extensions")
    assert installed.returncode == 0, installed.stderr
    assert str(folder / "extensions" / "onestroke_vectorize.inx") in installed.stdout
    assert "installed in" in installed.stdout
    png = folder / "drawing.png"
    Image.fromarray(render_polylines([alpha_loop()], width=8)).save(png)
    made = onestroke("vectorize", png, "-o", folder / "reference.svg")
    assert made.returncode == 0, made.stderr
    return {"folder": folder, "extension": folder / "extensions", "png": png,
            "reference": svg_curves(folder / "reference.svg")}


def embedded(png: Path) -> str:
    return "data:image/png;base64," + base64.b64encode(png.read_bytes()).decode()


def written(result: subprocess.CompletedProcess, tmp: Path, name: str) -> Path:
    """The document the extension wrote on stdout, saved as Inkscape would read it."""
    assert result.returncode == 0, result.stderr
    assert "Traceback" not in result.stderr
    path = tmp / name
    path.write_text(result.stdout)
    return path


def new_curves(path: Path, before: int) -> list[np.ndarray]:
    """The curves the extension added (the document's curves after the first `before`)."""
    return svg_curves(path)[before:]


def assert_same(curves: list[np.ndarray], expected: list[np.ndarray], tolerance: float = 0.1) -> None:
    assert len(curves) == len(expected)
    for got, want in zip(curves, expected):
        assert got.shape == want.shape
        assert np.abs(got - want).max() < tolerance, np.abs(got - want).max()


def test_embedded_transformed_bitmap_matches_the_cli(work, tmp_path):
    # A layer moved, the image rotated and scaled unevenly, preserveAspectRatio="none".
    document = tmp_path / "embedded.svg"
    document.write_text(f'<svg {SVG} width="800" height="800" viewBox="0 0 800 800">'
                        '<g id="layer" transform="translate(30,40)">'
                        '<image id="bitmap" x="50" y="60" width="300" height="200" preserveAspectRatio="none" '
                        f'transform="rotate(25) scale(1.3,0.9)" xlink:href="{embedded(work["png"])}"/></g></svg>')
    out = written(run_extension(work["extension"], document, ["bitmap"]), tmp_path, "out.svg")
    place = (affine(e=30, f=40) @ rotation(25) @ affine(1.3, 0, 0, 0.9)
             @ affine(300 / 400, 0, 0, 200 / 400, 50, 60))
    assert_same(new_curves(out, 0), [moved(c, place) for c in work["reference"]])
    root = se.SVG.parse(str(out))
    assert any(isinstance(e, se.Image) for e in root.elements()), "the bitmap is kept"


def test_linked_bitmap_in_a_mm_document_keeps_its_aspect(work, tmp_path):
    # A relative link (resolved against DOCUMENT_PATH: Inkscape hands over a copy elsewhere),
    # the default xMidYMid meet, user units in mm.
    shutil.copyfile(work["png"], tmp_path / "linked.png")
    document = tmp_path / "linked.svg"
    document.write_text(f'<svg {SVG} width="200mm" height="150mm" viewBox="0 0 200 150">'
                        '<image id="bitmap" x="20" y="10" width="120" height="80" xlink:href="linked.png"/></svg>')
    out = written(run_extension(work["extension"], document, ["bitmap"], keep="false"), tmp_path, "out.svg")
    scale = 80 / 400  # meet: the smaller of 120/400 and 80/400; centred across the width
    place = affine(PX_PER_MM, 0, 0, PX_PER_MM) @ affine(scale, 0, 0, scale, 20 + (120 - 400 * scale) / 2, 10)
    assert_same(new_curves(out, 0), [moved(c, place) for c in work["reference"]])
    assert "<image" not in out.read_text(), "keep=false removes the bitmap"
    # The stroke width is the measured ink width, in the document's units.
    path = next(e for e in se.SVG.parse(str(out)).elements() if isinstance(e, se.Path))
    ink = se.SVG.parse(str(work["folder"] / "reference.svg")).elements()
    ink_width = next(e for e in ink if isinstance(e, se.Path)).stroke_width
    assert path.stroke_width == pytest.approx(ink_width * scale * PX_PER_MM, rel=1e-3)


def test_filled_outline_matches_the_cli(work, tmp_path):
    # The ink's outline (the buffered loop, its holes included), filled, with a transform.
    ring = shapely.LineString(alpha_loop()).buffer(4.0, quad_segs=8)
    rings = [ring.exterior, *ring.interiors]
    d = " ".join("M " + " L ".join(f"{x:.3f} {y:.3f}" for x, y in r.coords) + " Z" for r in rings)
    document = tmp_path / "outline.svg"
    document.write_text(f'<svg {SVG} width="500" height="500" viewBox="0 0 500 500">'
                        f'<path id="outline" transform="translate(60,-20) rotate(-15)" fill="#aa2200" '
                        f'fill-rule="evenodd" d="{d}"/></svg>')
    reference = onestroke("vectorize", document, "-o", tmp_path / "reference.svg")
    assert reference.returncode == 0, reference.stderr
    out = written(run_extension(work["extension"], document, ["outline"]), tmp_path, "out.svg")
    curves = svg_curves(out)
    # The outline's own rings come first in the document; the curve after them.
    assert_same(curves[len(rings):], svg_curves(tmp_path / "reference.svg"))
    assert 'stroke:#aa2200' in out.read_text(), "the curve takes the outline's colour"


def test_multi_stroke_gives_one_path_per_stroke_in_order(work, tmp_path):
    png = tmp_path / "two.png"
    Image.fromarray(render_polylines([circle(120, 130, 70), alpha_loop()[:250] * 0.5 + 160], width=6)).save(png)
    made = onestroke("vectorize", png, "-o", tmp_path / "reference.svg", "--multi")
    assert made.returncode == 0, made.stderr
    document = tmp_path / "two.svg"
    document.write_text(f'<svg {SVG} width="400" height="400" viewBox="0 0 400 400">'
                        f'<image id="bitmap" x="0" y="0" width="400" height="400" xlink:href="{embedded(png)}"/>'
                        '</svg>')
    out = written(run_extension(work["extension"], document, ["bitmap"], multi="true"), tmp_path, "out.svg")
    reference = svg_curves(tmp_path / "reference.svg")
    assert len(reference) == 2
    assert_same(new_curves(out, 0), reference)
    group = next(e for e in ET.parse(out).getroot().iter("{http://www.w3.org/2000/svg}g"))
    assert len(list(group.iter("{http://www.w3.org/2000/svg}path"))) == 2, "the strokes are grouped, in order"


def test_satin_for_ink_stitch_and_inkscape_reads_it(work, tmp_path):
    document = tmp_path / "embedded.svg"
    document.write_text(f'<svg {SVG} width="400" height="400" viewBox="0 0 400 400">'
                        f'<image id="bitmap" x="0" y="0" width="400" height="400" xlink:href="{embedded(work["png"])}"/>'
                        '</svg>')
    out = written(run_extension(work["extension"], document, ["bitmap"], inkstitch="satin", keep="false"),
                  tmp_path, "satin.svg")
    text = out.read_text()
    assert 'xmlns:inkstitch="http://inkstitch.org/namespace"' in text.split(">", 2)[0] + text.split(">", 2)[1]
    assert 'inkstitch:satin_column="true"' in text
    # Each satin column is one path: two rails, then rungs.
    columns = [e for e in se.SVG.parse(str(out), reify=True).elements() if isinstance(e, se.Path)]
    assert columns and all(len(list(c.as_subpaths())) >= 3 for c in columns)
    queried = subprocess.run([INKSCAPE, "--query-all", str(out)], capture_output=True, text=True)
    assert queried.returncode == 0
    ids = [line.split(",")[0] for line in queried.stdout.splitlines()]
    assert all(c.id in ids for c in columns)


def test_inkscape_renders_the_curve_on_the_ink(work, tmp_path):
    """Inkscape's own rendering of the output lies on the input bitmap's ink; the PNG of it
    beside the input is kept in test-artifacts/."""
    document = tmp_path / "plain.svg"
    document.write_text(f'<svg {SVG} width="400" height="400" viewBox="0 0 400 400">'
                        f'<image id="bitmap" x="0" y="0" width="400" height="400" xlink:href="{embedded(work["png"])}"/>'
                        '</svg>')
    out = written(run_extension(work["extension"], document, ["bitmap"], keep="false"), tmp_path, "plain-out.svg")
    png = tmp_path / "render.png"
    rendered = subprocess.run([INKSCAPE, "--export-type=png", "--export-background=white",
                               "--export-background-opacity=1", "--export-area-page", f"--export-filename={png}",
                               str(out)], capture_output=True, text=True)
    assert rendered.returncode == 0, rendered.stderr
    drawn = np.asarray(Image.open(png).convert("L")) < 128
    ink = np.asarray(Image.open(work["png"]).convert("L")) < 128
    assert drawn.shape == ink.shape
    # The rendered line (as wide as the measured ink) covers the ink and stays on it.
    assert (drawn & ink).sum() / drawn.sum() > 0.97
    assert (drawn & ink).sum() / ink.sum() > 0.90
    ARTIFACTS.mkdir(exist_ok=True)
    side = Image.new("L", (2 * ink.shape[1] + 20, ink.shape[0]), 255)
    side.paste(Image.open(work["png"]).convert("L"), (0, 0))
    side.paste(Image.open(png).convert("L"), (ink.shape[1] + 20, 0))
    side.save(ARTIFACTS / "inkscape-extension.png")


def test_errors_reach_the_message_box_as_one_line(work, tmp_path):
    blank = tmp_path / "blank.png"
    Image.new("L", (200, 200), 255).save(blank)
    document = tmp_path / "blank.svg"
    document.write_text(f'<svg {SVG} width="200" height="200"><rect id="box" width="10" height="10" fill="none" '
                        f'stroke="#000"/><image id="bitmap" width="200" height="200" xlink:href="{embedded(blank)}"/>'
                        '</svg>')
    nothing = run_extension(work["extension"], document, [])
    unfilled = run_extension(work["extension"], document, ["box"])
    failed = run_extension(work["extension"], document, ["bitmap"])
    for result in (nothing, unfilled, failed):
        assert result.returncode != 0
        assert "Traceback" not in result.stderr
        assert len(result.stderr.strip().splitlines()) == 1, result.stderr
    assert "select a bitmap or a filled outline" in nothing.stderr
    assert "is not filled" in unfilled.stderr
    direct = onestroke("vectorize", blank, "-o", tmp_path / "x.svg")
    assert direct.returncode == 2
    assert failed.stderr.strip() == f"onestroke {direct.stderr.strip()}"


def test_a_missing_onestroke_is_named(work, tmp_path):
    moved_away = tmp_path / "extension"
    shutil.copytree(work["extension"], moved_away)
    (moved_away / "onestroke_vectorize.json").write_text(json.dumps({"python": "/nowhere/bin/python"}))
    document = tmp_path / "doc.svg"
    document.write_text(f'<svg {SVG} width="400" height="400"><image id="bitmap" width="400" height="400" '
                        f'xlink:href="{embedded(work["png"])}"/></svg>')
    result = run_extension(moved_away, document, ["bitmap"])
    assert result.returncode != 0 and "Traceback" not in result.stderr
    assert "/nowhere/bin/python" in result.stderr and "onestroke inkscape install" in result.stderr


def test_inkscape_loads_the_extension_installed_for_the_user(tmp_path):
    # `onestroke inkscape install` without --dir asks `inkscape --user-data-directory`, which
    # follows INKSCAPE_PROFILE_DIR; Inkscape then loads every extension there at start-up and
    # logs those it refuses (a missing script, a parse error) in extension-errors.log or stderr.
    env = {**os.environ, "INKSCAPE_PROFILE_DIR": str(tmp_path / "profile")}
    installed = subprocess.run([sys.executable, "-m", "fabrication.cli", "inkscape", "install"], env=env,
                               capture_output=True, text=True)
    assert installed.returncode == 0, installed.stderr
    folder = tmp_path / "profile" / "extensions"
    assert f"installed in {folder}" in installed.stdout

    def refused() -> str:
        log = tmp_path / "profile" / "extension-errors.log"
        log.unlink(missing_ok=True)
        started = subprocess.run([INKSCAPE, "--action-list"], env=env, capture_output=True, text=True)
        assert started.returncode == 0
        text = started.stderr + (log.read_text() if log.exists() else "")
        return "\n".join(line for line in text.splitlines() if "onestroke" in line or "Single-line" in line)

    assert refused() == ""
    (folder / "onestroke_vectorize.py").unlink()  # the check can fail: Inkscape names what is missing
    assert "Single-line vectorize" in refused()


def test_dialog_offers_the_clis_ranges_and_choices():
    from fabrication.bridges.inkstitch import STITCHES
    from vectorize.options import BLUR

    inx = ET.parse(Path(fabrication.bridges.__file__).parent / "inkscape" / "onestroke_vectorize.inx").getroot()
    params = {p.get("name"): p for p in inx.iter("{http://www.inkscape.org/namespace/inkscape/extension}param")}
    assert float(params["blur"].get("max")) == BLUR.high and float(params["blur"].get("min")) == BLUR.low
    assert 0 < float(params["threshold"].get("max")) < 1
    options = {name: [o.get("value") for o in params[name]] for name in ("classifier", "inkstitch")}
    assert options == {"classifier": ["cnn", "geometric"], "inkstitch": ["none", *STITCHES]}
    script = (Path(fabrication.bridges.__file__).parent / "inkscape" / "onestroke_vectorize.py").read_text()
    assert all(f'"--{name}"' in script for name in params)

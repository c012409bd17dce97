"""A drawing binarized in a second thread while the caller imports the later stages
(`pipeline.binarize_beside`, what `onestroke vectorize` does on a spare core) gives the
drawing a plain run gives, byte for byte, at every threshold and blur and for an image
that is downscaled; the thread imports nothing; a refused image is refused alike."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import onestroke.cores
from onestroke.errors import InputError
from tests.children import child_env
from vectorize import VectorizeOptions, vectorize_file
from vectorize.pipeline import binarize_beside
from vectorize.svg_write import drawing_to_svg

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
# (threshold, blur): Li's threshold and a set one, without and with a blur.
SETTINGS = [(None, 0.0), (0.4, 0.0), (None, 1.5), (0.45, 0.75)]


@pytest.fixture
def spare_core(monkeypatch):
    """The machine has a core to spare, whatever its load while the tests run."""
    monkeypatch.setattr(onestroke.cores, "idle_cores", lambda: 2)


def _large(tmp_path: Path) -> Path:
    """loops.png (1000 x 600) enlarged to 2300 x 1380 px: downscaled by the default max_size."""
    path = tmp_path / "large.png"
    with Image.open(EXAMPLES / "loops.png") as image:
        image.convert("L").resize((2300, 1380), Image.Resampling.BILINEAR).save(path)
    return path


@pytest.mark.parametrize("name", ["loops.png", "touch-drawing.png", "hershey-HersheySans1-ampersand.png"])
def test_the_same_drawing_as_a_plain_run(name, spare_core):
    path = EXAMPLES / name
    for threshold, blur in SETTINGS:
        options = VectorizeOptions(threshold=threshold, blur=blur)
        binarizing = binarize_beside(path, options)
        assert binarizing is not None
        beside = vectorize_file(path, options, binarizing=binarizing)
        plain = vectorize_file(path, options)
        assert drawing_to_svg(beside.drawing) == drawing_to_svg(plain.drawing), (name, threshold, blur)
        assert beside.report.threshold == plain.report.threshold


def test_a_downscaled_image(tmp_path, spare_core):
    path = _large(tmp_path)
    options = VectorizeOptions()
    beside = vectorize_file(path, options, binarizing=binarize_beside(path, options))
    plain = vectorize_file(path, options)
    assert plain.report.scale < 0.5  # the case: the working image is downscaled
    assert drawing_to_svg(beside.drawing) == drawing_to_svg(plain.drawing)


def test_refused_alike(tmp_path, spare_core):
    """A blank page is refused with the same message, when the caller asks for the ink."""
    blank = tmp_path / "blank.png"
    Image.fromarray(np.full((200, 300), 255, dtype=np.uint8)).save(blank)
    with pytest.raises(InputError) as plain:
        vectorize_file(blank, VectorizeOptions())
    binarizing = binarize_beside(blank, VectorizeOptions())
    with pytest.raises(InputError) as beside:
        vectorize_file(blank, VectorizeOptions(), binarizing=binarizing)
    assert str(beside.value) == str(plain.value)
    # A file that is no image is refused as it is read, before any thread starts.
    junk = tmp_path / "junk.png"
    junk.write_bytes(b"not a png")
    with pytest.raises(InputError, match="not an image"):
        binarize_beside(junk, VectorizeOptions())


def test_not_where_it_gains_nothing(monkeypatch, tmp_path):
    options = VectorizeOptions()
    svg = tmp_path / "line.svg"
    svg.write_text('<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100">'
                   '<path d="M 10 10 C 30 80 70 80 90 10" fill="none" stroke="black"/></svg>')
    monkeypatch.setattr(onestroke.cores, "idle_cores", lambda: 2)
    assert binarize_beside(svg, options) is None  # an SVG's strokes are read, not binarized
    monkeypatch.setattr(onestroke.cores, "idle_cores", lambda: 1)
    assert binarize_beside(EXAMPLES / "loops.png", options) is None  # no core to spare
    monkeypatch.setattr(onestroke.cores, "idle_cores", lambda: 2)
    binarizing = binarize_beside(EXAMPLES / "loops.png", options)
    with pytest.raises(ValueError, match="other options"):
        vectorize_file(EXAMPLES / "loops.png", VectorizeOptions(threshold=0.4), binarizing=binarizing)


# A fresh process that does what the command does: the drawing read and binarized beside
# the later stages' imports. Lists the modules imported while the binarize thread ran
# them, and the thread the ink was made in.
CHILD = """
import json, sys, threading
import onestroke.cores
onestroke.cores.idle_cores = lambda: 2
seen, made_in = [], []
def hook(event, args):
    if event == "import" and threading.current_thread().name.startswith("binarize"):
        seen.append(args[0])
sys.addaudithook(hook)
from vectorize import VectorizeOptions, vectorize_file
from vectorize.pipeline import binarize_beside, import_stages_for
import vectorize.raster.binarize as binarize
ink_image = binarize.ink_image
def recorded(*args, **kwargs):
    made_in.append(threading.current_thread().name)
    return ink_image(*args, **kwargs)
binarize.ink_image = recorded
path, threshold, blur = sys.argv[1], json.loads(sys.argv[2]), float(sys.argv[3])
options = VectorizeOptions(threshold=threshold, blur=blur)
binarizing = binarize_beside(path, options)
import_stages_for(path, li_threshold=threshold is None)
strokes = len(vectorize_file(path, options, binarizing=binarizing).drawing.strokes)
print(json.dumps({"imports": seen, "made in": made_in, "strokes": strokes}))
"""


@pytest.mark.parametrize("threshold, blur", [(None, 0.0), (0.45, 0.75)])
def test_the_thread_imports_nothing(tmp_path, threshold, blur):
    for path in (EXAMPLES / "loops.png", _large(tmp_path)):
        done = subprocess.run([sys.executable, "-c", CHILD, str(path), json.dumps(threshold), str(blur)],
                              capture_output=True, text=True, env=child_env(), timeout=300, cwd=tmp_path)
        assert done.returncode == 0, done.stderr
        result = json.loads(done.stdout.strip().splitlines()[-1])
        assert result["made in"] and result["made in"][0].startswith("binarize")
        assert result["strokes"] == 1
        assert result["imports"] == []


# The command line in a fresh process with `cores` idle cores; prints the threads the ink was made in.
COMMAND = """
import sys, threading
import onestroke.cores
cores, argv = int(sys.argv[1]), sys.argv[2:]
onestroke.cores.idle_cores = lambda: cores
import vectorize.raster.binarize as binarize
ink_image, made_in = binarize.ink_image, []
def recorded(*args, **kwargs):
    made_in.append(threading.current_thread().name)
    return ink_image(*args, **kwargs)
binarize.ink_image = recorded
sys.argv = ["onestroke", *argv]
from fabrication.cli import main
try:
    main()
except SystemExit as done:
    print("made in", made_in, "exit", done.code)
"""


@pytest.mark.parametrize("command, suffix", [("vectorize", ".svg"), ("embroider", ".pes")])
def test_the_command_binarizes_on_a_spare_core(tmp_path, command, suffix):
    """`onestroke vectorize`, and the commands that read a drawing (`common.read_drawing`)."""
    outputs = {}
    for cores in (2, 1):
        out = tmp_path / f"{cores}{suffix}"
        done = subprocess.run([sys.executable, "-c", COMMAND, str(cores), command, str(EXAMPLES / "loops.png"),
                               "-o", str(out)], capture_output=True, text=True, env=child_env(), timeout=300,
                              cwd=tmp_path)
        assert done.returncode == 0, done.stderr
        made_in = done.stdout.strip().splitlines()[-1]
        assert ("'binarize" in made_in) == (cores == 2) and made_in.endswith("exit 0"), made_in
        outputs[cores] = out.read_bytes()
    assert outputs[2] == outputs[1]

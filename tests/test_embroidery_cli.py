"""`onestroke embroider` and `onestroke preview`: a table of invocations and exit codes.

Bad input gives exit code 2, a one-line `error:` message naming the value, no traceback
and no file written.
"""

from __future__ import annotations

import importlib.util
import json

import numpy as np
import pytest
from click.testing import CliRunner
from PIL import Image

from fabrication.cli import main
from fabrication.embroidery.plan import STITCH
from fabrication.embroidery.read import read_embroidery
from vectorize.drawing import Drawing
from vectorize.stroke import Stroke
from vectorize.svg_write import write_drawing

SVG = """<svg xmlns="http://www.w3.org/2000/svg" width="200" height="150" viewBox="0 0 200 150">
<path d="M 20 120 C 40 20, 80 20, 100 75 S 160 130, 180 30" fill="none" stroke="black" stroke-width="3"/>
<path d="M 30 140 L 170 140 L 100 100" fill="none" stroke="black" stroke-width="3"/>
</svg>
"""
GCODE = "G21\nG90\nM4 S0\nG0 X5 Y5\nG1 X30 Y5 S600 F1500\nG1 X30 Y30\nG1 X5 Y5\nM5\n"


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    folder = tmp_path_factory.mktemp("inputs")
    (folder / "d.svg").write_text(SVG)
    (folder / "j.gcode").write_text(GCODE)
    (folder / "garbage.pes").write_bytes(np.random.default_rng(4).integers(0, 256, 3000, dtype=np.uint8).tobytes())
    (folder / "empty.dst").write_bytes(b"")
    spiral = np.c_[np.cos(np.linspace(0, 12, 200)), np.sin(np.linspace(0, 12, 200))] * np.linspace(5, 40, 200)[:, None]
    write_drawing(Drawing((Stroke.from_polyline(spiral + 50),), 100, 100, "px"), folder / "d.json")
    return folder


def run(args, folder):
    result = CliRunner().invoke(main, [str(a).replace("{in}", str(folder)) for a in args])
    return result


OK = [
    (["embroider", "{in}/d.svg", "-o", "out.pes"], ["out.pes"]),
    (["embroider", "{in}/d.svg", "-o", "out.dst", "--style", "triple", "--repeats", "2"], ["out.dst"]),
    (["embroider", "{in}/d.svg", "-o", "out.jef", "--style", "zigzag", "--stitch-width", "3mm",
      "--spacing", "0.5mm", "--pull-comp", "0.3mm"], ["out.jef"]),
    (["embroider", "{in}/d.svg", "-o", "out.exp", "--style", "arrows", "--arrow-size", "2mm",
      "--spacing", "6mm"], ["out.exp"]),
    (["embroider", "{in}/d.svg", "-o", "out.vp3", "--color", "navy", "--preview", "out.png"], ["out.vp3", "out.png"]),
    (["embroider", "{in}/d.svg", "-o", "out.pes", "--preview", "out.svg", "--preview-width", "600"],
     ["out.pes", "out.svg"]),
    (["embroider", "{in}/d.svg", "-o", "big.pes", "--size", "120mm", "--hoop", "5x7"], ["big.pes"]),
    (["embroider", "{in}/d.svg", "-o", "fit.pes", "--size", "150mm", "--fit"], ["fit.pes"]),
    (["embroider", "{in}/d.svg", "-o", "custom.pes", "--size", "150mm", "--hoop", "160x120"], ["custom.pes"]),
    (["embroider", "{in}/d.svg", "-o", "w.pes", "--width", "60mm", "--rotate", "90"], ["w.pes"]),
    (["embroider", "{in}/d.svg", "-o", "v1.pes", "--pes-version", "1", "--lock", "back_forth"], ["v1.pes"]),
    (["embroider", "{in}/d.json", "-o", "json.dst", "--size", "50mm", "--min-stitch", "1mm",
      "--max-stitch", "5mm", "--spm", "800"], ["json.dst"]),
    (["preview", "{in}/j.gcode", "-o", "laser.png"], ["laser.png"]),
    (["preview", "{in}/d.svg", "-o", "drawing.png", "--width", "400"], ["drawing.png"]),
    (["preview", "{in}/d.json", "-o", "drawing.svg"], ["drawing.svg"]),
]

BAD = [
    (["embroider", "{in}/d.svg", "-o", "out.txt"], "'.txt'"),
    (["embroider", "{in}/d.svg", "-o", "out"], "no extension"),
    (["embroider", "{in}/d.svg", "-o", "out.pes", "--style", "cross"], "'cross'"),
    (["embroider", "{in}/d.svg", "-o", "out.pes", "--size", "0"], "'0'"),
    (["embroider", "{in}/d.svg", "-o", "out.pes", "--size", "-5mm"], "'-5mm'"),
    (["embroider", "{in}/d.svg", "-o", "out.pes", "--width", "0mm"], "'0mm'"),
    (["embroider", "{in}/d.svg", "-o", "out.pes", "--size", "150mm"], "hoop 100x100"),
    (["embroider", "{in}/d.svg", "-o", "out.pes", "--size", "120mm", "--hoop", "4x4"], "hoop 100x100"),
    (["embroider", "{in}/d.svg", "-o", "{in}/missing/out.pes"], "does not exist"),
    (["embroider", "{in}/d.svg", "-o", "out.pes", "--preview", "p.jpg"], "'.jpg'"),
    (["embroider", "{in}/nothing.svg", "-o", "out.pes"], "nothing.svg"),
    (["embroider", "{in}/d.svg", "-o", "out.pes", "--color", "blurple"], "'blurple'"),
    (["embroider", "{in}/d.svg", "-o", "out.pes", "--hoop", "potato"], "'potato'"),
    (["embroider", "{in}/d.svg", "-o", "out.pes", "--hoop", "0x100"], "hoop '0x100' is not a sewing field"),
    (["embroider", "{in}/d.svg", "-o", "out.pes", "--pes-version", "3"], "3"),
    (["embroider", "{in}/d.svg", "-o", "out.dst", "--pes-version", "1"], ".dst"),
    (["embroider", "{in}/d.svg", "-o", "out.pes", "--stitch-length", "0"], "'0'"),
    (["embroider", "{in}/d.svg", "-o", "out.pes", "--style", "zigzag", "--spacing", "-1mm"], "'-1mm'"),
    (["embroider", "{in}/d.svg", "-o", "out.pes", "--lock", "bowtie"], "'bowtie'"),
    (["embroider", "{in}/d.svg", "-o", "out.pes", "--min-stitch", "0"], "'0'"),
    (["embroider", "{in}/d.svg", "-o", "out.pes", "--spm", "0"], "--spm"),
    (["preview", "{in}/d.svg", "-o", "p.gif"], "'.gif'"),
    (["preview", "{in}/thing.xyz", "-o", "p.png"], "thing.xyz"),
    (["preview", "{in}/missing.pes", "-o", "p.png"], "missing.pes"),
    (["preview", "{in}/d.svg", "-o", "p.png", "--width", "5"], "width 5"),
    (["preview", "{in}/garbage.pes", "-o", "p.png"], "not a valid .pes file"),
    (["preview", "{in}/empty.dst", "-o", "p.png"], "holds no stitches"),
]


@pytest.mark.parametrize("args,made", OK, ids=[" ".join(a[:1] + a[3:]) for a, _ in OK])
def test_good_invocations(args, made, inputs, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    result = run(args, inputs)
    assert result.exit_code == 0, result.output
    assert "Traceback" not in result.output
    for name in made:
        assert (tmp_path / name).stat().st_size > 0
        if name.endswith(".png"):
            with Image.open(tmp_path / name) as image:
                assert image.width == (400 if "--width" in args else 1000) or name == "laser.png"
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(made)


@pytest.mark.parametrize("args,needle", BAD, ids=[" ".join(a[:1] + a[3:]) for a, _ in BAD])
def test_bad_invocations_exit_2_with_one_line_and_write_nothing(args, needle, inputs, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    before = sorted(p.name for p in inputs.iterdir())
    result = run(args, inputs)
    assert result.exit_code == 2, result.output
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: "), result.stderr
    assert needle in lines[0]
    assert "Traceback" not in result.output
    assert list(tmp_path.iterdir()) == []
    assert sorted(p.name for p in inputs.iterdir()) == before


def test_cli_outputs_are_byte_identical_and_sized(inputs, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    for name in ("a.pes", "b.pes"):
        assert run(["embroider", "{in}/d.svg", "-o", name, "--style", "zigzag"], inputs).exit_code == 0
    assert (tmp_path / "a.pes").read_bytes() == (tmp_path / "b.pes").read_bytes()
    plan = read_embroidery(tmp_path / "a.pes").plan
    needles = plan.points[plan.kinds == STITCH]
    width, height = np.ptp(needles, axis=0)
    assert max(width, height) == pytest.approx(90 + 2.2, abs=0.3)  # 90 mm curve + zigzag reach
    result = run(["embroider", "{in}/d.svg", "-o", "w.dst", "--width", "60mm"], inputs)
    assert "60.0 x" in result.stdout
    plan = read_embroidery(tmp_path / "w.dst").plan
    assert np.ptp(plan.points[plan.kinds == STITCH][:, 0]) == pytest.approx(60, abs=0.2)


def test_preview_command_on_embroidery_files(inputs, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    for ext in ("pes", "dst", "jef", "exp", "vp3"):
        assert run(["embroider", "{in}/d.svg", "-o", f"d.{ext}"], inputs).exit_code == 0
        result = run(["preview", f"d.{ext}", "-o", f"p_{ext}.png", "--hoop", "4x4", "--width", "500"], inputs)
        assert result.exit_code == 0, result.output
        assert "stitches" in result.stdout
        with Image.open(tmp_path / f"p_{ext}.png") as image:
            assert image.size == (500, 500)


def test_unused_options_are_warned_about(inputs, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    result = run(["embroider", "{in}/d.svg", "-o", "o.pes", "--repeats", "2"], inputs)
    assert result.exit_code == 0 and "--repeats has no effect with --style running" in result.stderr
    result = run(["embroider", "{in}/d.svg", "-o", "z.pes", "--style", "zigzag", "--stitch-width", "0.6mm"], inputs)
    assert result.exit_code == 0 and "hardly shows" in result.stderr
    # --width is the design's width; a tiny one next to --style zigzag gets a hint.
    result = run(["embroider", "{in}/d.svg", "-o", "w.pes", "--style", "zigzag", "--width", "3mm"], inputs)
    assert result.exit_code == 0 and "the zigzag's own width is --stitch-width" in result.stderr
    result = run(["embroider", "{in}/d.svg", "-o", "w.pes", "--style", "zigzag", "--width", "60mm"], inputs)
    assert result.exit_code == 0 and "--stitch-width" not in result.stderr


def _png_input(folder):
    from conftest import alpha_loop, render_polylines

    path = folder / "loop.png"
    Image.fromarray(render_polylines([alpha_loop()])).save(path)
    return path


@pytest.mark.parametrize("classifier", ["geometric", "cnn"])
def test_png_end_to_end(classifier, tmp_path, monkeypatch):
    if classifier == "cnn":
        if importlib.util.find_spec("vectorize.junctions.cnn_classifier") is None:
            pytest.skip("the CNN crossing classifier is not in the package yet")
        from vectorize.junctions.cnn_classifier import DEFAULT_MODEL

        if not DEFAULT_MODEL.is_file():
            pytest.skip("the trained crossing model is not shipped yet")
    monkeypatch.chdir(tmp_path)
    png = _png_input(tmp_path)
    result = CliRunner().invoke(main, ["embroider", str(png), "-o", "loop.pes", "--style", "zigzag",
                                       "--classifier", classifier, "--preview", "loop_preview.png"])
    assert result.exit_code == 0, result.output
    plan = read_embroidery(tmp_path / "loop.pes").plan
    assert (plan.kinds == STITCH).sum() > 300
    assert len([k for k in plan.kinds if k != STITCH]) <= 2  # one curve: no trims in between
    with Image.open(tmp_path / "loop_preview.png") as image:
        assert image.size[0] == 1000  # realistic: framed to the design, not the hoop


def test_bundled_example_png_end_to_end(tmp_path, monkeypatch):
    from pathlib import Path

    example = Path(__file__).parents[1] / "examples" / "hershey-HersheySans1-ampersand.png"
    if not example.is_file():
        pytest.skip("examples/ has no ampersand drawing")
    from vectorize.junctions.cnn_classifier import DEFAULT_MODEL

    if not DEFAULT_MODEL.is_file():
        pytest.skip("the trained crossing model is not shipped yet")
    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(main, ["embroider", str(example), "-o", "amp.dst", "--style", "arrows",
                                       "--preview", "amp.png"])
    assert result.exit_code == 0, result.output
    plan = read_embroidery(tmp_path / "amp.dst").plan
    first = int(np.argmax(plan.kinds == STITCH))
    assert (plan.kinds[first:] == STITCH).all()  # one curve: sewn without a single jump or trim
    assert (plan.kinds == STITCH).sum() > 300
    with Image.open(tmp_path / "amp.png") as image:
        assert image.size[0] == 1000

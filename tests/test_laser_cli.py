"""`onestroke laser`: a table of invocations with exit codes; bad input writes nothing."""

from __future__ import annotations

import importlib.util

import pytest
from click.testing import CliRunner

from fabrication.cli import main
from laser_fixtures import grbl_refusals, parse_gcode
from benchmarks.sets.laser_jobs import rose_drawing, trefoil_png
from vectorize.svg_write import write_drawing


@pytest.fixture(scope="module")
def svg(tmp_path_factory):
    path = tmp_path_factory.mktemp("in") / "rose.svg"
    write_drawing(rose_drawing(), str(path))
    return path


def run(*args):
    return CliRunner().invoke(main, ["laser", *map(str, args)], catch_exceptions=False)


def test_writes_gcode_frame_and_preview(svg, tmp_path):
    out = tmp_path / "job.gcode"
    result = run(svg, "-o", out, "--size", "50mm", "--feed", "2000mm/min", "--power", "40%", "--passes", "2",
                 "--frame", "--preview", tmp_path / "p.png", "--arcs")
    assert result.exit_code == 0, result.output
    lines = out.read_text().splitlines()
    assert grbl_refusals(lines) == []
    assert any("estimated time" in line for line in lines[:6])
    assert "S400F2000" in out.read_text()
    frame = tmp_path / "job.frame.gcode"
    assert frame.exists() and grbl_refusals(frame.read_text().splitlines()) == []
    assert (tmp_path / "p.png").stat().st_size > 1000
    assert "estimated" in result.stdout
    moves = parse_gcode(lines)
    burn = moves.end[moves.laser_on]
    assert burn.max(axis=0).max() == pytest.approx(50.0, abs=0.02)


def test_long_unicode_file_name_keeps_lines_valid(svg, tmp_path):
    source = tmp_path / ("ünïcödé drawing " * 8 + ".svg")
    source.write_bytes(svg.read_bytes())
    out = tmp_path / "job.gcode"
    assert run(source, "-o", out, "--size", "20mm").exit_code == 0
    text = out.read_text(encoding="ascii")
    assert grbl_refusals(text.splitlines()) == []


def test_profile_and_center_origin(svg, tmp_path):
    profile = tmp_path / "small.toml"
    profile.write_text('name = "small"\n[bed]\nsize = "100x80mm"\n[laser]\nmax_power = 255\n')
    out = tmp_path / "job.gcode"
    result = run(svg, "-o", out, "--size", "40mm", "--profile", profile, "--origin", "center", "--power", "100%")
    assert result.exit_code == 0, result.output
    moves = parse_gcode(out.read_text().splitlines())
    burn = moves.end[moves.laser_on]
    centre = (burn.min(axis=0) + burn.max(axis=0)) / 2
    assert centre == pytest.approx([50.0, 40.0], abs=0.05)
    assert set(moves.power[moves.laser_on]) == {255.0}


BAD = [
    (["--size", "500mm"], "does not fit the bed"),
    (["--power", "150%"], "--power"),
    (["--power", "0%"], "--power"),
    (["--feed", "0"], "--feed"),
    (["--feed", "-100mm/min"], "--feed"),
    (["--feed", "fast"], "--feed"),
    (["--passes", "0"], "--passes"),
    (["--size", "-3mm"], "--size"),
    (["--tolerance", "0.001mm"], "tolerance"),
    (["--profile", "/nonexistent/p.toml"], "does not exist"),
    (["--raster-interval", "0.001mm"], "raster interval"),
    (["--raster-feed", "0"], "--raster-feed"),
]


@pytest.mark.parametrize("extra,message", BAD)
def test_bad_options_exit_2_and_write_nothing(svg, tmp_path, extra, message):
    out = tmp_path / "job.gcode"
    result = run(svg, "-o", out, "--preview", tmp_path / "p.png", "--frame", *extra)
    assert result.exit_code == 2
    assert message in result.stderr and result.stderr.startswith("error:")
    assert len(result.stderr.strip().splitlines()) == 1 and "Traceback" not in result.output
    assert list(tmp_path.iterdir()) == []


def test_bad_inputs_and_outputs(svg, tmp_path):
    garbage = tmp_path / "broken.png"
    garbage.write_bytes(b"not an image at all")
    broken_profile = tmp_path / "broken.toml"
    broken_profile.write_text("[motion]\nacceleration_x = 'fast'\n")
    cases = [
        ([tmp_path / "missing.svg", "-o", tmp_path / "a.gcode"], "does not exist"),
        ([garbage, "-o", tmp_path / "a.gcode"], "broken.png"),
        ([tmp_path, "-o", tmp_path / "a.gcode"], "directory"),
        ([svg, "-o", tmp_path / "no" / "such" / "a.gcode"], "does not exist"),
        ([svg, "-o", tmp_path / "a.png"], ".gcode"),
        ([svg, "-o", tmp_path / "a.gcode", "--preview", tmp_path / "p.jpg"], "preview"),
        ([svg, "-o", tmp_path / "a.gcode", "--profile", broken_profile], "acceleration"),
        ([svg, "-o", tmp_path / "a.gcode", "--preview", tmp_path / "a.gcode.svg", "--frame"], None),
        ([svg, "-o", tmp_path / "b.gcode", "--preview", svg], "same file as the input"),
    ]
    for args, message in cases:
        result = run(*args)
        if message is None:  # a valid run in the middle of the table: clean up after it
            assert result.exit_code == 0, result.output
            for made in ("a.gcode", "a.gcode.svg", "a.frame.gcode"):
                (tmp_path / made).unlink()
            continue
        assert result.exit_code == 2, (args, result.output)
        assert message in result.stderr, (args, result.stderr)
        assert len(result.stderr.strip().splitlines()) == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["broken.png", "broken.toml"]


def test_unwritable_output_folder(svg, tmp_path):
    """Refused before any work, as root too (an immutable folder; chmod for other users)."""
    from fault_fixtures import locked_folder

    with locked_folder(tmp_path / "locked") as locked:
        result = run(svg, "-o", locked / "a.gcode")
        assert result.exit_code == 2 and f"folder {str(locked)!r} " in result.stderr, result.stderr
        assert ("not writable" in result.stderr) or ("immutable" in result.stderr)
        assert list(locked.iterdir()) == []


def test_failed_run_keeps_a_good_file(svg, tmp_path):
    out = tmp_path / "job.gcode"
    assert run(svg, "-o", out, "--size", "30mm").exit_code == 0
    before = out.read_bytes()
    assert run(svg, "-o", out, "--size", "900mm").exit_code == 2
    assert out.read_bytes() == before


@pytest.mark.parametrize("classifier", ["geometric", "cnn"])
def test_png_end_to_end(tmp_path, classifier):
    if classifier == "cnn" and importlib.util.find_spec("vectorize.junctions.cnn_classifier") is None:
        pytest.skip("the CNN crossing classifier is not in the tree yet")
    png = trefoil_png(tmp_path / "trefoil.png")
    out = tmp_path / "trefoil.gcode"
    result = run(png, "-o", out, "--size", "60mm", "--classifier", classifier,
                 "--preview", tmp_path / "trefoil.preview.svg")
    assert result.exit_code == 0, result.output
    lines = out.read_text().splitlines()
    assert grbl_refusals(lines) == []
    moves = parse_gcode(lines)
    # one single-line drawing: one G0 to its start, then one continuous burn
    assert int((moves.kind == 0).sum()) == 1
    burn = moves.end[moves.laser_on]
    assert max(burn.max(axis=0) - burn.min(axis=0)) == pytest.approx(60.0, abs=0.05)


def test_preview_command_reads_laser_gcode(svg, tmp_path):
    out = tmp_path / "job.gcode"
    assert run(svg, "-o", out, "--size", "30mm").exit_code == 0
    result = CliRunner().invoke(main, ["preview", str(out), "-o", str(tmp_path / "p.png")])
    if result.exit_code != 0 and "No such command" in result.output:
        pytest.skip("the preview command is not registered")
    assert result.exit_code == 0, result.output
    assert (tmp_path / "p.png").stat().st_size > 1000


def test_port_streams_the_written_job_to_the_emulator(svg, tmp_path):
    pytest.importorskip("fabrication.cli.stream_cmd")
    out = tmp_path / "job.gcode"
    result = run(svg, "-o", out, "--size", "15mm", "--port", "sim://?speed=50")
    assert result.exit_code == 0, result.output
    # the estimate is printed before the run starts, the stream summary after it
    text = result.output
    assert text.index("estimated") < text.index("streamed")
    assert "beam off" in text

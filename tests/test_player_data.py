"""The player page: self-contained, and its data is the source file's truth (stitch count,
colours, trims, total time equal to the stats / the GRBL planner estimate)."""

from __future__ import annotations

import re

import numpy as np
import pyembroidery
import pytest
from click.testing import CliRunner

from benchmarks.sets.embroidery_designs import design
from fabrication.cli import main
from fabrication.embroidery.plan import PlanOptions, plan_embroidery, style_options
from fabrication.embroidery.read import read_embroidery
from fabrication.embroidery.stats import embroidery_stats
from machines.job_time import estimate_job_time as estimate_gcode_time
from machines.job_time import read_moves
from fabrication.player import player_html, stitch_player_data, write_player_html
from fabrication.player.data import COLOR, DOWN, DRAW, TRAVEL, TRIM
from machines.laser_profile import load_laser_profile
from onestroke.errors import InputError
from player_fixtures import BLUE, RED, page_data, write_pattern
from vectorize.svg_write import drawing_from_json, drawing_to_json

ROSE = "tests/golden/laser_rose_arcs.gcode"


def _preview(*args):
    return CliRunner().invoke(main, ["preview", *map(str, args)])


def assert_self_contained(html: str) -> None:
    assert "http://" not in html and "https://" not in html
    assert not re.search(r"""\s(src|href)\s*=""", html, re.I), "the page loads something external"
    assert "<script type=\"module\">" in html and "createPlayer" in html
    assert "@import" not in html and "url(" not in html


@pytest.mark.parametrize("ext", ["pes", "dst", "jef", "exp", "vp3"])
def test_embroidery_page_matches_the_file(tmp_path, ext):
    source = tmp_path / f"two.{ext}"
    write_pattern(source)
    out = tmp_path / "two.html"
    result = _preview(source, "-o", out, "--spm", 750)
    assert result.exit_code == 0, result.output
    html = out.read_text(encoding="utf-8")
    assert_self_contained(html)
    data = page_data(html)

    pattern = pyembroidery.read(str(source))
    commands = np.array([s[2] for s in pattern.stitches]) & pyembroidery.COMMAND_MASK
    read = read_embroidery(source)
    stats = embroidery_stats(read.plan, stitches_per_minute=750, trim_seconds=10.0,
                             color_changes=read.color_changes)
    kinds = data["kind"]
    assert data["n"] == len(read.plan)
    # every needle point of the file, numbered 1..S
    assert int(np.isin(kinds, (DRAW, DOWN)).sum()) == (commands == pyembroidery.STITCH).sum() == 120
    assert data["numberTotal"] == stats.stitches == data["num"][-1] == 120
    assert int((kinds == COLOR).sum()) == read.color_changes == 1
    assert int(np.isin(kinds, (TRIM, COLOR)).sum()) == stats.trims
    assert data["total"] == stats.seconds and data["t"][-1] == stats.seconds
    assert np.all(np.diff(data["t"]) >= 0)
    np.testing.assert_allclose(np.c_[data["x"], data["y"]], read.plan.points, atol=1e-4)
    # the colours: red before the change, blue after (PES v1 and JEF map to their palette)
    first, last = data["palette"][data["color"][0]], data["palette"][data["color"][-1]]
    change = int(np.flatnonzero(kinds == COLOR)[0])
    assert set(data["color"][:change]) == {data["color"][0]} and set(data["color"][change:]) == {data["color"][-1]}
    assert first != last
    threads = ["#%02x%02x%02x" % (t.get_red(), t.get_green(), t.get_blue()) for t in pattern.threadlist]
    if threads:  # the threads the file names (DST and EXP name none: filler colours)
        assert data["palette"] == threads[:len(data["palette"])]
    if ext in ("vp3",):  # RGB kept exactly
        assert (first, last) == ("#%02x%02x%02x" % RED, "#%02x%02x%02x" % BLUE)


def test_stitch_plan_from_the_pipeline(tmp_path):
    """The studio path: a plan straight from the embroidery pipeline, in its thread colour."""
    plan = plan_embroidery(design(), PlanOptions(style=style_options("running"), color=(200, 30, 40)))
    stats = embroidery_stats(plan, stitches_per_minute=600, trim_seconds=8)
    data = stitch_player_data(plan, stitches_per_minute=600, trim_seconds=8)
    assert data.palette == ("#c81e28",)
    assert data.number_total == stats.stitches and data.times[-1] == data.total == stats.seconds
    assert int((data.kinds == TRIM).sum()) == stats.trims > 0
    assert int((data.kinds == DRAW).sum()) == len(plan.stitches()[0])  # sewn stitches are lines


def test_two_colour_plan_from_the_pipeline():
    """A plan with its own colour blocks (COLOR rows): colours, changes and time as the stats say."""
    plan = plan_embroidery(design(), PlanOptions(style=style_options("running"), colors=(RED, BLUE)))
    stats = embroidery_stats(plan, stitches_per_minute=700, trim_seconds=12)
    data = stitch_player_data(plan, stitches_per_minute=700, trim_seconds=12)
    assert data.palette == ("#%02x%02x%02x" % RED, "#%02x%02x%02x" % BLUE)
    np.testing.assert_array_equal(data.colors, plan.blocks)
    assert int((data.kinds == COLOR).sum()) == plan.color_changes == stats.color_changes == 1
    assert int((data.kinds == TRIM).sum()) == stats.trims
    assert data.times[-1] == data.total == stats.seconds
    assert data.number_total == stats.stitches


def test_gcode_page_matches_the_estimate(tmp_path):
    out = tmp_path / "rose.html"
    result = _preview(ROSE, "-o", out)
    assert result.exit_code == 0, result.output
    html = out.read_text(encoding="utf-8")
    assert_self_contained(html)
    data = page_data(html)
    profile = load_laser_profile()
    lines = open(ROSE, encoding="utf-8").read().splitlines()
    job = estimate_gcode_time(lines, profile)
    moves = read_moves(lines, profile)[0]
    assert data["total"] == job.total_seconds
    assert data["t"][-1] == pytest.approx(job.total_seconds, rel=1e-12)
    assert np.all(np.diff(data["t"]) >= 0) and data["yUp"]
    assert data["numberTotal"] == len(job.line_seconds) == len(lines)
    # each move ends at its line's planner time, on its end point
    end_rows = np.r_[np.flatnonzero(np.diff(data["num"].astype(int)) != 0), len(data["num"]) - 1]
    last_move = {int(line): k for k, line in enumerate(moves.line)}
    for row in end_rows[1:]:
        line = int(data["num"][row]) - 1
        assert data["t"][row] == pytest.approx(job.line_seconds[line], abs=1e-9)
        np.testing.assert_allclose([data["x"][row], data["y"][row]], moves.end[last_move[line]], atol=1e-4)
    burn_lines = set((moves.line[moves.laser_on] + 1).tolist())
    assert set(data["num"][data["kind"] == DRAW].tolist()) == burn_lines
    assert (data["kind"] == TRAVEL).any() and (data["kind"] == DRAW).sum() > len(burn_lines)  # arcs in chords


def test_drawing_page(tmp_path):
    source = tmp_path / "design.json"
    source.write_text(drawing_to_json(design()), encoding="utf-8")
    drawing = drawing_from_json(source.read_text(encoding="utf-8"))
    out = tmp_path / "design.html"
    result = _preview(source, "-o", out)
    assert result.exit_code == 0, result.output
    data = page_data(out.read_text(encoding="utf-8"))
    assert data["source"] == "drawing" and data["numberTotal"] == len(drawing.strokes) == 4
    assert data["total"] == pytest.approx(drawing.length, rel=1e-9)
    assert int((data["kind"] == TRAVEL).sum()) == 4  # pen up to each stroke's start
    assert len(set(data["color"].tolist())) > 10  # coloured start to end


def test_refuses_to_overwrite_its_input_and_bad_inputs(tmp_path):
    source = tmp_path / "two.html"
    source.write_text("<p>not a drawing</p>", encoding="utf-8")
    result = _preview(source, "-o", source)
    assert result.exit_code == 2 and "cannot play" in result.output
    pes = tmp_path / "two.pes"
    write_pattern(pes)
    with pytest.raises(InputError, match="is the same file as the input"):
        from fabrication.player import player_data_for_file

        write_player_html(player_data_for_file(pes), pes.with_suffix(".html"), source=pes.with_suffix(".html"))
    missing = _preview(tmp_path / "nope.pes", "-o", tmp_path / "x.html")
    assert missing.exit_code == 2 and "does not exist" in missing.output and "Traceback" not in missing.output
    bad = tmp_path / "bad.gcode"
    bad.write_text("(nothing)\n", encoding="utf-8")
    empty = _preview(bad, "-o", tmp_path / "bad.html")
    assert empty.exit_code == 2 and not (tmp_path / "bad.html").exists()


def test_script_cannot_end_early():
    """A title with '</script>' stays inside the JSON (the page would break otherwise)."""
    plan = plan_embroidery(design(), PlanOptions(style=style_options("running")))
    html = player_html(stitch_player_data(plan, title="</script><script>alert(1)</script>"))
    assert html.count("</script>") == 2


def test_raster_drawing_is_vectorized_then_played(tmp_path):
    """A .png is vectorized with the defaults: one stroke for loops.png, played along its length."""
    from vectorize import VectorizeOptions, vectorize_file

    out = tmp_path / "loops.html"
    result = _preview("examples/loops.png", "-o", out)
    assert result.exit_code == 0, result.output
    data = page_data(out.read_text(encoding="utf-8"))
    drawing = vectorize_file("examples/loops.png", VectorizeOptions()).drawing
    assert data["source"] == "drawing" and data["unit"] == "px"
    assert data["numberTotal"] == len(drawing.strokes) == 1
    assert data["total"] == pytest.approx(drawing.length, rel=1e-12)


def test_gcode_dwell_is_a_pause_and_hoop_is_the_frame(tmp_path):
    from fabrication.player import gcode_player_data

    lines = ["G21 G90", "M4 S500", "G1 X10 Y0 F600", "G4 P2", "G1 X20", "M5", "G0 X0 Y0"]
    profile = load_laser_profile()
    data = gcode_player_data(lines, profile=profile)
    job = estimate_gcode_time(lines, profile)
    assert data.total == job.total_seconds and data.times[-1] == pytest.approx(job.total_seconds)
    np.testing.assert_array_equal(data.numbers, [3, 3, 5, 7])  # start, X10, X20, back home
    np.testing.assert_array_equal(data.kinds, [TRAVEL, DRAW, DRAW, TRAVEL])
    # 10 mm at 600 mm/min is at least 1 s; the G4 P2 adds 2 s before the second burn starts
    assert data.times[1] >= 1.0 and data.times[2] - data.times[1] >= 2.0 + 1.0

    source = tmp_path / "two.pes"
    write_pattern(source)
    out = tmp_path / "two.html"
    assert _preview(source, "-o", out, "--hoop", "100x100").exit_code == 0
    assert page_data(out.read_text(encoding="utf-8"))["frame"] == [-50.0, -50.0, 50.0, 50.0]


def test_a_laser_programs_player_data_reuses_its_reading(tmp_path):
    """The studio's laser preview plays the program from the reading its time estimate
    made: the same data as reading the G-code lines again (line numbers past the header
    comments, times, colours), and the estimate is that of the file as written."""
    from fabrication.job_options import laser_settings
    from fabrication.laser.program import laser_program
    from fabrication.player import gcode_player_data, laser_program_player_data
    from vectorize.drawing import Drawing
    from vectorize.stroke import Stroke

    t = np.linspace(0.0, 2.0 * np.pi, 200)
    loop = Stroke.from_polyline(np.c_[100 + 60 * np.cos(t), 100 + 40 * np.sin(3 * t)])
    line = Stroke.from_polyline(np.array([[20.0, 20.0], [180.0, 30.0]]))
    drawing = Drawing((loop, line), 200.0, 200.0, "px", 4.0)
    for arcs in (False, True):
        settings = laser_settings(size="60mm", arcs=arcs)
        program = laser_program(drawing, settings.profile, settings.toolpath, settings.gcode, name="loops.png")
        again = gcode_player_data(program.lines, title="t", profile=settings.profile).to_dict()
        reused = laser_program_player_data(program, title="t", profile=settings.profile).to_dict()
        assert again.keys() == reused.keys()
        for key in again:
            assert np.array_equal(np.asarray(again[key]), np.asarray(reused[key])), key
        assert program.time.total_seconds == estimate_gcode_time(list(program.lines), settings.profile).total_seconds

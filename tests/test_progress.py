"""Long work reports its progress, and large inputs take bounded work (issue 14, item 6).

The library calls a progress callback with `onestroke.progress.Progress` reports; within a
stage they never go back and the stage ends at 100 %, with a bounded number of reports.
Work on large inputs is bounded by counting calls (draw calls, svgelements' exact bbox),
not by timing.
"""

from __future__ import annotations

import numpy as np
import pytest
import svgelements as se
from PIL import ImageDraw

from benchmarks.large_inputs import long_path_svg, many_paths_svg
from onestroke.progress import REPORTS_PER_STAGE, Progress, Stage, counted

PATHS = 400


@pytest.fixture(scope="module")
def many(tmp_path_factory):
    path = tmp_path_factory.mktemp("progress") / "many.svg"
    path.write_text(many_paths_svg(PATHS), encoding="utf-8")
    return path


def check_stages(reports: list[Progress]) -> dict[str, Progress]:
    """Each stage: done never goes back, at most REPORTS_PER_STAGE + 2 reports, ends at
    done == total. The last report of each stage, by name."""
    assert reports and all(isinstance(r, Progress) for r in reports)
    stages: dict[str, list[Progress]] = {}
    for report in reports:
        stages.setdefault(report.stage, []).append(report)
    for name, seen in stages.items():
        done = [r.done for r in seen]
        assert done == sorted(done), (name, done)
        assert len(seen) <= REPORTS_PER_STAGE + 2, (name, len(seen))
        assert seen[-1].done == seen[-1].total and seen[-1].fraction == 1.0, (name, seen[-1])
    return {name: seen[-1] for name, seen in stages.items()}


def test_stage_counts_up_to_total_in_a_bounded_number_of_reports():
    reports: list[Progress] = []
    stage = Stage(reports.append, "work", 100_000, "items")
    for _ in range(100_000):
        stage.advance()
    stage.finish()
    last = check_stages(reports)["work"]
    assert (last.done, last.total, last.unit) == (100_000, 100_000, "items")
    assert [r.done for r in reports][:3] == [0, 1000, 2000]
    assert list(counted(range(5), None, "x", 5)) == [0, 1, 2, 3, 4]  # no callback: the items, nothing else
    reports.clear()
    assert list(counted(range(3), reports.append, "x", 3)) == [0, 1, 2]
    assert [r.done for r in reports] == [0, 1, 2, 3]


def test_reading_a_large_svg_reports_bytes_then_shapes(many):
    from vectorize.svg.svg_read import read_svg

    reports: list[Progress] = []
    content = read_svg(many, progress=reports.append)
    last = check_stages(reports)
    assert list(last) == ["reading XML", "parsing", "reading shapes"]
    for stage in ("reading XML", "parsing"):
        assert last[stage].total == many.stat().st_size and last[stage].unit == "bytes"
    assert last["reading shapes"].total >= PATHS
    assert len(content.strokes) == PATHS
    quiet = read_svg(many)  # the same strokes without a callback
    assert all(np.array_equal(a.control, b.control) for a, b in zip(quiet.strokes, content.strokes))


def test_embroidery_plan_reports_every_stroke(many):
    from fabrication.embroidery.pipeline import EmbroideryJob, embroider
    from fabrication.placement import PlacementOptions
    from machines.hoops import load_embroidery_profile
    from vectorize.svg.svg_read import read_svg

    drawing = read_svg(many).as_drawing()
    job = EmbroideryJob(placement=PlacementOptions(size=180.0), hoop=load_embroidery_profile().hoop("200x200"))
    reports: list[Progress] = []
    with_progress = embroider(drawing, job, progress=reports.append)
    last = check_stages(reports)
    assert last["stitching"].total == PATHS and last["stitching"].unit == "strokes"
    assert np.array_equal(with_progress.plan.points, embroider(drawing, job).plan.points)


def test_laser_program_reports_planning_writing_and_estimate(many):
    from fabrication.job_options import laser_settings
    from fabrication.laser.program import laser_program
    from vectorize.svg.svg_read import read_svg

    drawing = read_svg(many).as_drawing()
    settings = laser_settings(size="180mm")
    reports: list[Progress] = []
    program = laser_program(drawing, settings.profile, settings.toolpath, settings.gcode, name="many.svg",
                            progress=reports.append)
    last = check_stages(reports)
    assert list(last) == ["flattening", "ordering strokes", "writing G-code", "reading G-code"]
    assert last["flattening"].total == PATHS
    assert last["reading G-code"].total >= len(program.lines) - 10  # the header comments come after
    quiet = laser_program(drawing, settings.profile, settings.toolpath, settings.gcode, name="many.svg")
    assert quiet.lines == program.lines


def test_svg_paths_are_read_without_svgelements_exact_bbox(many, monkeypatch):
    """The exact bbox of svgelements cost more than reading the path: a path's control
    points bound it and are checked instead. Circles and other shapes still use it."""
    from vectorize.svg.svg_read import read_svg

    calls = []
    original = se.Shape.bbox
    monkeypatch.setattr(se.Shape, "bbox", lambda self, *a, **k: calls.append(self) or original(self, *a, **k))
    read_svg(many)
    assert calls == []


def _count_draw_calls(monkeypatch) -> list:
    calls: list = []
    original = ImageDraw.ImageDraw.line
    monkeypatch.setattr(ImageDraw.ImageDraw, "line", lambda self, *a, **k: calls.append(1) or original(self, *a, **k))
    return calls


def test_stitch_preview_draws_a_chain_of_stitches_in_one_call(tmp_path, monkeypatch):
    """One long path: thousands of stitches, one call per change of colour (was one per stitch)."""
    from fabrication.embroidery.pipeline import EmbroideryJob, embroider
    from fabrication.embroidery.preview import PreviewOptions, render_stitch_preview
    from fabrication.placement import PlacementOptions
    from machines.hoops import load_embroidery_profile
    from vectorize.svg.svg_read import read_svg

    (tmp_path / "long.svg").write_text(long_path_svg(2000), encoding="utf-8")
    drawing = read_svg(tmp_path / "long.svg").as_drawing()
    job = EmbroideryJob(placement=PlacementOptions(size=180.0), hoop=load_embroidery_profile().hoop("200x200"))
    plan = embroider(drawing, job).plan
    assert len(plan) > 500
    calls = _count_draw_calls(monkeypatch)
    # the diagnostic view (`onestroke preview`) colours stitches along the order: one call
    # per change of colour
    render_stitch_preview(plan, tmp_path / "b.png", options=PreviewOptions(width=400, style="diagnostic"))
    assert 0 < len(calls) < len(plan) / 2, (len(calls), len(plan))


def test_laser_preview_draws_runs_of_one_colour_in_one_call(tmp_path, monkeypatch):
    from fabrication.job_options import laser_settings
    from fabrication.laser.gcode_write import write_gcode
    from fabrication.laser.preview import render_gcode_preview
    from fabrication.laser.program import laser_program
    from vectorize.svg.svg_read import read_svg

    (tmp_path / "long.svg").write_text(long_path_svg(2000), encoding="utf-8")
    drawing = read_svg(tmp_path / "long.svg").as_drawing()
    settings = laser_settings(size="180mm")
    program = laser_program(drawing, settings.profile, settings.toolpath, settings.gcode, name="long.svg")
    write_gcode(tmp_path / "long.gcode", list(program.lines))
    assert program.toolpath.segment_count > 2000
    calls = _count_draw_calls(monkeypatch)
    render_gcode_preview(tmp_path / "long.gcode", tmp_path / "a.png")
    # a colour ramp of about 1,000 steps plus the frame, the bar and the marks; was one per move
    assert len(calls) < 1500, len(calls)

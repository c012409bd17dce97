"""Golden G-code: the exact bytes for two small jobs. Regenerate after an intended change with
`ONESTROKE_REGENERATE_GOLDEN=1 python -m pytest tests/test_laser_golden.py` and review the diff."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from fabrication.laser.gcode_write import GcodeOptions, gcode_lines, gcode_text
from fabrication.laser.toolpath import ToolpathOptions, plan_toolpath
from fabrication.placement import PlacementOptions
from benchmarks.sets.laser_jobs import hershey_text_drawing, rose_drawing
from machines.laser_profile import load_laser_profile

GOLDEN = Path(__file__).with_name("golden")
REGENERATE = os.environ.get("ONESTROKE_REGENERATE_GOLDEN") == "1"

JOBS = {
    "laser_rose_arcs.gcode": (rose_drawing, dict(arcs=True, tolerance=0.05), dict(passes=2, return_home=True)),
    "laser_text_lines.gcode": (lambda: hershey_text_drawing("on"), dict(origin="center"),
                               dict(feed=2400.0, power=0.35, air_assist=True)),
}


@pytest.mark.parametrize("name", sorted(JOBS))
def test_golden_gcode(name):
    make, toolpath_kw, gcode_kw = JOBS[name]
    profile = load_laser_profile()
    tp = plan_toolpath(make(), profile, ToolpathOptions(placement=PlacementOptions(size=40), **toolpath_kw))
    text = gcode_text(gcode_lines(tp, profile, GcodeOptions(**gcode_kw), comments=(f"golden {name}",)))
    path = GOLDEN / name
    if REGENERATE:
        path.write_text(text, encoding="ascii", newline="\n")
    assert path.exists(), f"run with ONESTROKE_REGENERATE_GOLDEN=1 to create {path}"
    assert text == path.read_text(encoding="ascii"), f"{name} changed; regenerate if intended"

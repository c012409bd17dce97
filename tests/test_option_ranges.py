"""Issue 25: every option's range is declared once, with its option type (`onestroke.ranges`),
and every way in (the option type itself, the command line, `job_options` as batch and the
studio call it, edits files) refuses the same value with the same line. The docs' table is
the declarations' own, and the README's examples are checked against them."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest
from click.testing import CliRunner

from fabrication.cli import main
from fabrication.cli.range_table import BEGIN, END, markdown, ranged_options
from fabrication.embroidery.arrows import ArrowOptions
from fabrication.embroidery.locks import LockOptions
from fabrication.embroidery.pipeline import EmbroideryJob
from fabrication.embroidery.plan import PlanOptions
from fabrication.embroidery.preview import PreviewOptions
from fabrication.embroidery.running import RunningOptions
from fabrication.embroidery.satin import SatinOptions
from fabrication.embroidery.triple import TripleOptions
from fabrication.embroidery.zigzag import ZigzagOptions
from fabrication.job_options import embroidery_settings, laser_settings
from fabrication.laser.gcode_write import GcodeOptions
from fabrication.laser.toolpath import ToolpathOptions
from fabrication.placement import PlacementOptions
from machines.emulator import EmulatorOptions
from onestroke.errors import InputError
from onestroke.ranges import Range, ranges_of
from vectorize.options import VectorizeOptions
from vectorize.refine.edits import Edits, edits_from_dict

ROOT = Path(__file__).resolve().parents[1]
OPTION_TYPES = [VectorizeOptions, Edits, PlacementOptions, RunningOptions, TripleOptions, ZigzagOptions,
                SatinOptions, ArrowOptions, LockOptions, PlanOptions, EmbroideryJob, PreviewOptions, ToolpathOptions,
                GcodeOptions, EmulatorOptions]


def _outside(limits: Range) -> list:
    """Values just outside each bound (the bound itself where it is open)."""
    values = []
    for bound, is_open, step in ((limits.low, limits.low_open, -1), (limits.high, limits.high_open, +1)):
        if bound is None:
            continue
        if is_open:
            values.append(int(bound) if limits.integer else float(bound))
        else:
            values.append(int(bound) + step if limits.integer else bound + step * max(abs(bound) * 1e-3, 1e-3))
    return values


CASES = [(cls, name, limits) for cls in OPTION_TYPES for name, limits in ranges_of(cls).items()]


def test_every_option_type_declares_ranges():
    assert all(ranges_of(cls) for cls in OPTION_TYPES)
    assert len(CASES) >= 40


@pytest.mark.parametrize("cls,name,limits", CASES, ids=[f"{c.__name__}.{n}" for c, n, _ in CASES])
def test_an_option_type_refuses_what_its_range_excludes(cls, name, limits):
    """Built directly (the library, the studio, batch, edits files): out of range, not finite,
    not a number, or a fraction where a whole number is declared is one `InputError` in the
    CLI's words; the default is inside."""
    cls()  # the defaults lie within every range
    for value in _outside(limits):
        with pytest.raises(InputError) as refused:
            cls(**{name: value})
        shown = str(value) if isinstance(value, int) else f"{value * limits.scale:g}"
        assert str(refused.value) == f"{limits.name} {shown} must be {limits.text()}"
    for value, words in ((math.nan, "is not a finite number"), (math.inf, "is not a finite number"),
                         ("12", "is not a number"), (True, "is not a number")):
        with pytest.raises(InputError, match=re.escape(f"{limits.name} ") + ".*" + words):
            cls(**{name: value})
    if limits.integer:
        with pytest.raises(InputError, match="is not a whole number"):
            cls(**{name: float(limits.low) + 0.5})


def test_edits_files_use_the_vectorizers_ranges():
    base = {"format": "onestroke-edits", "version": 1, "edits": []}
    for key, value, message in (("blur", 1e9, "--blur 1e+09 must be from 0 px to 25 px"),
                                ("threshold", 1.5, "--threshold 1.5 must be above 0 to below 1")):
        with pytest.raises(InputError, match=re.escape(message)):
            edits_from_dict({**base, key: value})


# (command line, the job_options call the studio and batch make with the same text)
SAME_LINE = [
    (["laser", "-o", "{out}/a.gcode", "--passes", "1000"], lambda: laser_settings(passes="1000")),
    (["laser", "-o", "{out}/a.gcode", "--passes", "2.5"], lambda: laser_settings(passes="2.5")),
    (["laser", "-o", "{out}/a.gcode", "--feed", "1e12"], lambda: laser_settings(feed="1e12")),
    (["laser", "-o", "{out}/a.gcode", "--feed", "0.5mm/min"], lambda: laser_settings(feed="0.5mm/min")),
    (["laser", "-o", "{out}/a.gcode", "--power", "0%"], lambda: laser_settings(power="0%")),
    (["laser", "-o", "{out}/a.gcode", "--size", "0.001mm"], lambda: laser_settings(size="0.001mm")),
    (["laser", "-o", "{out}/a.gcode", "--tolerance", "2mm"], lambda: laser_settings(tolerance="2mm")),
    (["laser", "-o", "{out}/a.gcode", "--rotate", "400"], lambda: laser_settings(rotate="400")),
    (["embroider", "-o", "{out}/a.pes", "--rotate", "-361"], lambda: embroidery_settings(output="a.pes", rotate="-361")),
    (["embroider", "-o", "{out}/a.pes", "--spm", "5000"], lambda: embroidery_settings(output="a.pes", spm="5000")),
    (["embroider", "-o", "{out}/a.pes", "--stitch-length", "20mm"],
     lambda: embroidery_settings(output="a.pes", stitch_length="20mm")),
    (["embroider", "-o", "{out}/a.pes", "--style", "zigzag", "--stitch-width", "13mm"],
     lambda: embroidery_settings(output="a.pes", style="zigzag", stitch_width="13mm")),
    (["embroider", "-o", "{out}/a.pes", "--style", "triple", "--repeats", "9"],
     lambda: embroidery_settings(output="a.pes", style="triple", repeats="9")),
    (["embroider", "-o", "{out}/a.pes", "--min-stitch", "0.05mm"],
     lambda: embroidery_settings(output="a.pes", min_stitch="0.05mm")),
    (["embroider", "-o", "{out}/a.pes", "--stitch-length", "0.2mm"],
     lambda: embroidery_settings(output="a.pes", stitch_length="0.2mm")),
    (["embroider", "-o", "{out}/a.pes", "--hoop", "11000x11000", "--size", "10000mm"],
     lambda: embroidery_settings(output="a.pes", hoop="11000x11000", size="10000mm")),
    (["embroider", "-o", "{out}/a.pes", "--hoop", "100x1.6m"], lambda: embroidery_settings(output="a.pes", hoop="100x1.6m")),
]


@pytest.mark.parametrize("argv,call", SAME_LINE, ids=[" ".join(a[3:]) for a, _ in SAME_LINE])
def test_the_command_line_and_job_options_give_the_same_line(tmp_path, argv, call):
    drawing = tmp_path / "d.svg"
    drawing.write_text('<svg xmlns="http://www.w3.org/2000/svg" width="100" height="80">'
                       '<path d="M 10 10 C 40 80, 60 0, 90 70" stroke="black" fill="none"/></svg>')
    out = tmp_path / "out"
    out.mkdir()
    result = CliRunner().invoke(main, [argv[0], str(drawing)] + [a.replace("{out}", str(out)) for a in argv[1:]])
    assert result.exit_code == 2, result.output
    with pytest.raises(InputError) as refused:
        call()
    assert result.stderr.strip() == f"error: {refused.value}"
    assert list(out.iterdir()) == []


def test_the_docs_table_is_the_declarations():
    text = (ROOT / "docs" / "cli.md").read_text(encoding="utf-8")
    start, end = text.index(BEGIN), text.index(END) + len(END)
    assert text[start:end] == markdown(), "regenerate it: python -m fabrication.cli.range_table"


def test_the_readme_quotes_the_declared_ranges():
    text = " ".join((ROOT / "README.md").read_text(encoding="utf-8").split())
    bullet = text[text.index("every numeric option has a range"):]
    bullet = bullet[:bullet.index(" - ")]
    spans = {}
    for _, flag, span in ranged_options():
        spans.setdefault(flag, set()).add(span)
    quoted = re.findall(r"`(--[a-z-]+)` (?=[-\d])", bullet)
    assert len(quoted) >= 5
    for flag in quoted:
        assert any(f"`{flag}` {span}" in bullet for span in spans[flag]), (flag, spans[flag])

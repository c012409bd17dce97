"""Hostile inputs (issue 28): bounded SVG reading, JSON checked against its schema, one
number grammar, options checked before any work, messages that say what is wrong."""

from __future__ import annotations

import gzip
import json
import os
import time
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from fabrication.cli import main
from onestroke.errors import InputError
from vectorize.svg.svg_read import read_svg

from benchmarks.hostile_cases import SVG_HEAD, WAVE, _comment, _nested_use

ROOT = Path(__file__).resolve().parents[1]


def run(*args) -> object:
    return CliRunner().invoke(main, [str(a) for a in args])


def refused(result, *words: str) -> str:
    """The one-line refusal of a command run (exit 2, no traceback), checked for `words`."""
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output and "internal error" not in result.output, result.output
    line = result.output.strip().splitlines()[-1]
    for word in words:
        assert word in line, line
    return line


# -- bounded SVG reading -------------------------------------------------------------------------

def test_nested_use_doubling_is_refused_before_expanding(tmp_path):
    svg = tmp_path / "use21.svg"
    svg.write_text(_nested_use(21))
    started = time.perf_counter()
    with pytest.raises(InputError, match=r"id='u8'> adds 1,018 elements once its <use> references are expanded"):
        read_svg(svg)
    assert time.perf_counter() - started < 5.0  # before: still running at 300 s, 2.5 GB


def test_expansion_within_the_budget_reads_every_copy(tmp_path):
    svg = tmp_path / "use4.svg"
    svg.write_text(_nested_use(4))  # 16 uses of one path kept in <defs>
    content = read_svg(svg)
    assert len(content.strokes) == 16
    assert all(np.allclose(s.control[0, 0], (10, 10)) for s in content.strokes)


def test_a_reference_loop_is_refused(tmp_path):
    svg = tmp_path / "loop.svg"
    svg.write_text(SVG_HEAD + '<g id="a"><use href="#b"/></g><g id="b"><use xlink:href="#a"/></g></svg>')
    with pytest.raises(InputError, match="refers to itself through <use>"):
        read_svg(svg)


def test_deep_nesting_is_refused_while_parsing(tmp_path):
    svg = tmp_path / "deep.svg"
    svg.write_text(SVG_HEAD + "<g>" * 5000 + '<path d="M0 0 L1 1"/>' + "</g>" * 5000 + "</svg>")
    with pytest.raises(InputError, match="nests elements more than 200 deep"):
        read_svg(svg)


def test_path_data_budget_counts_numbers_through_references(tmp_path):
    # one path of 5,000 numbers used 11 times: 50,000 numbers added, over 10 times the 5,000 written
    d = "M0 0 " + "L1 1 " * 2_499
    uses = "".join('<use href="#p"/>' for _ in range(11))
    svg = tmp_path / "many.svg"
    svg.write_text(SVG_HEAD + f'<defs><path id="p" d="{d}" stroke="black" fill="none"/></defs>{uses}</svg>')
    with pytest.raises(InputError, match="adds 55,000 numbers of path data once its <use> references are expanded, "
                                         "over the limit of 50,000"):
        read_svg(svg)
    svg.write_text(SVG_HEAD + f'<defs><path id="p" d="{d}" stroke="black" fill="none"/></defs>{uses[:-16]}</svg>')
    assert len(read_svg(svg).strokes) == 10  # 10 copies: 50,000 numbers added, within the limit


def test_a_plain_drawing_is_not_limited_by_the_reference_budget(tmp_path):
    body = "".join(f'<path d="M {i} 0 L {i} 50" stroke="black"/>' for i in range(3000))
    svg = tmp_path / "plain.svg"
    svg.write_text(SVG_HEAD + body + "</svg>")
    assert len(read_svg(svg).strokes) == 3000


def test_a_huge_comment_is_read_in_linear_time(tmp_path):
    svg = tmp_path / "comment.svg"
    svg.write_text(_comment(16))
    plain = tmp_path / "plain.svg"
    plain.write_text(_comment(0))
    started = time.perf_counter()
    content = read_svg(svg)
    assert time.perf_counter() - started < 10.0  # before: 22 s (16 MB), minutes for 60 MB
    assert np.array_equal(content.strokes[0].control, read_svg(plain).strokes[0].control)


def test_elements_that_draw_nothing_are_dropped_and_change_nothing(tmp_path):
    body = '<path d="M 10 10 C 30 0 60 90 90 40" stroke="black" fill="none"/>'
    noisy = tmp_path / "noisy.svg"
    noisy.write_text(SVG_HEAD.replace("<svg ", '<svg xmlns:sodipodi="http://sodipodi.sourceforge.net/DTD/'
                                      'sodipodi-0.dtd" ') + "<!-- a note --><metadata>" + "x" * 10_000 +
                     "</metadata><title>t</title><desc>d</desc><sodipodi:namedview id='n'/>" + body + "</svg>")
    clean = tmp_path / "clean.svg"
    clean.write_text(SVG_HEAD + body + "</svg>")
    a, b = read_svg(noisy), read_svg(clean)
    assert len(a.strokes) == len(b.strokes) == 1
    assert np.array_equal(a.strokes[0].control, b.strokes[0].control)


@pytest.mark.parametrize("body, words", [
    ('<path d="M 0 0 A 1e308 1e308 0 1 1 10 10" stroke="black"/>', "has an arc whose radius or sweep is not a finite"),
    ('<g transform="scale(1e308) rotate(45)"><path d="M 10 10 L 90 90" stroke="black"/></g>',
     "has a coordinate that is not a finite number"),
    ('<path d="M 0 0 L 1e300 1e300" stroke="black"/>', "beyond the limit"),
])
def test_non_finite_arithmetic_is_refused_naming_the_element(tmp_path, body, words):
    svg = tmp_path / "bad.svg"
    svg.write_text(SVG_HEAD + body + "</svg>")
    for command, out in (("vectorize", "o.svg"), ("embroider", "o.pes"), ("laser", "o.gcode"), ("preview", "o.png")):
        refused(run(command, svg, "-o", tmp_path / out), words, "<path>")
        assert not (tmp_path / out).exists()


def test_svgz_reads_as_the_svg_it_holds(tmp_path):
    plain, packed = tmp_path / "wave.svg", tmp_path / "wave.svgz"
    plain.write_text(WAVE)
    packed.write_bytes(gzip.compress(WAVE.encode()))
    assert np.array_equal(read_svg(plain).strokes[0].control, read_svg(packed).strokes[0].control)
    assert run("vectorize", packed, "-o", tmp_path / "a.svg").exit_code == 0
    assert run("vectorize", plain, "-o", tmp_path / "b.svg").exit_code == 0
    assert (tmp_path / "a.svg").read_bytes() == (tmp_path / "b.svg").read_bytes()
    assert run("preview", packed, "-o", tmp_path / "p.png").exit_code == 0
    damaged = tmp_path / "bad.svgz"
    damaged.write_bytes(gzip.compress(WAVE.encode())[:30])
    refused(run("vectorize", damaged, "-o", tmp_path / "c.svg"), "gzip-compressed (.svgz) but damaged")


# -- JSON inputs --------------------------------------------------------------------------------

@pytest.mark.parametrize("data, words", [
    (b"[1,2,3]", ["$: expected object, got a list"]),
    (bytes(range(256)) * 4, ["not JSON"]),
    (b"\xff\xfe\x00[", ["not JSON"]),
    (b'{"format": "onestroke-drawing", "width": "wide", "height": 10, "strokes": []}',
     ["$.width: expected number, got a string ('wide')"]),
    (b'{"format": "onestroke-drawing", "width": 10, "height": 10, "strokes": [[[0, 0], [1, 1]]]}',
     ["$.strokes[0]: expected numbers in an array of shape (K, 4, 2)"]),
    (b'{"format": "onestroke-drawing", "width": 10, "height": 10, "strokes": [], "x": NaN}',
     ["is not JSON", "NaN is not a number JSON allows"]),
    (b'{"format": "onestroke-drawing", "width": 10, "height": 10, "strokes": [[[[0,0],[1,1],[2,2],[3,true]]]]}',
     ["$.strokes[0]: expected numbers"]),
])
def test_bad_json_drawings_are_refused_in_one_line_naming_the_file(tmp_path, data, words):
    source = tmp_path / "bad.json"
    source.write_bytes(data)
    for command, out in (("preview", "o.png"), ("embroider", "o.pes"), ("preview", "o.html")):
        refused(run(command, source, "-o", tmp_path / out), f"drawing '{source}'", *words)


def test_a_good_json_drawing_still_reads(tmp_path):
    from vectorize.svg_write import drawing_to_json, read_drawing_json

    svg = tmp_path / "wave.svg"
    svg.write_text(WAVE)
    drawing = read_svg(svg).as_drawing()
    path = tmp_path / "wave.json"
    path.write_text(drawing_to_json(drawing))
    back = read_drawing_json(path)
    assert np.allclose(back.strokes[0].control, drawing.strokes[0].control, atol=1e-4)


@pytest.mark.parametrize("text, words", [
    ("[1,2,3]", "not an onestroke edits file"),
    ('{"format": "onestroke-edits", "version": 1, "edits": [{"kind": "split", "at": "here"}]}',
     '$.edits[0].at: expected array, got a string'),
    ('{"format": "onestroke-edits", "version": 1, "blur": "1"}', '$.blur: expected number or null, got a string'),
    ('{"format": "onestroke-edits", "version": 1, "blur": -1}', "--blur -1 must be from 0 px to 25 px"),
])
def test_bad_edits_files_are_refused_naming_the_file(tmp_path, text, words):
    edits = tmp_path / "e.json"
    edits.write_text(text)
    png = ROOT / "examples" / "loops.png"
    refused(run("vectorize", png, "-o", tmp_path / "o.svg", "--edits", edits), f"edits file '{edits}'", words)


def test_a_manifest_of_wrong_types_is_ignored_not_a_crash(tmp_path):
    from fabrication.batch.manifest import MANIFEST_NAME, Manifest

    (tmp_path / MANIFEST_NAME).write_text(json.dumps({"format": "onestroke-batch-manifest", "outputs": [1],
                                                      "failed": {"a.png": "x"}}))
    manifest = Manifest(tmp_path)
    assert manifest.outputs == {} and manifest.failed == {}


# -- one number grammar, options checked before any work -----------------------------------------

@pytest.mark.parametrize("text", ["1_0", "\u0661\u0660", "\uff11\uff10", "nan", "inf", "0x10", "1,5", ""])
def test_one_number_grammar_refuses_what_is_not_ascii_decimal(text):
    from onestroke.units import parse_integer, parse_length, parse_number

    for parse in (parse_number, parse_integer, parse_length):
        with pytest.raises(InputError):
            parse(text + ("mm" if parse is parse_length and text else ""))


def test_one_number_grammar_reads_ascii_decimal():
    from onestroke.units import parse_integer, parse_length, parse_number

    assert parse_number(" -2.5e1 ") == -25.0 and parse_number(".5") == 0.5 and parse_integer("+7") == 7
    assert parse_length("1e1mm") == 10.0


@pytest.mark.parametrize("flag, value", [("--passes", "1_0"), ("--rotate", "1_0"), ("--passes", "\u0663"),
                                         ("--rotate", "\uff11\uff10"), ("--size", "\uff19\uff10mm"),
                                         ("--port", "sim://?speed=nan"), ("--port", "sim://?rx=0"),
                                         ("--port", "sim://?speed=1e400"), ("--port", "sim://?blocks=1_5")])
def test_laser_options_are_refused_before_any_work(tmp_path, flag, value):
    svg = tmp_path / "wave.svg"
    svg.write_text(WAVE)
    out = tmp_path / "o.gcode"
    refused(run("laser", svg, "-o", out, flag, value), flag)
    assert not out.exists()  # before: sim://?speed=nan wrote the G-code, then failed with exit 1


@pytest.mark.parametrize("baud", ["0", "-1", "1e20", "115_200"])
def test_ports_refuses_a_baud_rate_grbl_does_not_use(baud):
    refused(run("ports", "--no-probe", "--baud", baud), "--baud")


# -- messages that say what is wrong -------------------------------------------------------------

def test_fifo_and_device_inputs_are_named_for_what_they_are(tmp_path):
    fifo = tmp_path / "fifo.svg"
    os.mkfifo(fifo)
    zero = tmp_path / "zero.svg"
    os.symlink("/dev/zero", zero)
    dangling = tmp_path / "gone.svg"
    os.symlink(tmp_path / "nothing.svg", dangling)
    refused(run("vectorize", fifo, "-o", tmp_path / "a.svg"), "is a named pipe (FIFO), not a regular file")
    refused(run("vectorize", zero, "-o", tmp_path / "a.svg"), "(a link to '/dev/zero') is a character device")
    refused(run("vectorize", dangling, "-o", tmp_path / "a.svg"), "is a symbolic link to", "which does not exist")
    refused(run("stream", fifo, "--port", "sim://"), "named pipe")
    with pytest.raises(InputError, match="named pipe"):
        read_svg(fifo)


def test_a_thin_image_is_refused_with_its_own_size(tmp_path):
    from PIL import Image

    Image.new("L", (1, 5000), 255).save(tmp_path / "tall.png")
    refused(run("vectorize", tmp_path / "tall.png", "-o", tmp_path / "o.svg"), "is 1x5000 px: too small")


def test_streaming_an_svg_says_it_is_not_gcode(tmp_path):
    svg = tmp_path / "wave.svg"
    svg.write_text(WAVE)
    refused(run("stream", svg, "--port", "sim://"), "is an SVG drawing, not G-code")

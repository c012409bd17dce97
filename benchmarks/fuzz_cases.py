"""Fuzzed command lines for `onestroke`: Hypothesis strategies for PNG bytes, SVG text,
G-code text and option values, and `run_case`, which runs one through the real click group
in-process and reports what a user would see go wrong.

Shared by the suite's fuzz test (tests/test_cli_fuzz.py, bounded to about a minute) and the
long run (benchmarks/fuzz.py, 2,000 inputs).
"""

from __future__ import annotations

import io
import signal
import time
import zlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from hypothesis import strategies as st

SVG_NAMESPACES = ['xmlns="http://www.w3.org/2000/svg"', 'xmlns="https://www.w3.org/2000/svg"',
                  'xmlns="http://www.w3.org/2000/svg/"', "", 'xmlns="urn:nothing"']
NUMBERS = st.one_of(st.floats(-500, 500, allow_nan=False), st.sampled_from(
    ["nan", "inf", "-inf", "1e300", "-1e30", "1e-300", "0", "", "x", "1e999", "5e6", "1,2"]))


def _num(value) -> str:
    return f"{value:.6g}" if isinstance(value, float) else str(value)


@st.composite
def png_bytes(draw) -> bytes:
    """A small image (1-48 px, gray, RGB or RGBA, lines or noise), sometimes damaged."""
    from PIL import Image, ImageDraw

    w, h = draw(st.integers(1, 48)), draw(st.integers(1, 48))
    mode = draw(st.sampled_from(["L", "RGB", "RGBA", "1", "I;16", "P"]))
    image = Image.new("L", (w, h), 255)
    pen = ImageDraw.Draw(image)
    for _ in range(draw(st.integers(0, 4))):
        pen.line([draw(st.integers(0, w)), draw(st.integers(0, h)), draw(st.integers(0, w)),
                  draw(st.integers(0, h))], fill=0, width=draw(st.integers(1, 5)))
    if draw(st.booleans()):
        noise = np.random.default_rng(draw(st.integers(0, 2**16))).random((h, w)) < draw(st.floats(0, 0.5))
        image = Image.fromarray(np.where(noise, 0, np.asarray(image)).astype(np.uint8))
    buffer = io.BytesIO()
    (image.convert(mode) if mode != "I;16" else image.convert("I;16")).save(buffer, format="PNG")
    data = bytearray(buffer.getvalue())
    damage = draw(st.sampled_from(["none", "none", "truncate", "flip", "header"]))
    if damage == "truncate":
        data = data[: draw(st.integers(0, len(data)))]
    elif damage == "flip" and len(data) > 8:
        for _ in range(draw(st.integers(1, 8))):
            data[draw(st.integers(8, len(data) - 1))] ^= draw(st.integers(1, 255))
    elif damage == "header":  # IHDR claiming a huge size
        data[16:24] = draw(st.sampled_from([b"\x00\x01\x00\x00\x00\x01\x00\x00", b"\xff\xff\xff\xff\x00\x00\x00\x01"]))
        data[29:33] = zlib.crc32(bytes(data[12:29])).to_bytes(4, "big")
    return bytes(data)


@st.composite
def svg_text(draw) -> str:
    """An SVG with random namespace spelling, wrapper, elements and (absurd) numbers."""
    n = lambda: _num(draw(NUMBERS))  # noqa: E731
    elements = []
    for _ in range(draw(st.integers(0, 5))):
        kind = draw(st.sampled_from(["path", "circle", "line", "polyline", "rect", "ellipse", "text", "g"]))
        paint = draw(st.sampled_from(['stroke="black" fill="none"', 'fill="black"', "", 'stroke="red" '
                                      'style="display:none"', 'stroke="none" fill="none"']))
        if kind == "path":
            d = " ".join(f"{c} {n()} {n()}" for c in draw(st.lists(st.sampled_from("MLCQTSHVZAmlc"), max_size=8)))
            elements.append(f'<path d="M {n()} {n()} {d}" {paint} transform="rotate({n()}) scale({n()})"/>')
        elif kind == "circle":
            elements.append(f'<circle cx="{n()}" cy="{n()}" r="{n()}" {paint}/>')
        elif kind == "line":
            elements.append(f'<line x1="{n()}" y1="{n()}" x2="{n()}" y2="{n()}" {paint} stroke-width="{n()}"/>')
        elif kind == "polyline":
            elements.append(f'<polyline points="{" ".join(n() for _ in range(draw(st.integers(0, 9))))}" {paint}/>')
        elif kind == "rect":
            elements.append(f'<rect x="{n()}" y="{n()}" width="{n()}" height="{n()}" rx="{n()}" {paint}/>')
        elif kind == "ellipse":
            elements.append(f'<ellipse cx="{n()}" cy="{n()}" rx="{n()}" ry="{n()}" {paint}/>')
        elif kind == "text":
            elements.append(f'<text x="{n()}" y="{n()}">{draw(st.text(max_size=10))}</text>')
        else:
            elements.append(f'<g transform="matrix({",".join(n() for _ in range(6))})"><path d="M0 0 L 10 10" '
                            'stroke="black"/></g>')
    root = draw(st.sampled_from(SVG_NAMESPACES))
    style = draw(st.sampled_from(["", 'style="display:none"', 'viewBox="0 0 0 0"', f'viewBox="0 0 {n()} {n()}"']))
    text = f'<svg {root} width="{n()}" height="{n()}" {style}>{"".join(elements)}</svg>'
    wrap = draw(st.sampled_from(["{}", "{}", '<html xmlns="http://www.w3.org/1999/xhtml"><body>{}</body></html>',
                                 '<?xml version="1.0"?>{}', "{}<!-- trailing", "<!DOCTYPE svg [<!ENTITY a "
                                 '"aaaaaaaaaa">]>{}']))
    return wrap.format(text)


@st.composite
def gcode_text(draw) -> bytes:
    """G-code lines from GRBL's words with random numbers, comments and stray bytes."""
    lines = []
    for _ in range(draw(st.integers(0, 12))):
        word = draw(st.sampled_from(["G0", "G1", "G2", "G3", "G21", "G20", "G90", "G91", "M3", "M4", "M5", "S",
                                     "F", "G4 P", "$H", "(comment", "; note", "%", "G17", "G92", "M8"]))
        args = " ".join(f"{a}{_num(draw(NUMBERS))}" for a in draw(st.lists(st.sampled_from("XYZIJRSFP"), max_size=4)))
        lines.append(f"{word} {args}")
    data = "\n".join(lines).encode("latin-1", "replace")
    if draw(st.booleans()):
        data += draw(st.binary(max_size=40))
    return data


SIZE = st.one_of(st.sampled_from(["90mm", "3in", "0", "-5mm", "1e999mm", "nan", "10furlong", "", "1e9mm",
                                  "0.05mm", "20000mm"]), st.floats(-1e6, 1e6).map(lambda v: f"{v:g}mm"))
OPTION_SETS = {
    "embroider": {"--size": SIZE, "--rotate": NUMBERS.map(_num), "--stitch-length": SIZE, "--min-stitch": SIZE,
                  "--max-stitch": SIZE, "--style": st.sampled_from(["running", "triple", "zigzag", "arrows", "x"]),
                  "--spacing": SIZE, "--stitch-width": SIZE, "--repeats": st.sampled_from(["0", "1", "5", "999", "x"]),
                  "--hoop": st.sampled_from(["100x100", "5x7", "0x0", "1e9x1e9", "x", "130x180mm"]),
                  "--spm": NUMBERS.map(_num), "--trim-distance": SIZE, "--blur": NUMBERS.map(_num)},
    "laser": {"--size": SIZE, "--feed": st.sampled_from(["1500mm/min", "0.0001mm/min", "0", "25mm/s", "1e9mm/min",
                                                         "fast", "-3"]),
              "--power": st.sampled_from(["60%", "0%", "150%", "nan%", "1e-9%", "100"]),
              "--passes": st.sampled_from(["1", "0", "100", "101", "1000000", "-1", "x"]),
              "--tolerance": SIZE, "--raster-interval": SIZE, "--blur": NUMBERS.map(_num),
              "--threshold": NUMBERS.map(_num), "--frame-power": st.sampled_from(["0%", "50%", "200%"])},
}


@st.composite
def option_case(draw) -> tuple[str, list[str]]:
    command = draw(st.sampled_from(sorted(OPTION_SETS)))
    chosen = draw(st.lists(st.sampled_from(sorted(OPTION_SETS[command])), max_size=4, unique=True))
    args = []
    for flag in chosen:
        args += [flag, draw(OPTION_SETS[command][flag])]
    return command, args


def fuzz_case(kind: str):
    """A strategy of (kind, input bytes or None, command, extra args) for one kind."""
    if kind == "png":
        return st.tuples(st.just("png"), png_bytes(), st.sampled_from(["vectorize", "vectorize", "laser"]),
                         st.just([]))
    if kind == "svg":
        return st.tuples(st.just("svg"), svg_text().map(lambda t: t.encode("utf-8")),
                         st.sampled_from(["vectorize", "preview", "embroider", "laser"]), st.just([]))
    if kind == "gcode":
        return st.tuples(st.just("gcode"), gcode_text(), st.just("preview"), st.just([]))
    return option_case().map(lambda c: ("options", None, c[0], c[1]))


GOOD_SVG = ('<svg xmlns="http://www.w3.org/2000/svg" width="200" height="150"><path d="M 20 120 C 40 20, 80 20, '
            '100 75 S 160 130, 180 30" fill="none" stroke="black" stroke-width="3"/></svg>')
OUTPUT = {"vectorize": "out.svg", "preview": "out.png", "embroider": "out.pes", "laser": "out.gcode"}
SUFFIX = {"png": ".png", "svg": ".svg", "gcode": ".gcode", "options": ".svg"}


class Hang(BaseException):
    """Raised by the alarm when one case runs past its time bound (not an Exception, so no
    handler in the command can swallow it)."""


@dataclass(frozen=True)
class Outcome:
    exit_code: int | None
    traceback: str | None  # the exception a user would have seen as a traceback, if any
    hung: bool
    leftovers: tuple[str, ...]  # files left after a failure, or partial files after success
    seconds: float


def run_case(case, folder: Path, *, time_bound: float) -> Outcome:
    """Run one fuzzed command line in `folder` (emptied first) through the real click group."""
    from click.testing import CliRunner

    from fabrication.cli import main

    kind, data, command, extra = case
    for old in folder.iterdir():
        old.unlink()
    source = folder / f"in{SUFFIX[kind]}"
    source.write_bytes(data if data is not None else GOOD_SVG.encode())
    out = folder / OUTPUT[command]
    args = [command, str(source), "-o", str(out), *extra]

    def alarm(signum, frame):
        raise Hang()

    previous = signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, time_bound)
    started = time.perf_counter()
    hung, code, trace = False, None, None
    try:
        result = CliRunner().invoke(main, args)
        code = result.exit_code
        if result.exception is not None and not isinstance(result.exception, SystemExit):
            trace = f"{type(result.exception).__name__}: {result.exception}"
        elif "Traceback" in result.output or "internal error" in result.output:
            trace = result.output.strip().splitlines()[-1]
    except Hang:
        hung = True
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
    seconds = time.perf_counter() - started
    made = sorted(p.name for p in folder.iterdir() if p != source)
    leftovers = tuple(m for m in made if code != 0 or m.endswith(".part") or m.startswith("."))
    return Outcome(code, trace, hung, leftovers, seconds)

"""Fuzzed command lines for `onestroke`: Hypothesis strategies for PNG bytes, SVG text and
SVG structure (nested and looping <use>, symbols, comments, huge numbers, transforms),
G-code text, JSON drawings and edits files, and option values of every command; and
`run_case`, which runs one through the real click group in-process and reports what a user
would see go wrong (a traceback or internal error, a run over its time or memory bound, an
incomplete set of outputs).

Shared by the suite's fuzz test (tests/test_cli_fuzz.py, bounded to about a minute) and the
long run (benchmarks/fuzz.py, 2,000 inputs or more).
"""

from __future__ import annotations

import gzip
import io
import json
import resource
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
    ["nan", "inf", "-inf", "1e300", "-1e30", "1e-300", "0", "", "x", "1e999", "5e6", "1,2", "1_0", "\u0661\u0660",
     "\uff11\uff10", "0x10", " 5 ", "+.5", "1e-400", "-0"]))
HUGE = st.sampled_from(["1e308", "-1e308", "1.8e308", "1e-308", "5e6", "nan", "inf", "0", "1e7", "-1e7"])


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


SVG_ROOT = ('<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" '
            'width="200" height="150">')


@st.composite
def svg_structure(draw) -> bytes:
    """An SVG whose cost is in its structure: <use> chains and fans (sometimes looping or
    missing their target), <symbol>s, deep <g> nesting, comments and metadata, huge or
    non-finite numbers in arcs and transforms; sometimes gzip-compressed."""
    h = lambda: draw(HUGE)  # noqa: E731
    n = lambda: _num(draw(NUMBERS))  # noqa: E731
    defs = ['<path id="d0" d="M 10 10 C 40 0 60 90 90 40" stroke="black" fill="none"/>']
    levels = draw(st.integers(0, 24))
    fan = draw(st.integers(1, 4))
    for level in range(1, levels + 1):
        tag = draw(st.sampled_from(["g", "symbol", "g"]))
        link = draw(st.sampled_from(["href", "xlink:href"]))
        target = f"#d{level - 1}" if not draw(st.integers(0, 30)) == 0 else draw(st.sampled_from(
            [f"#d{level}", "#d0", "#nothing", "", "d0"]))  # loops, missing targets, no '#'
        uses = "".join(f'<use {link}="{target}" transform="translate({n()},{n()})"/>' for _ in range(fan))
        defs.append(f'<{tag} id="d{level}">{uses}</{tag}>')
    body = [f'<use href="#d{levels}"/>']
    for _ in range(draw(st.integers(0, 4))):
        kind = draw(st.sampled_from(["arc", "transform", "comment", "metadata", "deep", "skew", "svg", "style"]))
        if kind == "arc":
            body.append(f'<path d="M {n()} {n()} A {h()} {h()} {h()} {draw(st.sampled_from("01"))} '
                        f'{draw(st.sampled_from("01"))} {h()} {h()}" stroke="black" fill="none"/>')
        elif kind == "transform":
            body.append(f'<g transform="{draw(st.sampled_from(["scale", "translate", "rotate"]))}({h()}) '
                        f'matrix({",".join(h() for _ in range(6))})"><use href="#d0"/></g>')
        elif kind == "skew":
            body.append(f'<g transform="skewX({draw(st.sampled_from(["90", "-90", "89.9999999", h()]))})">'
                        '<use href="#d0"/></g>')
        elif kind == "comment":
            body.append("<!--" + "c" * draw(st.integers(0, 300_000)) + "-->")
        elif kind == "metadata":
            body.append("<metadata><rdf:RDF xmlns:rdf='http://www.w3.org/1999/02/22-rdf-syntax-ns#'>"
                        + "m" * draw(st.integers(0, 100_000)) + "</rdf:RDF></metadata><title>t</title>")
        elif kind == "deep":
            depth = draw(st.sampled_from([5, 50, 199, 210, 2000]))
            body.append("<g>" * depth + '<use href="#d0"/>' + "</g>" * depth)
        elif kind == "svg":
            body.append(f'<svg x="{n()}" y="{n()}" width="{n()}" height="{n()}" viewBox="0 0 {n()} {n()}">'
                        '<use href="#d0"/></svg>')
        else:
            body.append(f"<style>path {{ stroke-width: {n()}; display: {draw(st.sampled_from(['none', 'inline']))} "
                        "}</style>")
    text = SVG_ROOT + "<defs>" + "".join(defs) + "</defs>" + "".join(body) + "</svg>"
    data = text.encode("utf-8")
    return gzip.compress(data, mtime=0) if draw(st.integers(0, 9)) == 0 else data


@st.composite
def drawing_json(draw) -> bytes:
    """A JSON drawing: valid, with a wrong type or shape somewhere, not finite, or not JSON."""
    coordinate = lambda: [draw(st.floats(-100, 100)), draw(st.floats(-100, 100))]  # noqa: E731
    strokes = []
    for _ in range(draw(st.integers(0, 3))):
        pieces = [[coordinate() for _ in range(4)]]
        for _ in range(draw(st.integers(0, 2))):  # one connected curve: each piece starts where the last ended
            pieces.append([pieces[-1][3]] + [coordinate() for _ in range(3)])
        strokes.append(pieces)
    payload = {"format": "onestroke-drawing", "version": 1, "unit": draw(st.sampled_from(["px", "mm"])),
               "width": 200, "height": 150, "stroke_width": 2, "strokes": strokes}
    damage = draw(st.sampled_from(["none", "none", "type", "shape", "colors", "drop", "nan", "bytes", "list",
                                   "deep", "huge", "gap"]))
    if damage == "type":
        key = draw(st.sampled_from(sorted(payload)))
        payload[key] = draw(st.sampled_from(["wide", None, True, [1, 2], {"a": 1}, -1, 1e308, 0]))
    elif damage == "shape" and strokes:
        strokes[0] = draw(st.sampled_from([[], [[0, 0]], [[[0, 0]] * 3], "s", [[[0, 0, 0]] * 4], [[[True, 0]] * 4]]))
    elif damage == "colors":
        payload["colors"] = draw(st.sampled_from([[[0, 0, 0]] * len(strokes) + [[1, 2, 3]], [[256, 0, 0]] *
                                                  len(strokes), "red", [None] * len(strokes)]))
    elif damage == "gap" and strokes and len(strokes[0]) > 1:
        strokes[0][1][0] = [strokes[0][1][0][0] + draw(st.sampled_from([1e-3, 0.5, 1e300])), strokes[0][1][0][1]]
    elif damage == "drop":
        payload.pop(draw(st.sampled_from(["format", "width", "height", "strokes"])))
    text = json.dumps(payload)
    if damage == "nan":
        text = text.replace("200", draw(st.sampled_from(["NaN", "Infinity", "-Infinity", "1e999"])), 1)
    if damage == "bytes":
        return draw(st.binary(max_size=300))
    if damage == "list":
        return draw(st.sampled_from([b"[1,2,3]", b"null", b"3", b'"drawing"', b"", b"\xef\xbb\xbf{}"]))
    if damage == "deep":
        depth = draw(st.sampled_from([100, 5000, 100_000]))
        return ("[" * depth + "]" * depth).encode()
    if damage == "huge":
        return json.dumps({**payload, "strokes": [[[[1e308, 1e308]] * 4] * 3]}).encode()
    return text.encode("utf-8")


@st.composite
def edits_json(draw) -> bytes:
    """An edits file: valid, with wrong types or values, or not JSON."""
    edit = {"kind": draw(st.sampled_from(["split", "merge", "pairing", "passes", "start", "fold", 3])),
            "at": draw(st.sampled_from([[10, 10], [1e308, 0], "here", [1], [None, None], [5, 5, 5]]))}
    if draw(st.booleans()):
        edit["pairing"] = draw(st.sampled_from(["crossing", "third", "x", None, 1]))
    if draw(st.booleans()):
        edit["passes"] = draw(st.sampled_from([[[0, 180], [60, 240], [120, 300]], [[1, 2]], "x", [[1, "a"]] * 3]))
    payload = {"format": draw(st.sampled_from(["onestroke-edits", "onestroke-edits", "other"])),
               "version": draw(st.sampled_from([1, 1, 2, "1"])),
               "threshold": draw(st.sampled_from([None, 0.5, 2, -1, "x"])),
               "blur": draw(st.sampled_from([None, 0, 1.5, -3, 1e308, [1]])),
               "multi": draw(st.sampled_from([None, True, "yes"])),
               "tolerance": draw(st.sampled_from([8, 0, -1, "x", 1e-308])),
               "edits": draw(st.sampled_from([[edit], [], "none", [edit, 1]]))}
    if draw(st.integers(0, 5)) == 0:
        return draw(st.sampled_from([b"[1,2,3]", b"{", b"\xff\xfe", b"NaN"]))
    return json.dumps(payload).encode()


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
                                  "0.05mm", "20000mm", "1_0mm", "\uff19\uff10mm", "9 0mm"]),
                 st.floats(-1e6, 1e6).map(lambda v: f"{v:g}mm"))
INTEGERS = st.sampled_from(["1", "0", "100", "101", "1000000", "-1", "x", "1_0", "\u0663", "1e2", "2.0", " 3 "])
PORTS = st.sampled_from(["sim://", "sim://?speed=nan", "sim://?speed=1e400", "sim://?rx=0", "sim://?rx=1_0",
                         "sim://?blocks=99", "sim://?travel=10x", "sim://?laser=2", "sim://?nope=1", "sim:/x",
                         "sim://?speed=\uff15", "", "/dev/nonexistent-tty"])
BAUDS = st.sampled_from(["115200", "0", "-1", "1e20", "9600", "115_200", "\uff19\uff16\uff10\uff10", "x"])
OPTION_SETS = {
    "embroider": {"--size": SIZE, "--rotate": NUMBERS.map(_num), "--stitch-length": SIZE, "--min-stitch": SIZE,
                  "--max-stitch": SIZE, "--style": st.sampled_from(["running", "triple", "zigzag", "arrows", "x"]),
                  "--spacing": SIZE, "--stitch-width": SIZE, "--repeats": INTEGERS,
                  "--hoop": st.sampled_from(["100x100", "5x7", "0x0", "1e9x1e9", "x", "130x180mm", "1_0x10"]),
                  "--spm": NUMBERS.map(_num), "--trim-distance": SIZE, "--blur": NUMBERS.map(_num),
                  "--start": st.sampled_from(["reverse", "0,0", "1e999,0", "x", "1_0,2"]),
                  "--pes-version": INTEGERS},
    "laser": {"--size": SIZE, "--feed": st.sampled_from(["1500mm/min", "0.0001mm/min", "0", "25mm/s", "1e9mm/min",
                                                         "fast", "-3", "1_500mm/min", "\uff11\uff10mm/s"]),
              "--power": st.sampled_from(["60%", "0%", "150%", "nan%", "1e-9%", "100", "6_0%"]),
              "--passes": INTEGERS, "--tolerance": SIZE, "--raster-interval": SIZE, "--blur": NUMBERS.map(_num),
              "--threshold": NUMBERS.map(_num), "--frame-power": st.sampled_from(["0%", "50%", "200%"]),
              "--port": PORTS, "--baud": BAUDS},
    "vectorize": {"--threshold": NUMBERS.map(_num), "--blur": NUMBERS.map(_num),
                  "--classifier": st.sampled_from(["cnn", "geometric", "x"])},
    "preview": {"--width": INTEGERS, "--spm": NUMBERS.map(_num), "--hoop": st.sampled_from(["100x100", "x", "0x5"])},
    "stream": {"--port": PORTS, "--baud": BAUDS, "--from-line": INTEGERS},
    "ports": {"--baud": BAUDS},
    "batch": {"--size": SIZE, "--jobs": INTEGERS, "--to": st.sampled_from(["svg", "pes,gcode", "x", "", "svg,svg"])},
}
GCODE_JOB = b"G21\nG90\nM4 S0\nG0 X1 Y1\nG1 X5 Y5 F600 S300\nM5\n"


@st.composite
def option_case(draw) -> tuple[str, list[str]]:
    command = draw(st.sampled_from(sorted(OPTION_SETS)))
    chosen = draw(st.lists(st.sampled_from(sorted(OPTION_SETS[command])), max_size=4, unique=True))
    args = []
    for flag in chosen:
        args += [flag, draw(OPTION_SETS[command][flag])]
    return command, args


# kind -> (suffix of the input file, the commands that read it)
KINDS = {
    "png": (".png", ["vectorize", "vectorize", "laser", "embroider", "preview"]),
    "svg": (".svg", ["vectorize", "preview", "embroider", "laser"]),
    "svg-structure": (".svg", ["vectorize", "preview", "embroider", "laser", "batch"]),
    "gcode": (".gcode", ["preview", "preview", "stream"]),
    "json": (".json", ["preview", "embroider", "preview-html"]),
    "edits": (".png", ["vectorize", "embroider", "laser"]),
    "options": (".svg", []),
}


def fuzz_case(kind: str):
    """A strategy of (kind, input bytes or None, command, extra args) for one kind."""
    commands = st.sampled_from(KINDS[kind][1]) if KINDS[kind][1] else None
    data = {"png": png_bytes(), "svg": svg_text().map(lambda text: text.encode("utf-8")),
            "svg-structure": svg_structure(), "gcode": gcode_text(), "json": drawing_json(),
            "edits": edits_json()}
    if kind == "options":
        return option_case().map(lambda c: ("options", None, c[0], c[1]))
    return st.tuples(st.just(kind), data[kind], commands, st.just([]))


GOOD_SVG = ('<svg xmlns="http://www.w3.org/2000/svg" width="200" height="150"><path d="M 20 120 C 40 20, 80 20, '
            '100 75 S 160 130, 180 30" fill="none" stroke="black" stroke-width="3"/></svg>')
OUTPUT = {"vectorize": "out.svg", "preview": "out.png", "preview-html": "out.html", "embroider": "out.pes",
          "laser": "out.gcode"}
MEMORY_BOUND_MB = 1024.0


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
    peak_mb: float = 0.0  # the process's (or a finished child's) peak resident memory after the case
    peak_before_mb: float = 0.0  # ... and before it
    message: str = ""  # the last line the command printed
    resident_before_mb: float = 0.0  # the memory in use when the case started

    @property
    def over_memory(self) -> bool:
        """The case set a new memory peak more than MEMORY_BOUND_MB above what was in use when
        it started (a peak is a high-water mark: a case under an earlier, higher peak did not
        go over it; in benchmarks/fuzz.py's fresh process the final peak bounds every case)."""
        return self.peak_mb > self.peak_before_mb and self.peak_mb - self.resident_before_mb > MEMORY_BOUND_MB


def _good_png() -> bytes:
    from PIL import Image, ImageDraw

    image = Image.new("L", (120, 90), 255)
    ImageDraw.Draw(image).line([(10, 80), (60, 10), (110, 80)], fill=0, width=5)
    buffer = io.BytesIO()
    image.save(buffer, format="PNG")
    return buffer.getvalue()


def _command_line(kind: str, command: str, extra: list[str], source: Path, folder: Path) -> tuple[list[str], list[Path]]:
    """The argv after `onestroke` and the outputs it should make (all of them on success)."""
    if command == "ports":
        return ["ports", "--no-probe", *extra], []
    if command == "stream":
        port = [] if "--port" in extra else ["--port", "sim://?speed=1000"]
        return ["stream", str(source), *port, *extra], []
    if command == "batch":
        out = folder / "batch-out"
        to = [] if "--to" in extra else ["--to", "svg,pes,gcode"]
        jobs = [] if "--jobs" in extra else ["--jobs", "1"]
        return ["batch", str(source), "-o", str(out), *to, *jobs, *extra], []
    if kind == "edits":
        edits = folder / "edits.json"
        extra = ["--edits", str(edits), *extra]
    name = command.split("-")[0]
    out = folder / OUTPUT[command]
    outputs = [out]
    if name in ("embroider", "laser") and kind in ("png", "svg-structure"):
        outputs.append(folder / "out-preview.png")
        extra = ["--preview", str(outputs[-1]), *extra]
    return [name, str(source), "-o", str(out), *extra], outputs


def _resident_mb() -> float:
    """Resident memory of this process now (Linux /proc; 0 where it cannot be read)."""
    try:
        with open("/proc/self/statm") as handle:
            return int(handle.read().split()[1]) * resource.getpagesize() / 2**20
    except (OSError, IndexError, ValueError):
        return 0.0


def _peak_mb() -> float:
    own = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    children = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    return max(own, children) / 1024.0


def run_case(case, folder: Path, *, time_bound: float) -> Outcome:
    """Run one fuzzed command line in `folder` (emptied first) through the real click group."""
    import shutil

    from click.testing import CliRunner

    from fabrication.cli import main

    kind, data, command, extra = case
    for old in folder.iterdir():
        shutil.rmtree(old) if old.is_dir() else old.unlink()
    source = folder / f"in{KINDS[kind][0] if kind != 'options' else SUFFIX_OF.get(command, '.svg')}"
    if kind == "edits":
        (folder / "edits.json").write_bytes(data)
        data = _good_png()
    elif data is None:
        data = GCODE_JOB if source.suffix == ".gcode" else GOOD_SVG.encode()
    source.write_bytes(data)
    args, outputs = _command_line(kind, command, list(extra), source, folder)

    def alarm(signum, frame):
        raise Hang()

    peak_before, resident_before = _peak_mb(), _resident_mb()
    previous = signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, time_bound)
    started = time.perf_counter()
    hung, code, trace, message = False, None, None, ""
    try:
        result = CliRunner().invoke(main, args)
        code = result.exit_code
        message = (result.output.strip().splitlines() or [""])[-1]
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
    inputs = {source.name, "edits.json"}
    made = sorted(p.name for p in folder.iterdir() if p.name not in inputs and p.name != "batch-out")
    leftovers = [m for m in made if code != 0 or m.endswith(".part") or m.startswith(".")]
    if code == 0:
        leftovers += [f"missing {p.name}" for p in outputs if not p.exists()]  # an incomplete set
    return Outcome(code, trace, hung, tuple(leftovers), seconds, _peak_mb(), peak_before, message,
                   resident_before)


SUFFIX_OF = {"stream": ".gcode"}

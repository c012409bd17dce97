"""An SVG file's XML, read once with bounds, as the bytes svgelements then parses.

`svg_source` reads the file (gzip-compressed `.svgz` too), parses it with the XML parser's
own event stream and, before svgelements expands anything, checks what the drawing would
cost once every `<use>` is replaced by what it refers to (svgelements inlines each
reference while it parses, so 21 nested `<use>` doubling each other become 2**21 paths):

- <use> references may add at most `GROWTH` (10) times the elements and path-data numbers
  of the document as written (at least `ADDED_ELEMENTS` and `ADDED_NUMBERS`); expanded, it
  may hold at most `MAX_SVG_BYTES` of attributes and text (what a plain file may hold) and
  nest at most `MAX_NESTING` deep; no reference may lead back to itself;
- comments, processing instructions and elements that draw nothing (`<metadata>`,
  `<title>`, `<desc>`, `<script>`, other tools' elements) are dropped.

The cost is summed over the reference graph in one pass (each element once, its sum reused
by every reference to it), so the refusal takes milliseconds however large the expansion.

Why the bytes go to the parsers in large pieces: the expat bundled here (2.5) scans a token
that spans several `feed` calls again from its start at every call (expat 2.6 defers that).
`xml.etree.ElementTree.parse` feeds 64 KiB and `iterparse`, which svgelements uses, 16 KiB at
a time, so a 16 MB comment took 22 s and a 60 MB one minutes. Pieces of `CHUNK` bytes make
that rescanning negligible (a 200 MB token is scanned ~13 times instead of ~12,000).
"""

from __future__ import annotations

import gzip
import io
import os
import re
import xml.etree.ElementTree as ET

from onestroke.errors import InputError
from onestroke.progress import ProgressCallback, Stage

SVG_NS = "http://www.w3.org/2000/svg"
XHTML_NS = "http://www.w3.org/1999/xhtml"
XLINK_HREF = "{http://www.w3.org/1999/xlink}href"
MAX_SVG_BYTES = 200_000_000  # a 200 MB SVG is far past any drawing; refuse before parsing
# What <use> references may add to the drawing as written: at most GROWTH times its own
# elements and path-data numbers, and never less than the ADDED_* allowances. svgelements
# makes each element and segment in Python and the commands work per stroke (embroider:
# ~9 ms a stroke, 2,000 strokes in 17 s on 2 cores at load 9), so a small file may not
# become a huge drawing; 21 nested <use> doubling each other add 2 million paths.
GROWTH = 10
ADDED_ELEMENTS = 1_000
ADDED_NUMBERS = 20_000  # a segment takes one to six numbers
MAX_NESTING = 200  # elements inside elements, references followed (svgelements recurses per level)
CHUNK = 16 * 1024 * 1024  # bytes per parser feed: see the module's note on expat
GZIP_MAGIC = b"\x1f\x8b"
# Namespaces a human meant as SVG's: http or https, www or not, with or without a final slash.
_SVG_LIKE = re.compile(r"^(https?://)?(www\.)?w3\.org/2000/svg/?$", re.IGNORECASE)
_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
# SVG elements that draw nothing and may be large (embedded RDF, scripts, long descriptions).
NOT_DRAWN = frozenset({"metadata", "title", "desc", "script"})


def _local(tag) -> str:
    return tag.rsplit("}", 1)[-1] if isinstance(tag, str) else ""


def _namespace(tag) -> str | None:
    return tag[1:].split("}", 1)[0] if isinstance(tag, str) and tag.startswith("{") else None


def read_svg_bytes(path: str) -> bytes:
    """The file's bytes, gunzipped when it is gzip-compressed (.svgz), at most MAX_SVG_BYTES."""
    too_large = f"SVG {path!r} is over {MAX_SVG_BYTES // 1_000_000} MB; too large to read"
    if os.path.getsize(path) > MAX_SVG_BYTES:
        raise InputError(too_large)
    with open(path, "rb") as handle:
        data = handle.read(MAX_SVG_BYTES + 1)
    if not data.startswith(GZIP_MAGIC):
        return data
    try:
        with gzip.GzipFile(fileobj=io.BytesIO(data)) as unpacked:
            data = unpacked.read(MAX_SVG_BYTES + 1)
    except (OSError, EOFError) as error:
        raise InputError(f"cannot read SVG {path!r}: it is gzip-compressed (.svgz) but damaged ({error})") from None
    if len(data) > MAX_SVG_BYTES:
        raise InputError(f"SVG {path!r} unpacks to over {MAX_SVG_BYTES // 1_000_000} MB; too large to read")
    return data


def _parse(data: bytes, path: str, progress: ProgressCallback | None) -> tuple[ET.Element, bool]:
    """The element tree (comments and processing instructions left out, as ElementTree does)
    and whether the file had any; refuses nesting beyond MAX_NESTING while it reads."""
    parser = ET.XMLPullParser(events=("start", "end", "comment", "pi"))
    report = Stage(progress, "reading XML", len(data), "bytes")
    depth, dropped, root = 0, False, None
    try:
        for offset in range(0, max(len(data), 1), CHUNK):
            parser.feed(data[offset:offset + CHUNK])
            for event, element in parser.read_events():
                if event == "start":
                    depth += 1
                    if depth > MAX_NESTING:
                        raise InputError(f"SVG {path!r} nests elements more than {MAX_NESTING} deep (at "
                                         f"<{_local(element.tag)}>); no drawing needs that")
                    root = element if root is None else root
                elif event == "end":
                    depth -= 1
                else:
                    dropped = True
            report.set(offset + CHUNK)
        parser.close()
    except ET.ParseError as error:
        raise InputError(f"cannot read SVG {path!r}: not well-formed XML ({error})") from None
    report.finish()
    if root is None:
        raise InputError(f"cannot read SVG {path!r}: it holds no XML element")
    return root, dropped


def _drop_not_drawn(svg: ET.Element) -> bool:
    """Remove the elements that draw nothing (NOT_DRAWN in SVG's namespace, and elements of
    other namespaces but XHTML's, e.g. Inkscape's `sodipodi:namedview`); True if any went."""
    removed = False
    stack = [svg]
    while stack:
        parent = stack.pop()
        for child in list(parent):
            namespace = _namespace(child.tag)
            if not isinstance(child.tag, str) or (namespace == SVG_NS and _local(child.tag) in NOT_DRAWN) or \
                    (namespace not in (None, SVG_NS, XHTML_NS)):
                parent.remove(child)
                removed = True
            else:
                stack.append(child)
    return removed


def _reference(element: ET.Element, ids: dict[str, ET.Element]) -> ET.Element | None:
    """What a <use> refers to, found as svgelements finds it (href over xlink:href, '#id')."""
    if element.tag != f"{{{SVG_NS}}}use":
        return None
    url = element.get("href", element.get(XLINK_HREF))
    return ids.get(url[1:]) if url else None


def _own_cost(element: ET.Element) -> tuple[int, int]:
    """(bytes of attributes and text, numbers in its path data) of one element."""
    size = len(element.tag) + len(element.text or "") + sum(len(k) + len(v) for k, v in element.attrib.items())
    data = element.get("d") or element.get("points")
    return size, (_NUMBER.subn("", data)[1] if data else 0)


def check_expansion(svg: ET.Element, path: str) -> tuple[int, int]:
    """(elements, path-data numbers) that `svg`'s <use> references add once expanded,
    computed without expanding: each element's sums once, reused by every reference to it.
    `InputError` when a budget (see GROWTH; MAX_SVG_BYTES, MAX_NESTING) is passed or a
    reference loops."""
    own = {id(element): _own_cost(element) for element in svg.iter()}
    limits = (max(ADDED_ELEMENTS, GROWTH * len(own)), max(ADDED_NUMBERS, GROWTH * sum(n for _, n in own.values())))
    ids = {element.get("id"): element for element in svg.iter() if element.get("id") is not None}
    busy = object()  # an element whose sums are being computed: meeting it again is a loop
    # id(element) -> (elements, bytes, numbers, depth) expanded, and (elements, numbers) as written
    sums: dict[int, object] = {}
    stack: list[tuple[ET.Element, bool]] = [(svg, False)]
    while stack:
        element, children_done = stack.pop()
        key = id(element)
        target = _reference(element, ids)
        if not children_done:
            state = sums.get(key)
            if state is busy:
                raise InputError(f"SVG {path!r}: <{_local(element.tag)} id={element.get('id')!r}> refers to itself "
                                 "through <use> (a reference loop)")
            if state is not None:
                continue
            sums[key] = busy
            stack.append((element, True))
            stack.extend((child, False) for child in element)
            if target is not None:
                stack.append((target, False))
            continue
        children = [sums[id(child)] for child in element]
        parts = children + ([sums[id(target)]] if target is not None else [])
        size, numbers = own[key]
        expanded = (1 + sum(p[0] for p in parts), size + sum(p[1] for p in parts),
                    numbers + sum(p[2] for p in parts), 1 + max((p[3] for p in parts), default=0))
        written = (1 + sum(c[4] for c in children), numbers + sum(c[5] for c in children))
        over = [(what, value, limit) for what, value, limit in (
            ("adds {:,} elements", expanded[0] - written[0], limits[0]),
            ("adds {:,} numbers of path data", expanded[2] - written[1], limits[1]),
            ("holds {:,} bytes of attributes and text", expanded[1], MAX_SVG_BYTES),
            ("nests {:,} levels deep", expanded[3], MAX_NESTING)) if value > limit]
        if over:
            what, value, limit = over[0]
            name = f"<{_local(element.tag)}" + (f" id={element.get('id')!r}>" if element.get("id") else ">")
            raise InputError(f"SVG {path!r}: {name} {what.format(value)} once its <use> references are expanded, "
                             f"over the limit of {limit:,} ({GROWTH} times the drawing as written, at least "
                             f"{ADDED_ELEMENTS:,} elements and {ADDED_NUMBERS:,} numbers); unlink the clones "
                             "(flatten) or simplify the drawing")
        sums[key] = expanded + written
    root = sums[id(svg)]
    return root[0] - root[4], root[2] - root[5]


def svg_source(path: str, *, progress: ProgressCallback | None = None) -> bytes:
    """The bytes of `path`'s drawing as svgelements should parse them: the file itself when
    its root is a standard <svg> and nothing needs dropping; else its first <svg> element
    (inside XHTML or any wrapper), its SVG-like namespaces made the standard one, without
    comments and elements that draw nothing. Bounds: see the module's docstring."""
    data = read_svg_bytes(path)
    root, dropped = _parse(data, path, progress)
    if root.tag == f"{{{SVG_NS}}}svg":
        svg, renamed = root, False
    else:
        svg = next((element for element in root.iter() if _local(element.tag) == "svg"), None)
        if svg is None:
            raise InputError(f"{path!r} holds no <svg> element (its root is <{_local(root.tag)}>)")
        for element in svg.iter():
            namespace = _namespace(element.tag)
            if namespace is None or _SVG_LIKE.match(namespace) or namespace == XHTML_NS:
                element.tag = f"{{{SVG_NS}}}{_local(element.tag)}"
        renamed = True
    dropped = _drop_not_drawn(svg) or dropped
    check_expansion(svg, path)
    return ET.tostring(svg) if renamed or dropped else data


class ChunkReader:
    """`data` as a binary file whose `read` hands out CHUNK bytes however few are asked for
    (see the module's note on expat), reporting each piece to `report` if given."""

    def __init__(self, data: bytes, report: Stage | None = None) -> None:
        self.data, self.offset, self.report = data, 0, report

    def read(self, size: int = -1) -> bytes:
        piece = self.data[self.offset:self.offset + max(size, CHUNK)] if size >= 0 else self.data[self.offset:]
        self.offset += len(piece)
        if self.report is not None:
            self.report.advance(len(piece))
        return piece

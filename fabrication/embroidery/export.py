"""Write a `StitchPlan` as .pes/.dst/.jef/.exp/.vp3 through pyembroidery, atomically.

We hand pyembroidery integer 0.1 mm coordinates (VP3 truncates floats; the other formats
round them) of a plan that already respects the format's stitch limit, and we do the
encoder's remaining job ourselves, in numpy: split jumps longer than the format's jump
record and land a jump on the first needle point where the format wants one. Then
pyembroidery writes with `encode: False`: no stitch can become a jump, every format reads
back exactly, and its pure-Python encoder (a third of the write time) is skipped. The
.pes/.pec thumbnails are drawn by `pec_thumbnail` (same bytes, vectorised).
Per-format numbers and writer settings (PES version, JEF trims) come from the profile.
The bytes depend on the plan alone: the design name, the JEF date (pyembroidery would
stamp the current time), the JEF hoop code and the PES hoop fields come from the plan,
not from the clock or the design's extent (pyembroidery always writes a 130x180 hoop
indicator into .pes, and 100x100 mm into version 6's hoop size).
"""

from __future__ import annotations

import io
import os

import numpy as np
import pyembroidery

from fabrication.embroidery.pec_thumbnail import fast_pec_thumbnails
from fabrication.embroidery.plan import COLOR, JUMP, STITCH, TRIM, StitchPlan
from machines.hoops import EmbroideryFormat, format_for_path
from onestroke.atomic import atomic_write_bytes
from onestroke.errors import FabricationError, InputError

_COMMANDS = np.array([pyembroidery.STITCH, pyembroidery.JUMP, pyembroidery.TRIM,
                      pyembroidery.COLOR_CHANGE])
# JEF hoop codes (pyembroidery's JefWriter constants) and their sewing fields in mm,
# smallest first: the code written is the smallest field holding the plan's hoop.
JEF_HOOPS = ((1, 50.0, 50.0), (0, 110.0, 110.0), (3, 126.0, 110.0), (2, 140.0, 200.0), (4, 200.0, 200.0))
_JEF_HOOP_OFFSET = 0x20  # int32 after the offsets, 0x14, the date, 2 pad bytes and 2 counts
PES_VERSIONS = (1, 6)
# PES header (libpes' description of PE-Design's files): after "#PES0001"/"#PES0060" and
# the PEC offset, a u16 hoop size indicator (0: 100x100 mm, 1: 130x180 mm and larger).
# Version 6 then has 2 characters, five length-prefixed strings, two u16 flags and the hoop
# size in mm (u16 width, u16 height).
_PES_HOOP_INDICATOR = 12
SMALL_PES_HOOP = (100.0, 100.0)


def check_pes_version(version, extension: str) -> int | None:
    """`version` (None: the default, 6) when it suits a file of `extension` ("pes", ...)."""
    if version is None:
        return None
    if extension != "pes":
        raise InputError(f"--pes-version applies to .pes output only, not .{extension}")
    if isinstance(version, bool) or version not in PES_VERSIONS:
        raise InputError(f"--pes-version {version} is not supported; use 1 or 6")
    return int(version)


def plan_units(plan: StitchPlan) -> np.ndarray:
    """Plan points as integer 0.1 mm units (N, 2); exact for a plan on the 0.1 mm grid."""
    return np.rint(plan.points * 10.0).astype(np.int64)


def normalized_rows(plan: StitchPlan, fmt: EmbroideryFormat) -> np.ndarray:
    """Rows (M, 3) int64 of x, y (0.1 mm) and our kind (STITCH/JUMP/TRIM) ready for `fmt`:
    the needle starts at the origin, jumps are split into records of at most
    `fmt.max_jump` per axis, and full-jump formats get a jump onto the first needle point."""
    units = plan_units(plan)
    # A virtual jump from the origin onto the first row leads the design in.
    points = np.vstack([units[:1], units])
    kinds = np.concatenate([[JUMP], plan.kinds]).astype(np.int64)
    prev = np.vstack([[0, 0], points[:-1]])
    delta = points - prev
    max_jump = int(np.floor(fmt.max_jump * 10 + 1e-9))
    steps = np.where(kinds == JUMP, -(-np.abs(delta).max(axis=1) // max_jump), 1)
    steps = np.maximum(steps, 1)
    owner = np.repeat(np.arange(len(points)), steps)
    k = np.arange(owner.size) - np.repeat(np.cumsum(steps) - steps, steps) + 1
    frac = k / steps[owner]
    out = prev[owner] + np.rint(delta[owner] * frac[:, None]).astype(np.int64)
    rows = np.column_stack([out, kinds[owner]])
    lead_end = int(steps[0]) - 1  # the lead-in's landing record
    if not fmt.full_jump or not delta[0].any():
        rows = np.delete(rows, lead_end, axis=0)
    return rows


def design_name(plan: StitchPlan) -> str:
    """The name files store: printable ASCII (fixed-width headers count bytes, not
    characters), at most 16 characters (the DST label field)."""
    text = "".join(c if 32 <= ord(c) < 127 else "_" for c in plan.name).strip()
    return (text or "onestroke")[:16]


def to_pattern(plan: StitchPlan, fmt: EmbroideryFormat) -> pyembroidery.EmbPattern:
    """A pyembroidery pattern of `plan` for `fmt`: its threads, normalized rows, END."""
    pattern = pyembroidery.EmbPattern()
    for thread in plan.threads:
        emb = pyembroidery.EmbThread()
        emb.set_color(*thread.color)
        emb.description = thread.name or "onestroke {}".format(thread.hex)
        if thread.number is not None:
            emb.catalog_number = thread.number
            emb.brand = emb.chart = thread.chart
        pattern.add_thread(emb)
    pattern.metadata("name", design_name(plan))
    rows = normalized_rows(plan, fmt)
    rows[:, 2] = _COMMANDS[rows[:, 2]]
    rows = rows.tolist()
    rows.append([rows[-1][0], rows[-1][1], pyembroidery.END])
    pattern.stitches = rows
    return pattern


def jef_hoop_code(plan: StitchPlan) -> int | None:
    """JEF hoop code of the smallest JEF field that holds the plan's hoop (either way
    round); None when the plan names no hoop or no JEF field holds it (pyembroidery's
    choice by the design's extent stands)."""
    if plan.field is None:
        return None
    w, h = plan.field
    for code, fw, fh in JEF_HOOPS:
        if (w <= fw + 1e-9 and h <= fh + 1e-9) or (h <= fw + 1e-9 and w <= fh + 1e-9):
            return code
    return None


def pes_hoop_fields(data: bytes, field: tuple[float, float]) -> bytes:
    """`data` (a .pes file as pyembroidery writes it) with its hoop fields saying `field`
    (width, height) mm: the indicator 0 when it fits 100x100 mm, else 1; in version 6
    also the hoop size in whole mm."""
    w, h = field
    small = w <= SMALL_PES_HOOP[0] + 1e-9 and h <= SMALL_PES_HOOP[1] + 1e-9
    out = bytearray(data)
    out[_PES_HOOP_INDICATOR:_PES_HOOP_INDICATOR + 2] = (0 if small else 1).to_bytes(2, "little")
    if bytes(out[:8]) == b"#PES0060":
        at = _PES_HOOP_INDICATOR + 2 + 2  # the indicator, then 2 characters ("02")
        for _ in range(5):  # name, category, author, keywords, comments
            at += 1 + out[at]
        at += 4  # "optimize hoop change", "design page is custom"
        size = int(round(w)).to_bytes(2, "little") + int(round(h)).to_bytes(2, "little")
        out[at:at + 4] = size
    return bytes(out)


def _vp3_layout(data: bytes) -> tuple[int, list[int]]:
    """Byte offsets in a .vp3 file (as pyembroidery writes it: big-endian blocks tagged
    00 0N 00 with a length) of the design's centre and of each colour block's start."""
    def skip_string(at: int) -> int:  # a length-prefixed string
        return at + 2 + int.from_bytes(data[at:at + 2], "big")

    at = skip_string(6)  # "%vsm%", 0, the producer
    at = skip_string(at + 7)  # 00 02 00, length, settings
    at += 16 + 4 + 4 + 1 + 7  # extents, count, 4 bytes, designs; 00 03 00, length
    centre = at
    at = skip_string(at + 8 + 3 + 16 + 8)  # centre, 3 bytes, extents, size; notes
    at = skip_string(at + 2 + 16 + 6)  # "dd", four int32, "xxPP\x01\x00"; producer
    count = int.from_bytes(data[at:at + 2], "big")
    at += 2
    starts = []
    for _ in range(count):
        starts.append(at + 7)
        at += 7 + int.from_bytes(data[at + 3:at + 7], "big")
    return centre, starts


def vp3_exact_block_starts(data: bytes, rows: np.ndarray) -> bytes:
    """`data` (a .vp3 file pyembroidery wrote from `rows` (M, 3): x, y in 0.1 mm and our
    kinds) with each colour block after the first starting where the thread left off.
    pyembroidery truncates the design's centre and each start measured from it, so with a
    centre on half a unit the next colour was sewn 0.1 mm off."""
    centre, starts = _vp3_layout(data)
    cx = int.from_bytes(data[centre:centre + 4], "big", signed=True) // 100
    cy = -int.from_bytes(data[centre + 4:centre + 8], "big", signed=True) // 100
    out = bytearray(data)
    for at, (x, y) in zip(starts[1:], rows[rows[:, 2] == COLOR, :2].tolist()):
        out[at:at + 8] = ((x - cx) * 100).to_bytes(4, "big", signed=True) + \
            (-(y - cy) * 100).to_bytes(4, "big", signed=True)
    return bytes(out)


def writer_settings(plan: StitchPlan, fmt: EmbroideryFormat, *, pes_version: int | None = None) -> dict:
    """pyembroidery writer settings for `plan` in `fmt` (the profile's, the JEF date)."""
    settings = {**fmt.settings}
    if fmt.extension == "jef":
        settings["date"] = plan.date
    if pes_version is not None:
        settings["pes version"] = pes_version
    return settings


def check_plan_fits_format(plan: StitchPlan, fmt: EmbroideryFormat) -> None:
    """Raise `FabricationError` if a needle-down stitch exceeds the format's per-axis limit
    (pyembroidery would silently turn it into jumps)."""
    a, b = plan.stitches()
    if len(a):
        longest = float(np.abs(b - a).max()) if len(a) else 0.0
        if longest > fmt.max_stitch + 1e-9:
            raise FabricationError(f"a {longest:.1f} mm stitch exceeds the {fmt.max_stitch:g} mm "
                                   f"limit of {fmt.name}; plan with max_stitch={fmt.max_stitch:g}")


def embroidery_bytes(plan: StitchPlan, fmt: EmbroideryFormat, *, pes_version: int | None = None) -> bytes:
    """The file content of `plan` in format `fmt`."""
    check_pes_version(pes_version, fmt.extension)
    settings = {**writer_settings(plan, fmt, pes_version=pes_version), "encode": False}
    check_plan_fits_format(plan, fmt)
    if plan.color_changes + 1 > fmt.max_colors:
        raise FabricationError(f"{plan.color_changes + 1} threads exceed the {fmt.max_colors} "
                               f"colours {fmt.name} holds")
    writer = getattr(pyembroidery, f"write_{fmt.extension}")
    pattern = to_pattern(plan, fmt)
    buffer = io.BytesIO()
    with fast_pec_thumbnails():  # identical bytes, 40 % less .pes write time
        writer(pattern, buffer, settings)
    data = buffer.getvalue()
    if fmt.extension == "vp3" and plan.color_changes:
        data = vp3_exact_block_starts(data, normalized_rows(plan, fmt))
    if fmt.extension == "pes" and plan.field is not None:
        data = pes_hoop_fields(data, plan.field)
    code = jef_hoop_code(plan) if fmt.extension == "jef" else None
    if code is not None:
        # pyembroidery picks the code from the design's extent; the user named the hoop.
        data = data[:_JEF_HOOP_OFFSET] + int(code).to_bytes(4, "little") + data[_JEF_HOOP_OFFSET + 4:]
    return data


def write_embroidery(plan: StitchPlan, path: str | os.PathLike, *, pes_version: int | None = None) -> None:
    """Write `plan` to `path` in the format of its extension, atomically."""
    fmt = format_for_path(path)
    atomic_write_bytes(path, embroidery_bytes(plan, fmt, pes_version=pes_version))


__all__ = ["write_embroidery", "embroidery_bytes", "to_pattern", "plan_units", "writer_settings",
           "jef_hoop_code", "pes_hoop_fields", "STITCH", "JUMP", "TRIM", "COLOR"]

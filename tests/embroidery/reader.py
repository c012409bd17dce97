"""A second reader of the five embroidery formats we write, for the tests: decoded here
from the formats' published layouts (Tajima DST, Melco EXP, Janome JEF, Brother PEC inside
PES, Viking/Pfaff VP3), sharing no code with pyembroidery, so that a file both readers see
the same way is not merely a file pyembroidery agrees with itself about.

`read_stitches(path)` -> `Decoded`: absolute positions in 0.1 mm (+y down, as the rest of
the project) of every record, and what each record is.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from pathlib import Path

import numpy as np

STITCH, JUMP, TRIM, COLOR = "stitch", "jump", "trim", "color"


@dataclass(frozen=True)
class Decoded:
    """points (N, 2) int, 0.1 mm, +y down; kinds (N,) one of STITCH/JUMP/TRIM/COLOR."""

    points: np.ndarray
    kinds: tuple[str, ...]

    @property
    def needles(self) -> np.ndarray:
        """(S, 2) positions of the needle-down records."""
        mask = np.array([k == STITCH for k in self.kinds], dtype=bool)
        return self.points[mask] if len(mask) else np.zeros((0, 2), dtype=np.int64)

    def count(self, kind: str) -> int:
        return sum(k == kind for k in self.kinds)


class _Track:
    """Accumulates relative moves into absolute records."""

    def __init__(self, x: int = 0, y: int = 0) -> None:
        self.x, self.y = x, y
        self.points: list[tuple[int, int]] = []
        self.kinds: list[str] = []

    def move(self, dx: int, dy: int, kind: str) -> None:
        self.x += dx
        self.y += dy
        self.add(kind)

    def add(self, kind: str) -> None:
        self.points.append((self.x, self.y))
        self.kinds.append(kind)

    def done(self) -> Decoded:
        return Decoded(np.array(self.points, dtype=np.int64).reshape(-1, 2), tuple(self.kinds))


def _signed8(b: int) -> int:
    return b - 256 if b > 127 else b


# Tajima DST: a 512-byte header, then 3-byte records; each bit adds a power of 3 to x or
# y (+y up); byte 2's top bits say jump (0x83), colour change (0xC3) or end (0xF3).
_DST_BITS = (  # (byte, bit, axis, value)
    (0, 0, 0, 1), (0, 1, 0, -1), (0, 2, 0, 9), (0, 3, 0, -9),
    (0, 7, 1, 1), (0, 6, 1, -1), (0, 5, 1, 9), (0, 4, 1, -9),
    (1, 0, 0, 3), (1, 1, 0, -3), (1, 2, 0, 27), (1, 3, 0, -27),
    (1, 7, 1, 3), (1, 6, 1, -3), (1, 5, 1, 27), (1, 4, 1, -27),
    (2, 2, 0, 81), (2, 3, 0, -81), (2, 5, 1, 81), (2, 4, 1, -81),
)


def read_dst(data: bytes) -> Decoded:
    track = _Track()
    for at in range(512, len(data) - 2, 3):
        record = data[at:at + 3]
        if record[2] & 0xF3 == 0xF3:
            break
        d = [0, 0]
        for byte, bit, axis, value in _DST_BITS:
            if record[byte] >> bit & 1:
                d[axis] += value
        kind = COLOR if record[2] & 0xC3 == 0xC3 else JUMP if record[2] & 0x83 == 0x83 else STITCH
        track.move(d[0], -d[1], kind)
    return track.done()


def read_exp(data: bytes) -> Decoded:
    """Melco EXP: 2 signed bytes per stitch (+y up); 0x80 escapes: 0x01 colour change,
    0x04 jump (the move follows), 0x80 trim (2 bytes of payload)."""
    track = _Track()
    at = 0
    while at + 1 < len(data):
        if data[at] == 0x80:
            code = data[at + 1]
            dx, dy = _signed8(data[at + 2]), _signed8(data[at + 3])
            at += 4
            if code == 0x01:
                track.move(dx, -dy, COLOR)
            elif code == 0x80:
                track.add(TRIM)
            else:
                track.move(dx, -dy, JUMP)
            continue
        track.move(_signed8(data[at]), -_signed8(data[at + 1]), STITCH)
        at += 2
    return track.done()


def read_jef(data: bytes) -> Decoded:
    """Janome JEF: the stitches start at the offset in the first int32; 2 signed bytes per
    stitch (+y up); 0x80 escapes: 0x01 colour change, 0x02 move (three in place: a trim),
    0x10 end."""
    track = _Track()
    at = struct.unpack_from("<i", data, 0)[0]
    still = 0  # moves in place in a row
    while at + 1 < len(data):
        if data[at] == 0x80:
            code = data[at + 1]
            if code == 0x10:
                break
            dx, dy = _signed8(data[at + 2]), _signed8(data[at + 3])
            at += 4
            if code == 0x01:
                track.move(dx, -dy, COLOR)
            elif dx == 0 and dy == 0:
                still += 1
                if still == 3:
                    track.add(TRIM)
                    still = 0
            else:
                track.move(dx, -dy, JUMP)
            continue
        still = 0
        track.move(_signed8(data[at]), -_signed8(data[at + 1]), STITCH)
        at += 2
    return track.done()


def read_pes(data: bytes) -> Decoded:
    """The PEC section of a PES file (its offset at byte 8): after a 512-byte header and
    a 16-byte block header, x then y per record (+y down): one byte, 7-bit signed; or two
    bytes with the top bit set, 12-bit signed, flag 0x20 trim, 0x10 jump. 0xFE 0xB0 and a
    byte: colour change; 0xFF: end."""
    pec = struct.unpack_from("<I", data, 8)[0]
    at = pec + 512 + 16
    track = _Track()

    def value(at: int) -> tuple[int, int, int]:
        b = data[at]
        if b & 0x80:
            v = (b & 0x0F) << 8 | data[at + 1]
            return (v - 0x1000 if v & 0x800 else v), b & 0x30, at + 2
        return (b - 0x80 if b & 0x40 else b), 0, at + 1

    while at < len(data):
        if data[at] == 0xFF:
            break
        if data[at] == 0xFE and data[at + 1] == 0xB0:
            track.add(COLOR)
            at += 3
            continue
        dx, fx, at = value(at)
        dy, fy, at = value(at)
        flags = fx | fy
        if flags & 0x20:
            track.add(TRIM)
        track.move(dx, dy, JUMP if flags else STITCH)
    return track.done()


def read_vp3(data: bytes) -> Decoded:
    """Viking VP3 (big-endian): "%vsm%", then blocks tagged 00 0N 00 with a length; the design block holds
    its centre (1/1000 mm, +y up), each colour block its start from the centre, its thread
    and a stitch block: 2 signed bytes per stitch (+y down, 0.1 mm), 0x80 0x01 + two int16
    a long stitch (0x80 0x02 closes it), 0x80 0x03 a trim. Colour blocks move to their
    start without a stitch."""

    def string16(at: int) -> int:  # skips a length-prefixed string
        return at + 2 + struct.unpack_from(">H", data, at)[0]

    assert data[:5] == b"%vsm%", "not a VP3 file"
    at = string16(6)  # "%vsm%", 0, the producer
    assert data[at:at + 3] == b"\x00\x02\x00", "no file block"
    at = string16(at + 7)  # 00 02 00, length, settings
    at += 16 + 4 + 4  # extents, stitch count, 4 bytes (0, blocks, 12, 0)
    at += 1  # number of designs
    assert data[at:at + 3] == b"\x00\x03\x00", "no design block"
    at += 3 + 4
    centre_x, centre_y = struct.unpack_from(">ii", data, at)
    at += 8 + 3 + 16 + 8  # centre, 3 bytes, extents, width and height
    at = string16(at)
    at += 2 + 16 + 6  # "dd", four int32, "xxPP\x01\x00"
    at = string16(at)
    blocks = struct.unpack_from(">H", data, at)[0]
    at += 2
    track = _Track()
    for block in range(blocks):
        assert data[at:at + 3] == b"\x00\x05\x00", "no colour block"
        end = at + 7 + struct.unpack_from(">I", data, at + 3)[0]
        start_x, start_y = struct.unpack_from(">ii", data, at + 7)
        at += 15
        at += 2 + 3 + 5  # 01 00, RGB, parts, length, weight
        for _ in range(3):  # catalogue number, description, brand
            at = string16(at)
        at += 8  # the block's shift
        if block:
            track.add(COLOR)
            track.x, track.y = (start_x + centre_x) // 100, -(start_y + centre_y) // 100
        assert data[at:at + 3] == b"\x00\x01\x00", "no stitch block"
        stop = at + 7 + struct.unpack_from(">I", data, at + 3)[0]
        at += 7 + 3  # header, 0A F6 00
        while at < stop:
            if data[at] == 0x80:
                code = data[at + 1]
                if code == 0x01:
                    dx, dy = struct.unpack_from(">hh", data, at + 2)
                    track.move(dx, dy, STITCH)
                    at += 8  # the two int16 and 0x80 0x02
                elif code == 0x03:
                    track.add(TRIM)
                    at += 2
                else:
                    at += 2
                continue
            track.move(_signed8(data[at]), _signed8(data[at + 1]), STITCH)
            at += 2
        at = end
    return track.done()


READERS = {"dst": read_dst, "exp": read_exp, "jef": read_jef, "pes": read_pes, "vp3": read_vp3}


def read_stitches(path: str | Path) -> Decoded:
    """Decode `path` by its extension."""
    path = Path(path)
    return READERS[path.suffix.lower().lstrip(".")](path.read_bytes())

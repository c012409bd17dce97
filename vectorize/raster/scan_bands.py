"""Shrinking a huge scan by an integer factor a band of rows at a time (issue 14: scans up to
300 Mpx are read downscaled without holding the full image in memory).

A non-interlaced PNG is streamed: Pillow's own "zip" decoder (which unfilters the rows and
keeps the previous row and the inflate state between calls) is fed one band of rows at a
time and writes into a full-size canvas that is only reserved address space (an anonymous
private memory map); each band is box-averaged (`Image.reduce`) as soon as it is complete
and its pages are handed back to the OS (madvise DONTNEED). Peak memory is then one band
(`BAND_BYTES`) plus the reduced image, whatever the input size.

To know exactly which rows the decoder has written, the compressed data is inflated here
with zlib and forwarded to the decoder band by band re-wrapped as stored (level 0) deflate
blocks: the decoder then has every row of a band the moment it is given it. Filtering,
unpacking and bit depths stay Pillow's. (A band-sized target per band is not possible:
the decoder's row counter, previous row and inflate state live with the one target it is
given, and calling `setimage` again would leak and undersize its row buffer.)

Everything else (TIFF, whose compressed strips Pillow only decodes all at once through
libtiff; interlaced PNG; BMP, GIF, WebP) is decoded whole in its native mode (one byte a
pixel for 1-bit and gray, four for colour) and converted and reduced band by band, so no
full-size copy in another mode is ever made.

The result equals what converting the whole image and reducing it gives, byte for byte:
bands are whole multiples of the factor tall and every step is per pixel or per box.
"""

from __future__ import annotations

import mmap
import zlib
from collections.abc import Callable, Iterator

import numpy as np
from PIL import Image, PngImagePlugin

# Canvas bytes decoded before a band is reduced and released.
BAND_BYTES = 8 << 20

# PNG mode -> the mode the canvas is mapped in (same bytes a pixel as Pillow's own storage:
# "1" is one byte a pixel, "RGB" and "LA" four). Modes missing here take the generic path.
_CANVAS = {"1": "L", "L": "L", "P": "P", "RGB": "RGBX", "RGBA": "RGBA", "LA": "RGBA", "I;16": "I;16"}
_CHANNELS = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}  # PNG colour type -> samples a pixel
# PNG raw mode -> bits a pixel, from Pillow's own table of PNG bit depths and colour types.
_PNG_BITS = {raw: depth * _CHANNELS[colour] for (depth, colour), (_, raw) in PngImagePlugin._MODES.items()}


def can_stream(image: Image.Image) -> bool:
    """True when `image` (opened, not loaded) is a PNG this module can decode band by band."""
    if image.format != "PNG" or image.info.get("interlace") or getattr(image, "n_frames", 1) != 1:
        return False
    if len(image.tile) != 1 or image.tile[0][0] != "zip" or tuple(image.tile[0][1]) != (0, 0, *image.size):
        return False
    return image.mode in _CANVAS and image.tile[0][3] in _PNG_BITS and hasattr(mmap, "MADV_DONTNEED")


def band_rows(width: int, bytes_per_pixel: int, factor: int) -> int:
    """Rows per band: about `BAND_BYTES` at `bytes_per_pixel`, a whole multiple of `factor`."""
    rows = max(1, BAND_BYTES // max(1, width * bytes_per_pixel))
    return max(factor, rows // factor * factor)


def reduce_decoded(image: Image.Image, factor: int, prepare: Callable[[Image.Image], Image.Image]) -> np.ndarray:
    """`prepare(image).reduce(factor)` as an array, for a loaded image, one band at a time.

    prepare: the per-pixel conversion to the working mode (uint8 L, RGB or RGBA).
    """
    w, h = image.size
    step = band_rows(w, 4, factor)
    pieces = [np.asarray(prepare(image.crop((0, y0, w, min(h, y0 + step)))).reduce(factor))
              for y0 in range(0, h, step)]
    return np.concatenate(pieces, axis=0)


def reduce_png_stream(image: Image.Image, factor: int,
                      prepare: Callable[[Image.Image], Image.Image]) -> np.ndarray:
    """`prepare(image).reduce(factor)` as an array for a PNG that `can_stream`, decoding it
    one band at a time into released pages (see the module text). Raises OSError for a
    damaged or truncated file.
    """
    w, h = image.size
    canvas_mode = _CANVAS[image.mode]
    rawmode = image.tile[0][3]
    pixel = 1 if canvas_mode in ("L", "P") else 2 if canvas_mode == "I;16" else 4
    linesize = w * pixel
    rowbytes = 1 + (_PNG_BITS[rawmode] * w + 7) // 8  # the filter byte, then the packed row
    step = band_rows(w, 4, factor)  # a band's widest copy is RGB(A) at four bytes a pixel
    flags = mmap.MAP_PRIVATE | getattr(mmap, "MAP_NORESERVE", 0)
    try:
        memory = mmap.mmap(-1, linesize * h, flags=flags)
    except OSError as error:  # address space refused (a strict overcommit policy): memory, not the file
        raise MemoryError(f"cannot reserve {linesize * h / 1e6:.0f} MB of address space to decode "
                          f"the image in bands ({error.strerror})") from None
    canvas = Image.frombuffer(canvas_mode, (w, h), memory, "raw", canvas_mode, 0, 1)
    decoder = Image._getdecoder(image.mode, "zip", rawmode, image.decoderconfig)
    pieces = []
    try:
        decoder.setimage(canvas.im, (0, 0, w, h))
        inflater, wrapper = zlib.decompressobj(), zlib.compressobj(0)
        stream = _idat_data(image)
        page, done = mmap.PAGESIZE, False
        for y0 in range(0, h, step):
            y1 = min(h, y0 + step)
            for filtered in _inflate(inflater, stream, (y1 - y0) * rowbytes):
                done = done or _decode(decoder, wrapper.compress(filtered), last=y1 == h)
            done = done or _decode(decoder, wrapper.flush(zlib.Z_SYNC_FLUSH), last=y1 == h)
            rows = memoryview(memory)[y0 * linesize:y1 * linesize]
            band = Image.frombuffer(canvas_mode, (w, y1 - y0), rows, "raw", canvas_mode, 0, 1)
            pieces.append(_reduce_band(band, image, factor, prepare))
            del band, rows
            start = y0 * linesize // page * page
            memory.madvise(mmap.MADV_DONTNEED, start, y1 * linesize - start)
    finally:
        decoder.cleanup()
        del decoder, canvas
        try:
            memory.close()
        except BufferError:  # a view still alive (an exception's frame): freed with it
            pass
    return np.concatenate(pieces, axis=0)


def _decode(decoder, data: bytes, *, last: bool) -> bool:
    """Feed stored deflate data to Pillow's decoder. True once it has written the image's
    last row (status -1), which must be in the last band."""
    if not data:
        return False
    status, error = decoder.decode(data)
    if error < 0 or (status < 0 and not last):
        raise OSError(f"the PNG image data could not be decoded (decoder error {error})")
    return status < 0


def _reduce_band(band: Image.Image, png: Image.Image, factor: int,
                 prepare: Callable[[Image.Image], Image.Image]) -> np.ndarray:
    """`prepare(<band in the PNG's mode>).reduce(factor)` for a canvas band, as an array."""
    if png.mode in ("1", "RGB"):
        # The canvas holds 0/255 gray for "1" and RGB plus a pad byte for "RGB"; prepare makes
        # both RGB, copies or a subset of those channels: box-average first (a quarter of the
        # pixels to convert), then convert. Same numbers: reduce works channel by channel.
        return np.asarray(prepare(band.reduce(factor).convert("RGB")))
    if png.mode == "P":
        band.palette = png.palette.copy()
        band.palette.dirty = 1
        if "transparency" in png.info:
            band.info["transparency"] = png.info["transparency"]
    # "LA" bands are RGBA canvases holding (L, L, L, A): Pillow's own LA storage, and what
    # converting LA to RGBA (prepare's first step for LA) gives.
    return np.asarray(prepare(band).reduce(factor))


def _inflate(inflater, stream: Iterator[bytes], size: int, piece: int = 1 << 20) -> Iterator[bytes]:
    """The next `size` bytes of the inflated image data (filtered rows), in pieces."""
    while size > 0:
        data = inflater.unconsumed_tail or next(stream, b"")
        if not data:
            raise OSError("the PNG image data ends early")
        part = inflater.decompress(data, min(size, piece))
        if not part and inflater.eof:
            raise OSError("the PNG image data ends early")
        size -= len(part)
        yield part


def _idat_data(image: Image.Image, block: int = 1 << 20) -> Iterator[bytes]:
    """The compressed image data of an opened PNG: its IDAT chunks' contents, in order."""
    fp, png = image.fp, image.png
    fp.seek(image.tile[0][2])
    remaining = png.im_idat
    while True:
        while remaining:
            data = fp.read(min(remaining, block))
            if not data:
                return
            remaining -= len(data)
            yield data
        fp.read(4)  # the chunk's CRC
        cid, _, remaining = png.read()
        if cid != b"IDAT":
            return

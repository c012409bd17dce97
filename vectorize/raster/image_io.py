"""Loading raster images with clear errors for files that are not usable images."""

from __future__ import annotations

import os
import warnings

import numpy as np
from PIL import Image, UnidentifiedImageError

from onestroke.errors import InputError
from onestroke.paths import check_input_file
from vectorize.options import InputFrame

# Largest image read (decoded pixels): a 1200 dpi A4 scan is 139 Mpx; beyond this a file is
# refused right after its header is read, before any decoding. This check replaces Pillow's
# own decompression-bomb guard (which would speak of twice this limit), off while opening.
MAX_PIXELS = 300_000_000


def load_image(path: str | os.PathLike, *, max_size: int | None = None):
    """Read an image file as uint8 (H, W), (H, W, 3) or (H, W, 4), and its `InputFrame`.

    An image much larger than `max_size` is shrunk by an integer factor: a JPEG is decoded
    at 1/2, 1/4 or 1/8 size directly (Pillow's draft mode, never holding the full image),
    anything else box-averaged by Pillow on 8-bit data a band of rows at a time
    (`vectorize.raster.scan_bands`: a PNG is streamed and never held whole; other formats are
    held only in their native mode), so that a huge scan never needs gigabytes.
    Images over `MAX_PIXELS` are refused.
    """

    path = check_input_file(path, expect="an image")
    saved_limit = Image.MAX_IMAGE_PIXELS
    try:
        Image.MAX_IMAGE_PIXELS = None
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", Image.DecompressionBombWarning)
            with Image.open(path) as image:
                original = (image.width, image.height)
                from vectorize.raster.binarize import MIN_SIDE

                if min(original) < MIN_SIDE:  # said of the file's size, not of a downscaled copy
                    raise InputError(f"image {path!r} is {image.width}x{image.height} px: too small for a drawing "
                                     f"(need at least {MIN_SIDE} px a side)")
                if image.width * image.height > MAX_PIXELS:
                    raise InputError(f"image {path!r} is {image.width} x {image.height} px "
                                     f"({image.width * image.height:,} pixels); the largest this reads is "
                                     f"{MAX_PIXELS:,} (a 1200 dpi A4 scan is about 139,000,000): "
                                     "scan at a lower resolution")
                Image.MAX_IMAGE_PIXELS = MAX_PIXELS  # for frames or layers the plugin reads later
                factor = max(1, int(max(original) // (2 * max_size))) if max_size else 1
                drafted = 1
                if factor > 1 and image.format == "JPEG":
                    mode = image.mode if image.mode in ("L", "RGB") else "RGB"
                    image.draft(mode, (-(-image.width // factor), -(-image.height // factor)))
                    drafted = max(1, original[0] // image.width)
                rest = max(1, factor // drafted)
                if rest > 1:
                    array = _read_reduced(image, rest)
                else:
                    image.load()
                    maximum = np.asarray(image).max() if _is_deep(image) else 0.0
                    array = np.asarray(_working(image, _gray_top(image, maximum)))
                total = drafted * rest
                frame = InputFrame(1.0 / total, (0.0, 0.0), float(original[0]), float(original[1]),
                                   original if total > 1 else None)
                return array, frame
    except InputError:
        raise
    except UnidentifiedImageError:
        raise InputError(f"{path!r} is not an image Pillow can read (PNG, JPEG, BMP, GIF, TIFF, WebP) or SVG") from None
    except Image.DecompressionBombError as error:
        raise InputError(f"image {path!r} is too large to read ({error})") from None
    except (OSError, SyntaxError, ValueError, EOFError) as error:
        raise InputError(f"cannot read image {path!r}: it is damaged or truncated ({error})") from None
    finally:
        Image.MAX_IMAGE_PIXELS = saved_limit


def _read_reduced(image: Image.Image, factor: int) -> np.ndarray:
    """The working image box-averaged by `factor`, read a band at a time (vectorize.raster.scan_bands):
    a PNG streamed, anything else decoded in its native mode only."""
    # Imported here: only an image larger than twice the working size is read in bands, and a
    # command pays for every module it imports (this one brings `mmap`).
    from vectorize.raster import scan_bands

    if scan_bands.can_stream(image):  # its only deep mode is I;16, whose top needs no maximum
        return scan_bands.reduce_png_stream(image, factor, lambda band: _working(band, _gray_top(band, 0.0)))
    image.load()
    top = _gray_top(image, image.getextrema()[1] if _is_deep(image) else 0.0)
    return scan_bands.reduce_decoded(image, factor, lambda band: _working(band, top))


def _is_deep(image: Image.Image) -> bool:
    return image.mode.startswith("I") or image.mode == "F"


def _gray_top(image: Image.Image, maximum: float) -> float:
    """The value that maps to white for 16/32-bit and float gray; `maximum` is the image's."""
    if not _is_deep(image):
        return 0.0
    top = 65535.0 if image.mode.startswith("I;16") or maximum > 255 else 255.0
    return 1.0 if image.mode == "F" and maximum <= 1.0 else top


def _working(image: Image.Image, top: float) -> Image.Image:
    """`image` as 8-bit L, RGB or RGBA (per pixel; `top` from `_gray_top` for deep gray)."""
    if _is_deep(image):
        # 16/32-bit gray: keep the depth (converting to RGB would clip it at 255).
        data = np.asarray(image, dtype=np.float64)
        image = Image.fromarray(np.clip(np.round(data / top * 255.0), 0, 255).astype(np.uint8))
    if image.mode in ("RGBA", "LA") or (image.mode == "P" and "transparency" in image.info):
        return image.convert("RGBA")
    if image.mode not in ("L", "RGB"):
        return image.convert("RGB")
    return image

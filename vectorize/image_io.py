"""Loading raster images with clear errors for files that are not usable images."""

from __future__ import annotations

import os
import warnings

import numpy as np
from PIL import Image, UnidentifiedImageError

from onestroke.errors import InputError
from vectorize.options import InputFrame

# Largest image read (decoded pixels): a 1200 dpi A4 scan is 139 Mpx; beyond this a file is
# refused before decoding. Pillow's own decompression-bomb guard is raised to this limit.
MAX_PIXELS = 300_000_000


def load_image(path: str | os.PathLike, *, max_size: int | None = None):
    """Read an image file as uint8 (H, W), (H, W, 3) or (H, W, 4), and its `InputFrame`.

    An image much larger than `max_size` is shrunk by an integer factor: a JPEG is decoded
    at 1/2, 1/4 or 1/8 size directly (Pillow's draft mode, never holding the full image),
    anything else box-averaged by Pillow on 8-bit data, so that a huge scan never needs
    gigabytes as floats. Images over `MAX_PIXELS` are refused.
    """

    path = str(path)
    if not os.path.isfile(path):
        raise InputError(f"input file {path!r} does not exist")
    saved_limit = Image.MAX_IMAGE_PIXELS
    try:
        Image.MAX_IMAGE_PIXELS = MAX_PIXELS
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", Image.DecompressionBombWarning)
            with Image.open(path) as image:
                original = (image.width, image.height)
                if image.width * image.height > MAX_PIXELS:
                    raise InputError(f"image {path!r} is {image.width} x {image.height} px "
                                     f"({image.width * image.height / 1e6:.0f} Mpx); the largest this reads is "
                                     f"{MAX_PIXELS / 1e6:.0f} Mpx: scan at a lower resolution")
                factor = max(1, int(max(original) // (2 * max_size))) if max_size else 1
                drafted = 1
                if factor > 1 and image.format == "JPEG":
                    mode = image.mode if image.mode in ("L", "RGB") else "RGB"
                    image.draft(mode, (-(-image.width // factor), -(-image.height // factor)))
                    drafted = max(1, original[0] // image.width)
                image.load()
                if image.mode.startswith("I") or image.mode == "F":
                    # 16/32-bit gray: keep the depth (converting to RGB would clip it at 255).
                    data = np.asarray(image, dtype=np.float64)
                    top = 65535.0 if image.mode.startswith("I;16") or data.max() > 255 else 255.0
                    if image.mode == "F" and data.max() <= 1.0:
                        top = 1.0
                    image = Image.fromarray(np.clip(np.round(data / top * 255.0), 0, 255).astype(np.uint8))
                if image.mode in ("RGBA", "LA") or (image.mode == "P" and "transparency" in image.info):
                    image = image.convert("RGBA")
                elif image.mode not in ("L", "RGB"):
                    image = image.convert("RGB")
                rest = max(1, factor // drafted)
                if rest > 1:
                    image = image.reduce(rest)
                total = drafted * rest
                array = np.asarray(image)
                frame = InputFrame(1.0 / total, (0.0, 0.0), float(original[0]), float(original[1]),
                                   original if total > 1 else None)
                return array, frame
    except UnidentifiedImageError:
        raise InputError(f"{path!r} is not an image Pillow can read (PNG, JPEG, BMP, GIF, TIFF, WebP) or SVG") from None
    except Image.DecompressionBombError as error:
        raise InputError(f"image {path!r} is too large to read ({error})") from None
    except (OSError, SyntaxError, ValueError, EOFError) as error:
        raise InputError(f"cannot read image {path!r}: it is damaged or truncated ({error})") from None
    finally:
        Image.MAX_IMAGE_PIXELS = saved_limit

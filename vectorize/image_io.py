"""Loading raster images with clear errors for files that are not usable images."""

from __future__ import annotations

import os
import warnings

import numpy as np
from PIL import Image, UnidentifiedImageError

from onestroke.errors import InputError

# Refuse images whose decoded size would exhaust memory (e.g. a decompression bomb).
MAX_PIXELS = 200_000_000


def load_image(path: str | os.PathLike, *, max_size: int | None = None):
    """Read an image file as uint8 (H, W), (H, W, 3) or (H, W, 4), and its `InputFrame`.

    An image much larger than `max_size` is first shrunk by an integer factor (box average,
    done by Pillow on 8-bit data) so that a huge scan never needs gigabytes as floats.
    """
    from vectorize.pipeline import InputFrame

    path = str(path)
    if not os.path.isfile(path):
        raise InputError(f"input file {path!r} does not exist")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", Image.DecompressionBombWarning)
            with Image.open(path) as image:
                if image.width * image.height > MAX_PIXELS:
                    raise InputError(f"image {path!r} is {image.width}x{image.height}: too large to read")
                image.load()
                original = (image.width, image.height)
                factor = max(1, int(max(original) // (2 * max_size))) if max_size else 1
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
                if factor > 1:
                    image = image.reduce(factor)
                array = np.asarray(image)
                scale = 1.0 / factor
                frame = InputFrame(scale, (0.0, 0.0), float(original[0]), float(original[1]),
                                   original if factor > 1 else None)
                return array, frame
    except UnidentifiedImageError:
        raise InputError(f"{path!r} is not an image Pillow can read (PNG, JPEG, BMP, GIF, TIFF, WebP) or SVG") from None
    except (OSError, SyntaxError, ValueError, Image.DecompressionBombWarning, Image.DecompressionBombError) as error:
        raise InputError(f"cannot read image {path!r}: it is damaged or truncated ({error})") from None

"""Huge scans are read a band at a time (vectorize/raster/scan_bands.py): the result equals a full
decode followed by the conversion and box reduction the reader always did, and the memory
used scales with a band and the reduced image, not with the input."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from click.testing import CliRunner
from PIL import Image, ImageDraw

from fabrication.cli import main
from vectorize.raster import image_io, scan_bands


def drawing(mode: str, size=(1003, 777), seed: int = 0) -> Image.Image:
    """Seeded content with detail at every scale (noise and a pen loop), in `mode`."""
    rng = np.random.default_rng(seed)
    gray = (rng.random(size[::-1]) * 255).astype(np.uint8)
    base = Image.fromarray(gray)
    ImageDraw.Draw(base).ellipse([50, 40, size[0] - 60, size[1] - 30], outline=0, width=25)
    colour = Image.merge("RGB", (base, base.transpose(Image.Transpose.FLIP_LEFT_RIGHT),
                                 base.transpose(Image.Transpose.FLIP_TOP_BOTTOM)))
    if mode == "1":
        return base.convert("1")
    if mode == "L":
        return base
    if mode == "RGB":
        return colour
    if mode == "RGBA":
        return Image.merge("RGBA", (*colour.split(), base.transpose(Image.Transpose.ROTATE_180)))
    if mode == "LA":
        return Image.merge("LA", (base, base.transpose(Image.Transpose.FLIP_LEFT_RIGHT)))
    if mode in ("P", "P-alpha"):
        indexed = Image.frombytes("P", size, (gray % 100).tobytes())
        indexed.putpalette(rng.integers(0, 256, 300, dtype=np.uint8).tobytes())
        return indexed
    if mode == "I;16":
        return Image.fromarray(gray.astype(np.uint16) * 257 + rng.integers(0, 256, gray.shape, dtype=np.uint16))
    raise ValueError(mode)


def full_decode_reduced(path, factor: int) -> np.ndarray:
    """What the reader did before bands: decode all, convert to 8-bit L/RGB/RGBA, reduce."""
    with Image.open(path) as image:
        image.load()
        if image.mode == "I;16":
            image = Image.fromarray(np.round(np.asarray(image, dtype=np.float64) / 65535 * 255).astype(np.uint8))
        elif image.mode in ("RGBA", "LA") or (image.mode == "P" and "transparency" in image.info):
            image = image.convert("RGBA")
        elif image.mode not in ("L", "RGB"):
            image = image.convert("RGB")
        return np.asarray(image.reduce(factor))


@pytest.fixture
def calls(monkeypatch):
    """Small bands (many per image) and a record of which band reader ran."""
    monkeypatch.setattr(scan_bands, "BAND_BYTES", 1 << 16)
    seen = []
    for name in ("reduce_png_stream", "reduce_decoded"):
        real = getattr(scan_bands, name)

        def recorded(*args, _real=real, _name=name):
            seen.append(_name)
            return _real(*args)

        monkeypatch.setattr(scan_bands, name, recorded)
    return seen


@pytest.mark.parametrize("mode", ["1", "L", "RGB", "RGBA", "LA", "P", "P-alpha", "I;16"])
def test_streamed_png_equals_full_decode(tmp_path, calls, mode):
    path = tmp_path / "scan.png"
    drawing(mode).save(path, **({"transparency": 7} if mode == "P-alpha" else {}))
    array, frame = image_io.load_image(path, max_size=70)  # factor 1003 // 140 = 7
    assert calls == ["reduce_png_stream"]
    assert np.array_equal(array, full_decode_reduced(path, 7))
    assert frame.scale == pytest.approx(1 / 7) and frame.reduced_from == (1003, 777)


@pytest.mark.parametrize("mode,save", [("1", {"compression": "group4"}), ("L", {"compression": "tiff_lzw"}),
                                       ("RGB", {"compression": "tiff_deflate"}), ("RGB", {"format": "BMP"})])
def test_other_files_are_reduced_in_bands_from_their_native_mode(tmp_path, calls, mode, save):
    path = tmp_path / ("scan.bmp" if "format" in save else "scan.tif")
    drawing(mode).save(path, **save)
    array, _ = image_io.load_image(path, max_size=100)  # factor 5
    assert calls == ["reduce_decoded"]
    assert np.array_equal(array, full_decode_reduced(path, 5))


def test_small_images_take_the_direct_path(tmp_path, calls):
    path = tmp_path / "small.png"
    drawing("RGB").save(path)
    array, frame = image_io.load_image(path, max_size=1000)
    assert calls == [] and frame.reduced_from is None
    assert np.array_equal(array, np.asarray(Image.open(path)))


def test_truncated_large_png_is_refused_in_one_line(tmp_path):
    path = tmp_path / "cut.png"
    drawing("L", size=(4200, 900)).save(path)
    path.write_bytes(path.read_bytes()[: path.stat().st_size // 2])
    result = CliRunner().invoke(main, ["vectorize", str(path), "-o", str(tmp_path / "cut.svg")])
    assert result.exit_code == 2 and result.stderr.startswith("error: cannot read image")
    assert "damaged or truncated" in result.stderr and result.stderr.count("\n") == 1
    assert not (tmp_path / "cut.svg").exists()


PEAK = textwrap.dedent("""
    import sys
    from vectorize.raster import image_io
    def status(key):
        return int(next(l.split()[1] for l in open("/proc/self/status") if l.startswith(key)))
    before = status("VmRSS:")
    with open("/proc/self/clear_refs", "w") as f:  # restart the peak (VmHWM) from here
        f.write("5")
    array, frame = image_io.load_image(sys.argv[1], max_size=1000)
    print(array.shape, (status("VmHWM:") - before) // 1024)
""")


def test_a_27_megapixel_png_is_read_in_bands_within_a_band_of_memory(tmp_path):
    """6000 x 4500 RGB: 108 MB decoded (Pillow keeps RGB at four bytes a pixel); read in
    bands of 16 MB, the reader's peak is a fraction of that (measured in a child process)."""
    path = tmp_path / "scan.png"
    image = Image.new("RGB", (6000, 4500), (245, 242, 235))
    ImageDraw.Draw(image).ellipse([400, 300, 5600, 4200], outline=(20, 20, 50), width=50)
    image.save(path, compress_level=1)
    del image
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    done = subprocess.run([sys.executable, "-c", PEAK, str(path)], capture_output=True, text=True, env=env)
    assert done.returncode == 0, done.stderr
    shape, peak_mb = done.stdout.rsplit(" ", 1)
    assert shape == "(1500, 2000, 3)"
    assert int(peak_mb) < 64, done.stdout  # a full decode alone is 108 MB
    assert np.array_equal(image_io.load_image(path, max_size=1000)[0], full_decode_reduced(path, 3))


def fake_png_header(path, width: int, height: int) -> None:
    """A PNG whose header claims `width` x `height` (valid CRC), with a 1 px body."""
    import io
    import struct
    import zlib

    buffer = io.BytesIO()
    Image.new("L", (1, 1), 255).save(buffer, "PNG")
    data = bytearray(buffer.getvalue())
    data[16:24] = struct.pack(">II", width, height)
    data[29:33] = struct.pack(">I", zlib.crc32(bytes(data[12:29])))
    path.write_bytes(bytes(data))


@pytest.mark.parametrize("size", [(17321, 17321), (30000, 30000), (100000, 100000)])
def test_bomb_guard_refuses_over_300_megapixels_clearly(tmp_path, size):
    """Just over the limit, over twice it (where Pillow's own guard would have spoken of
    600 Mpx as "damaged or truncated") and absurd: one line, exit 2, nothing written."""
    path = tmp_path / "bomb.png"
    fake_png_header(path, *size)
    result = CliRunner().invoke(main, ["vectorize", str(path), "-o", str(tmp_path / "bomb.svg")])
    assert result.exit_code == 2
    assert result.stderr == (f"error: image {str(path)!r} is {size[0]} x {size[1]} px ({size[0] * size[1]:,} "
                             "pixels); the largest this reads is 300,000,000 (a 1200 dpi A4 scan is about "
                             "139,000,000): scan at a lower resolution\n")
    assert not (tmp_path / "bomb.svg").exists()

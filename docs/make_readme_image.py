"""Make examples/readme.png: the bundled drawing, its vectorized curve and its stitches
(zigzag, the embroider command's realistic preview).

    python -m docs.make_readme_image

Runs the real commands (`onestroke vectorize`, `preview`, `embroider`) on
examples/loops.png and puts the three pictures side by side.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
from pathlib import Path

from PIL import Image, ImageChops, ImageDraw

ROOT = Path(__file__).resolve().parents[1]
SOURCE = ROOT / "examples" / "loops.png"
OUT = ROOT / "examples" / "readme.png"
PANEL_HEIGHT = 300


def onestroke(*args: str) -> None:
    subprocess.run([sys.executable, "-m", "fabrication.cli", *args], check=True, cwd=ROOT)


def trimmed(path: Path) -> Image.Image:
    """The picture cropped to its content (plus a margin), scaled to the panel height."""
    image = Image.open(path).convert("RGB")
    background = Image.new("RGB", image.size, image.getpixel((image.width - 1, image.height - 1)))
    box = ImageChops.difference(image, background).getbbox() or (0, 0, image.width, image.height)
    margin = 12
    box = (max(box[0] - margin, 0), max(box[1] - margin, 0),
           min(box[2] + margin, image.width), min(box[3] + margin, image.height))
    image = image.crop(box)
    return image.resize((round(image.width * PANEL_HEIGHT / image.height), PANEL_HEIGHT), Image.LANCZOS)


def main() -> None:
    with tempfile.TemporaryDirectory() as folder:
        work = Path(folder)
        onestroke("vectorize", str(SOURCE), "-o", str(work / "loops.svg"))
        onestroke("preview", str(work / "loops.svg"), "-o", str(work / "curve.png"))
        # The realistic preview: thread in its colour on fabric, as it will look sewn.
        onestroke("embroider", str(SOURCE), "-o", str(work / "loops.pes"), "--style", "zigzag",
                  "--size", "95mm", "--hoop", "100x100", "--color", "#1d4e89",
                  "--preview", str(work / "stitches.png"), "--preview-width", "1400")
        panels = [trimmed(SOURCE), trimmed(work / "curve.png"), trimmed(work / "stitches.png")]
    labels = ["drawing (PNG)", "one curve, start blue -> end red", "zigzag, .pes (preview)"]
    gap = 16
    width = sum(p.width for p in panels) + gap * (len(panels) + 1)
    sheet = Image.new("RGB", (width, PANEL_HEIGHT + 2 * gap + 20), "white")
    draw = ImageDraw.Draw(sheet)
    x = gap
    for panel, label in zip(panels, labels):
        sheet.paste(panel, (x, gap))
        draw.text((x, PANEL_HEIGHT + gap + 4), label, fill=(60, 60, 60))
        x += panel.width + gap
    sheet.save(OUT, optimize=True)
    print(f"wrote {OUT.relative_to(ROOT)} ({sheet.width}x{sheet.height})")


if __name__ == "__main__":
    main()

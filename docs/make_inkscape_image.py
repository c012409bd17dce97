"""Make docs/notes/2026-12-05/inkscape-extension.png: the Inkscape extension's output as Inkscape
renders it, beside the input bitmap.

    python -m docs.make_inkscape_image

examples/loops.png is embedded in an A5 page, turned by -8 degrees and scaled; the extension
(installed with `onestroke inkscape install --dir`) runs on it as Inkscape 1.2 runs it
(tests/bridges/test_inkscape.py: Debian's python3 and Inkscape's own inkex). Panels: the input
bitmap; Inkscape's rendering (`inkscape --export-type=png`) of the output with the bitmap removed;
and the output's path drawn red over the kept bitmap, to show they coincide.
"""

from __future__ import annotations

import subprocess
import tempfile
from pathlib import Path

from PIL import Image, ImageDraw

from tests.bridges.readback import onestroke
from tests.bridges.test_inkscape import INKSCAPE, SVG, embedded, run_extension

ROOT = Path(__file__).resolve().parents[1]

OUT = ROOT / "docs" / "notes" / "2026-12-05" / "inkscape-extension.png"
SOURCE = ROOT / "examples" / "loops.png"
PANEL = 560  # px per panel side


def render(svg: Path, png: Path) -> Image.Image:
    subprocess.run([INKSCAPE, "--export-type=png", "--export-area-page", "--export-background=white",
                    "--export-background-opacity=1", f"--export-width={PANEL}", f"--export-filename={png}",
                    str(svg)], check=True, capture_output=True)
    return Image.open(png).convert("RGB")


def main() -> None:
    with tempfile.TemporaryDirectory() as folder:
        work = Path(folder)
        assert onestroke("inkscape", "install", "--dir", work / "ext").returncode == 0
        document = work / "page.svg"
        document.write_text(f'<svg {SVG} width="148mm" height="105mm" viewBox="0 0 148 105">'
                            '<image id="bitmap" x="14" y="30" width="125" height="75" preserveAspectRatio="none" '
                            f'transform="rotate(-8) scale(0.95)" xlink:href="{embedded(SOURCE)}"/></svg>')
        panels = []
        for keep in ("false", "true"):
            result = run_extension(work / "ext", document, ["bitmap"], keep=keep)
            assert result.returncode == 0, result.stderr
            out = work / f"out-{keep}.svg"
            text = result.stdout if keep == "false" else result.stdout.replace("stroke:#000000", "stroke:#e0201b")
            out.write_text(text)
            panels.append(render(out, work / f"out-{keep}.png"))
        bitmap = Image.open(SOURCE).convert("RGB")
        bitmap.thumbnail((PANEL, PANEL))
        height = max(p.height for p in panels)
        sheet = Image.new("RGB", (bitmap.width + 2 * PANEL + 40, height + 28), "white")
        draw = ImageDraw.Draw(sheet)
        x = 0
        for image, title in ((bitmap, "input bitmap (examples/loops.png)"),
                             (panels[0], "Inkscape's rendering of the output"),
                             (panels[1], "output path (red) over the kept bitmap")):
            sheet.paste(image, (x, 28 + (height - image.height) // 2))
            draw.text((x + 4, 6), title, fill="black")
            x += image.width + 20
        OUT.parent.mkdir(parents=True, exist_ok=True)
        sheet.save(OUT, optimize=True)
        print(f"{OUT}: {sheet.width} x {sheet.height} px, {OUT.stat().st_size // 1024} kB")


if __name__ == "__main__":
    main()

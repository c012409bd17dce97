"""Player page on a 100,000-stitch embroidery file: build time, page size, and in Chromium
the time to the first picture, to scrub to the end and back, and frames while playing.

    python -m benchmarks.player_bench [--stitches 100000] [--repeat 5]

Prints medians. Needs /usr/bin/chromium (Debian's package) and Playwright.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

if __name__ == "__main__" and Path(sys.path[0]).resolve() == Path(__file__).resolve().parent:
    sys.path[0] = str(Path(__file__).resolve().parents[1])  # run as a file: see benchmarks/__init__.py

import pyembroidery

from fabrication.player import player_data_for_file, write_player_html

ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
        "--disable-component-update", "--disable-sync", "--no-first-run"]

# one scrub in the page: seek, then wait until two frames have been drawn
_SEEK = """async (t) => {
  const start = performance.now();
  window.player.seek(t);
  await new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)));
  return performance.now() - start;
}"""
_FRAMES = """async (ms) => {
  let frames = 0; const start = performance.now();
  window.player.setSpeed(1000); window.player.seek(0); window.player.play();
  await new Promise((r) => { const f = () => { frames++; performance.now() - start < ms ? requestAnimationFrame(f) : r(); }; requestAnimationFrame(f); });
  window.player.pause();
  return frames / (ms / 1000);
}"""


def big_pattern(stitches: int) -> pyembroidery.EmbPattern:
    """Zigzag rows across 100 mm in 4 colours, trim and jump between rows (0.1 mm units)."""
    pattern = pyembroidery.EmbPattern()
    for colour in (0xc81e28, 0x1e50c8, 0x14963c, 0xe69614):
        pattern.add_thread({"color": colour})
    per_row, rows = 250, max(1, stitches // 250)
    for row in range(rows):
        if row and row % (rows // 4 or 1) == 0:
            pattern.add_stitch_absolute(pyembroidery.COLOR_CHANGE, 0, 0)
        y = (row % 250) * 4
        for i in range(per_row):
            pattern.add_stitch_absolute(pyembroidery.STITCH, i * 4, y + (i % 2) * 3)
        pattern.add_stitch_absolute(pyembroidery.TRIM, 0, 0)
        pattern.add_stitch_absolute(pyembroidery.JUMP, 0, y + 4)
    pattern.add_stitch_absolute(pyembroidery.END, 0, 0)
    return pattern


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--stitches", type=int, default=100_000)
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    from playwright.sync_api import sync_playwright

    with tempfile.TemporaryDirectory() as folder:
        source, page_path = Path(folder) / "big.vp3", Path(folder) / "big.html"
        pyembroidery.write(big_pattern(args.stitches), str(source))
        builds = []
        for _ in range(args.repeat):
            start = time.perf_counter()
            data = player_data_for_file(source)
            write_player_html(data, page_path, source=source)
            builds.append(time.perf_counter() - start)
        print(f"rows {len(data):,}, stitches {data.number_total:,}, page {page_path.stat().st_size / 1e6:.2f} MB")
        print(f"build data + write page: median {statistics.median(builds):.3f} s")
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path="/usr/bin/chromium", args=ARGS)
            loads, ends, backs, fps = [], [], [], []
            for _ in range(args.repeat):
                page = browser.new_page(viewport={"width": 1200, "height": 800})
                start = time.perf_counter()
                page.goto(page_path.as_uri())
                page.wait_for_function("() => document.querySelector('.osp-root').dataset.index !== undefined")
                loads.append(time.perf_counter() - start)
                ends.append(page.evaluate(_SEEK, data.total))
                backs.append(page.evaluate(_SEEK, data.total / 2))
                fps.append(page.evaluate(_FRAMES, 2000))
                page.close()
            browser.close()
        print(f"open to first picture: median {statistics.median(loads):.2f} s")
        print(f"scrub 0 -> end (draws every stitch): median {statistics.median(ends):.0f} ms")
        print(f"scrub end -> middle (redraws half): median {statistics.median(backs):.0f} ms")
        print(f"playing at 1000x: median {statistics.median(fps):.0f} frames/s")


if __name__ == "__main__":
    main()

"""Make docs/studio.png: the studio on a hand drawing, as the README shows it.

    python docs/make_studio_image.py

A jittered cursive word from the benchmark's generator ("little": its l and t stems are
drawn down and back up), with two pen gaps wiped out of the ink, opened in the studio in
Debian's Chromium; the line is started at the tip of the word's lead-in (the start tool)
and the pen played part way along.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT), str(ROOT / "tests")]

from conftest import CHROMIUM, CHROMIUM_ARGS  # noqa: E402
from studio_fixtures import IDLE, click_at, open_page, settle  # noqa: E402
from benchmarks.sets.hand_drawings import bench_drawing  # noqa: E402

from fabrication.studio.server import StudioServer  # noqa: E402
from fabrication.studio.session import StudioSession  # noqa: E402

OUT = ROOT / "docs" / "studio.png"


def main() -> None:
    from playwright.sync_api import sync_playwright

    with tempfile.TemporaryDirectory() as folder, sync_playwright() as playwright:
        drawing = bench_drawing(Path(folder), "little")
        server = StudioServer(StudioSession(drawing), port=0).start()
        browser = playwright.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
        errors: list = []
        page = open_page(browser, server.url, errors)
        page.set_viewport_size({"width": 1200, "height": 700})
        page.check("input[name=tool][value=start]")
        click_at(page, min(page.evaluate("window.studio.state.graph.ends")))  # the lead-in's tip
        settle(page, 1)
        page.check("input[name=tool][value=pairing]")
        page.evaluate("() => { window.studio.pen = 0.62; document.getElementById('scrub').value = 620; }")
        page.dispatch_event("#scrub", "input")
        page.wait_for_function(IDLE)
        page.screenshot(path=str(OUT))
        browser.close()
        server.stop()
        if errors:
            raise SystemExit(f"script errors on the page: {errors}")
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()

"""The player page in a real browser (Debian's Chromium through Playwright), from file://
with every network request blocked: play, scrub, step, and thread colours on the canvas.
Screenshots go to test-artifacts/ (kept by CI as artifacts of the run)."""

from __future__ import annotations

import re
from pathlib import Path

from click.testing import CliRunner

from tests.chromium import ARTIFACTS
from fabrication.cli import main
from tests.player.pattern import BLUE, RED, write_pattern

# pixels of the canvas within `tol` of an RGB colour, counted in the page
_COUNT = """([r, g, b, tol]) => {
  const c = document.querySelector('[data-role=canvas]');
  const p = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
  let n = 0;
  for (let i = 0; i < p.length; i += 4)
    if (p[i + 3] > 200 && Math.abs(p[i] - r) <= tol && Math.abs(p[i + 1] - g) <= tol && Math.abs(p[i + 2] - b) <= tol) n++;
  return n;
}"""


def _number(text: str) -> int:
    return int(text.split("/")[0].replace(",", "").strip())


def _seconds(text: str) -> float:
    minutes, seconds = text.split("/")[0].strip().split(":")[-2:]
    return int(minutes) * 60 + float(seconds)


def _open(browser, path: Path):
    """A page on `path` with the network blocked; returns (page, requests that were not file://)."""
    context = browser.new_context(viewport={"width": 1100, "height": 700}, offline=True)
    outside: list[str] = []

    def route(r):
        if r.request.url.startswith("file://"):
            r.continue_()
        else:
            outside.append(r.request.url)
            r.abort()

    context.route("**/*", route)
    page = context.new_page()
    errors: list[str] = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.goto(path.as_uri())
    page.wait_for_selector("[data-role=number]")
    return page, outside, errors


def test_embroidery_player_plays_scrubs_and_draws_thread(browser, tmp_path):
    source, out = tmp_path / "two.vp3", tmp_path / "two.html"
    write_pattern(source)
    assert CliRunner().invoke(main, ["preview", str(source), "-o", str(out)]).exit_code == 0
    page, outside, errors = _open(browser, out)
    number, clock = page.locator("[data-role=number]"), page.locator("[data-role=time]")
    assert _number(number.inner_text()) == 0 and _seconds(clock.inner_text()) == 0.0
    assert re.search(r"/ 120$", number.inner_text())

    page.locator("[data-role=speed]").select_option("5")
    page.click("[data-role=play]")
    page.wait_for_function("() => Number(document.querySelector('.osp-root').dataset.time) > 1.5")
    page.click("[data-role=play]")  # pause
    played = _number(number.inner_text())
    assert played > 0 and _seconds(clock.inner_text()) > 1.5
    page.screenshot(path=str(ARTIFACTS / "player-embroidery-playing.png"))
    assert page.evaluate(_COUNT, [*RED, 40]) > 50
    assert page.evaluate(_COUNT, [*BLUE, 40]) < 10  # the blue block is still to come

    scrub = page.locator("[data-role=scrub]")
    scrub.fill("100000")  # the end
    page.wait_for_function("() => document.querySelector('[data-role=number]').textContent.startsWith('120 ')")
    assert _seconds(clock.inner_text()) > 0
    assert page.evaluate(_COUNT, [*BLUE, 40]) > 50 and page.evaluate(_COUNT, [*RED, 40]) > 50
    page.screenshot(path=str(ARTIFACTS / "player-embroidery-end.png"))

    scrub.fill("20000")  # back to 20 %: fewer stitches, and blue gone again
    page.wait_for_function("() => !document.querySelector('[data-role=number]').textContent.startsWith('120 ')")
    middle = _number(number.inner_text())
    assert 0 < middle < 120
    assert page.evaluate(_COUNT, [*BLUE, 40]) < 10  # (a few head-marker pixels are bluish)
    # the arrow key steps move by move (a trim or a jump is a move but not a stitch)
    for _ in range(4):
        before = float(page.evaluate("document.querySelector('.osp-root').dataset.time"))
        page.locator(".osp-root").press("ArrowRight")
        page.wait_for_function(f"() => Number(document.querySelector('.osp-root').dataset.time) > {before}")
        if _number(number.inner_text()) != middle:
            break
    assert _number(number.inner_text()) == middle + 1
    page.click("[data-role=zoom-in]")
    page.wait_for_timeout(100)
    page.screenshot(path=str(ARTIFACTS / "player-embroidery-zoomed.png"))
    assert outside == [] and errors == []


def test_gcode_player_plays_on_the_planner_clock(browser, tmp_path):
    out = tmp_path / "rose.html"
    assert CliRunner().invoke(main, ["preview", "tests/golden/laser_rose_arcs.gcode", "-o", str(out)]).exit_code == 0
    page, outside, errors = _open(browser, out)
    line = page.locator("[data-role=number]")
    assert re.search(r"/ 82$", line.inner_text())
    page.click("[data-role=play]")
    page.wait_for_function("() => Number(document.querySelector('.osp-root').dataset.time) > 2")
    page.click("[data-role=play]")
    assert _number(line.inner_text()) > 1 and page.locator("[data-role=kind]").inner_text() in ("burn", "travel")
    page.screenshot(path=str(ARTIFACTS / "player-gcode.png"))
    assert outside == [] and errors == []

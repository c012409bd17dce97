"""Shared by the studio's browser tests: a studio server on a copy of examples/loops.png,
one page on it in the session's Chromium, and the small helpers that drive the page the
way a user does (real mouse clicks and drags at screen positions) and wait for it."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner

from fabrication.cli import main
from fabrication.studio.server import StudioServer
from fabrication.studio.session import StudioSession

ROOT = Path(__file__).resolve().parents[1]
IDLE = "!document.body.classList.contains('busy')"


@pytest.fixture(scope="module")
def studio(tmp_path_factory):
    """(server, drawing path) of a studio on a copy of examples/loops.png."""
    folder = tmp_path_factory.mktemp("studio-browser")
    drawing = folder / "loops.png"
    shutil.copy(ROOT / "examples" / "loops.png", drawing)
    server = StudioServer(StudioSession(drawing), port=0).start()
    yield server, drawing
    server.stop()


def open_page(browser, url: str, errors: list):
    """A new page on `url`, waited for until the first vectorization is drawn."""
    context = browser.new_context(viewport={"width": 1280, "height": 760}, accept_downloads=True)
    page = context.new_page()
    page.set_default_timeout(20000)
    page.on("pageerror", lambda error: errors.append(str(error)))
    page.goto(url)
    page.wait_for_function(f"window.studio.state !== null && {IDLE}", timeout=90000)
    return page


@pytest.fixture(scope="module")
def page(studio, browser):
    """The studio page, loaded and idle; fails the module's last test on a script error."""
    context = browser.new_context(viewport={"width": 1280, "height": 760}, accept_downloads=True)
    page = context.new_page()
    page.set_default_timeout(20000)
    errors = []
    page.on("pageerror", lambda error: errors.append(str(error)))
    page.goto(studio[0].url)
    page.wait_for_function(f"window.studio.state !== null && {IDLE}", timeout=90000)  # the first vectorization
    yield page
    context.close()
    assert not errors, errors


def settle(page, edits_count=None, extra: str = "") -> None:
    """Wait until no request is pending (and the edits list has `edits_count` items)."""
    condition = IDLE
    if edits_count is not None:
        condition += f" && window.studio.state.edits.edits.length === {edits_count}"
    if extra:
        condition += f" && ({extra})"
    page.wait_for_function(condition)


def refused_threshold(page, value: float, says: str) -> None:
    """Move the threshold slider from the automatic threshold to `value` (as a drag ends),
    wait for the refusal whose message contains `says`, and check that the slider, its
    figure and "automatic" went back to the drawing shown."""
    import pytest

    before = page.evaluate("window.studio.state.report.threshold")
    assert page.is_checked("#auto-threshold")
    page.eval_on_selector("#threshold", f"e => {{ e.value = {value}; e.dispatchEvent(new Event('input')); "
                                        "e.dispatchEvent(new Event('change')); }")
    page.wait_for_function(f"document.getElementById('warnings').textContent.includes({says!r})")
    settle(page)
    page.wait_for_timeout(400)
    assert page.is_checked("#auto-threshold")
    assert float(page.input_value("#threshold")) == pytest.approx(before, abs=0.006)
    assert page.inner_text("#threshold-value") == f"auto {before:.2f}"


def click_at(page, at) -> None:
    """A mouse click at image position `at` (px), wherever the view has put it."""
    x, y = page.evaluate(f"window.studio.toScreen({at[0]}, {at[1]})")
    page.mouse.click(x, y)


def drag_slider(page, selector: str, fraction: float, *, steps: int = 8) -> None:
    """Press the mouse on a range input's thumb and drag it to `fraction` of its track."""
    box = page.locator(selector).bounding_box()
    low, high = page.eval_on_selector(selector, "e => [Number(e.min), Number(e.max)]")
    value = float(page.eval_on_selector(selector, "e => e.value"))
    thumb = 8  # half of Chromium's range thumb: the track's usable part is inset by it
    def x_of(f):
        return box["x"] + thumb + f * (box["width"] - 2 * thumb)
    y = box["y"] + box["height"] / 2
    page.mouse.move(x_of((value - low) / (high - low)), y)
    page.mouse.down()
    page.mouse.move(x_of(fraction), y, steps=steps)
    page.mouse.up()


def coloured_pixels(page) -> int:
    """Strongly coloured pixels on the drawing canvas: the curve (the raster is drawn grey)."""
    return page.evaluate("""() => {
        const c = document.getElementById('canvas');
        const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
        let n = 0;
        for (let i = 0; i < d.length; i += 4) {
            const mx = Math.max(d[i], d[i + 1], d[i + 2]), mn = Math.min(d[i], d[i + 1], d[i + 2]);
            if (mx - mn > 80) n++;
        }
        return n;
    }""")


def download(page, selector: str) -> tuple[str, bytes]:
    """Click a download button; (suggested file name, bytes)."""
    with page.expect_download() as event:
        page.click(selector)
    return event.value.suggested_filename, Path(event.value.path()).read_bytes()


def cli_bytes(command: str, drawing: Path, edits: dict, tmp_path: Path, suffix: str, *flags) -> bytes:
    """The bytes `onestroke COMMAND DRAWING --edits E -o OUT FLAGS` writes."""
    (tmp_path / "edits.json").write_text(json.dumps(edits))
    out = tmp_path / f"cli{suffix}"
    run = CliRunner().invoke(main, [command, str(drawing), "--edits", str(tmp_path / "edits.json"),
                                    "-o", str(out), *flags])
    assert run.exit_code == 0, run.output
    return out.read_bytes()


def curve_under_labels(page) -> dict[str, float]:
    """text -> screen px of the drawn curve under that marker's text on the drawing (its white
    box: the text's box and the 2 px the box adds each side), each segment of the curve
    walked in 0.5 px steps."""
    return page.evaluate("""() => {
        const s = window.studio, t = s.line, r = document.getElementById('canvas').getBoundingClientRect();
        const at = (p) => { const [x, y] = s.toScreen(p[0], p[1]); return [x - r.left, y - r.top]; };
        const under = {};
        for (const { text, box: [x, y, w, h] } of s.placed) {
            let length = 0;
            for (let i = 1; i < t.pts.length; i++) {
                if (t.pts[i].first) continue;
                const a = at(t.pts[i - 1]), b = at(t.pts[i]), d = Math.hypot(b[0] - a[0], b[1] - a[1]);
                const n = Math.max(1, Math.ceil(2 * d));
                for (let k = 1; k <= n; k++) {
                    const px = a[0] + (b[0] - a[0]) * k / n, py = a[1] + (b[1] - a[1]) * k / n;
                    if (px >= x - 2 && px <= x + w + 2 && py >= y && py <= y + h) length += d / n;
                }
            }
            under[text] = Math.max(under[text] || 0, length);
        }
        return under;
    }""")

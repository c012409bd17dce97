"""Fixtures of the studio's tests: a small drawing as a PNG; for the browser tests a studio
server on a copy of examples/loops.png and one page on it in the session's Chromium
(tests/conftest.py)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from PIL import Image

from fabrication.studio.server import StudioServer
from fabrication.studio.session import StudioSession
from tests.drawings import alpha_loop, render_polylines
from tests.studio.browser_page import IDLE

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def studio(tmp_path_factory):
    """(server, drawing path) of a studio on a copy of examples/loops.png."""
    folder = tmp_path_factory.mktemp("studio-browser")
    drawing = folder / "loops.png"
    shutil.copy(ROOT / "examples" / "loops.png", drawing)
    server = StudioServer(StudioSession(drawing), port=0).start()
    yield server, drawing
    server.stop()


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


@pytest.fixture(scope="module")
def loop_png(tmp_path_factory):
    """A small drawing that loops once and crosses itself (tests/drawings.py), as a PNG."""
    path = tmp_path_factory.mktemp("studio") / "loop.png"
    Image.fromarray(render_polylines([alpha_loop()])).save(path)
    return path

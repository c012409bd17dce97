"""Shared fixtures: small constructed drawings rendered the way a scanner would see them."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from PIL import Image, ImageDraw

# Browser tests drive Debian's Chromium (`playwright install` cannot download browsers
# here; .ci/run installs the package). Their screenshots are the run's artifacts.
CHROMIUM = "/usr/bin/chromium"
CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
                 "--disable-component-update", "--disable-sync", "--no-first-run"]
ARTIFACTS = Path(__file__).resolve().parents[1] / "test-artifacts"
# Debian packages the tests drive, by a file each installs: Chromium for the browser tests,
# Inkscape (and the lxml its extensions' inkex needs) for the Inkscape extension's tests.
SYSTEM_PACKAGES = {CHROMIUM: "chromium", "/usr/bin/inkscape": "inkscape",
                   "/usr/lib/python3/dist-packages/lxml": "python3-lxml"}


def pytest_sessionstart(session) -> None:
    """Install the missing system packages (as root, with apt-get), so that the README's test
    command passes alone on a fresh Debian machine; elsewhere the tests that need them say so."""
    missing = [package for path, package in SYSTEM_PACKAGES.items() if not Path(path).exists()]
    if not missing or not hasattr(os, "geteuid") or os.geteuid() != 0 or not shutil.which("apt-get"):
        return
    env = {**os.environ, "DEBIAN_FRONTEND": "noninteractive"}
    subprocess.run(["apt-get", "update", "-qq"], env=env, check=False)
    subprocess.run(["apt-get", "install", "-y", "-qq", *missing], env=env, check=False,
                   stdout=subprocess.DEVNULL)


@pytest.fixture(scope="session")
def browser():
    """One headless Chromium for every browser test (Playwright's sync API)."""
    if not Path(CHROMIUM).exists():
        pytest.fail(f"{CHROMIUM} is missing: apt-get install -y chromium")
    from playwright.sync_api import sync_playwright

    ARTIFACTS.mkdir(exist_ok=True)
    with sync_playwright() as playwright:
        chromium = playwright.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
        yield chromium
        chromium.close()


def render_polylines(polylines, size=(400, 400), width=6.0, supersample=4) -> np.ndarray:
    """Anti-aliased black polylines on white: uint8 (H, W). Round caps and joins."""
    w, h = size
    s = supersample
    image = Image.new("L", (w * s, h * s), 255)
    draw = ImageDraw.Draw(image)
    r = width * s / 2
    for line in polylines:
        pts = [(float(x) * s, float(y) * s) for x, y in line]
        draw.line(pts, fill=0, width=max(1, int(round(width * s))), joint="curve")
        for x, y in pts:
            draw.ellipse([x - r, y - r, x + r, y + r], fill=0)
    return np.asarray(image.resize((w, h), Image.LANCZOS))


def circle(cx=200, cy=200, radius=120, n=400):
    t = np.linspace(0, 2 * np.pi, n)
    return np.c_[cx + radius * np.cos(t), cy + radius * np.sin(t)]


def figure_eight(n=600):
    t = np.linspace(0, 2 * np.pi, n)
    return np.c_[200 + 150 * np.sin(t), 200 + 100 * np.sin(2 * t)]


def alpha_loop(n=600):
    """An open curve that loops once and crosses itself (a trochoid arc)."""
    t = np.linspace(-2.9, 2.9, n)
    return np.c_[200 + 45 * t - 110 * np.sin(t), 200 - 110 * np.cos(t)]


def v_spike():
    """Out along a line and back at a slight angle: an out-and-back spike with a sharp tip."""
    return np.array([[60.0, 200.0], [330.0, 200.0], [80.0, 240.0]])


@pytest.fixture
def write_png(tmp_path):
    def _write(array: np.ndarray, name: str = "drawing.png"):
        path = tmp_path / name
        Image.fromarray(np.asarray(array)).save(path)
        return path

    return _write

"""Fixtures every folder of the tests shares: one Chromium for the browser tests, a PNG writer;
and the system packages the tests drive, installed before the session when missing."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from tests.chromium import ARTIFACTS, CHROMIUM, CHROMIUM_ARGS

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


@pytest.fixture
def write_png(tmp_path):
    def _write(array: np.ndarray, name: str = "drawing.png"):
        path = tmp_path / name
        Image.fromarray(np.asarray(array)).save(path)
        return path

    return _write

"""The Chromium the browser tests drive, and where their screenshots go."""

from __future__ import annotations

from pathlib import Path

# Browser tests drive Debian's Chromium (`playwright install` cannot download browsers
# here; .ci/run installs the package). Their screenshots are the run's artifacts.
CHROMIUM = "/usr/bin/chromium"
CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
                 "--disable-component-update", "--disable-sync", "--no-first-run"]
ARTIFACTS = Path(__file__).resolve().parents[1] / "test-artifacts"

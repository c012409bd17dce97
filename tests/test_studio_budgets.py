"""Issue 25: the studio's budgets (`fabrication.studio.budgets`). A setting inside its range
whose work grows with the input is refused before that work, with a 400 that says what was
found and what to change, and nothing in the session changes: loops.png at threshold 0.08
(a ragged edge: hundreds of spurs for route inspection to pair) and satin at 0.1 mm spacing
on the largest hoop (52,000 rows). In the browser the controls go back to the drawing shown.
"""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest
from starlette.testclient import TestClient

from fabrication.studio import budgets
from fabrication.studio.app import create_app
from fabrication.studio.server import StudioServer
from fabrication.studio.session import StudioSession
from machines.hoops import HOOP_SIDE
from tests.conftest import ARTIFACTS
from tests.studio_fixtures import IDLE, refused_threshold

ROOT = Path(__file__).resolve().parents[1]
HOST = "127.0.0.1:8766"
EDITS = {"format": "onestroke-edits", "version": 1, "edits": []}
SIDE = f"{HOOP_SIDE.high:g}"
SATIN = {"style": "satin", "spacing": "0.1mm", "size": f"{SIDE}mm", "hoop": f"{SIDE}x{SIDE}", "fit": True}


@pytest.fixture(scope="module")
def loops(tmp_path_factory):
    folder = tmp_path_factory.mktemp("studio-budgets")
    drawing = folder / "loops.png"
    shutil.copy(ROOT / "examples" / "loops.png", drawing)
    return drawing


@pytest.fixture(scope="module")
def studio(loops):
    session = StudioSession(loops, edits_path=loops.with_name("saved.edits.json"))
    with TestClient(create_app(session, token="t", hosts={HOST}), base_url=f"http://{HOST}") as client:
        client.headers["X-Studio-Token"] = "t"
        yield session, client


def _without_time(state: dict) -> dict:
    return dict(state, report={k: v for k, v in state["report"].items() if k != "seconds"})


def test_a_ragged_threshold_is_refused_before_the_matching(studio, loops):
    session, client = studio
    shown = client.get("/api/state").json()
    answer = client.post("/api/state", json={"edits": dict(EDITS, threshold=0.08)})
    assert answer.status_code == 400
    message = answer.json()["error"]
    found = re.match(r"the ink has (\d+) loose ends (?:and forks )?for the line to pair up at threshold 0\.08, "
                     rf"more than the {budgets.ODD_NODES} an interactive run takes: .*--threshold.*--blur", message)
    assert found and int(found[1]) > budgets.ODD_NODES, message
    # Nothing changed: the state shown is the drawing's, no edits file was written.
    assert _without_time(client.get("/api/state").json()) == _without_time(shown)
    assert not loops.with_name("saved.edits.json").exists()
    # In multi-stroke mode each pair is a stroke: its own budget.
    multi = client.post("/api/state", json={"edits": dict(EDITS, threshold=0.05, multi=True)})
    assert multi.status_code == 400
    found = re.match(r"the ink has (\d+) loose ends (?:and forks )?strokes to end there at threshold 0\.05, more than "
                     rf"the {budgets.MULTI_ODD_NODES} an interactive run takes", multi.json()["error"])
    assert found and int(found[1]) > budgets.MULTI_ODD_NODES, multi.json()["error"]
    assert _without_time(client.get("/api/state").json()) == _without_time(shown)
    # The CLI's settings pass the budget where the drawing is a line: a threshold above the noise.
    fine = client.post("/api/state", json={"edits": dict(EDITS, threshold=0.3)})
    assert fine.status_code == 200 and fine.json()["report"]["strokes"] == 1


def test_too_many_stitch_steps_are_refused_before_stitching(studio):
    session, client = studio
    for endpoint in ("embroidery", "export/pes"):
        answer = client.post(f"/api/{endpoint}", json={"options": SATIN})
        assert answer.status_code == 400, endpoint
        message = answer.json()["error"]
        found = re.match(r"0\.1 mm steps along ([\d,]+) mm of curve are ([\d,]+) steps, more than the "
                         r"([\d,]+) an interactive preview makes; use a wider --spacing or a smaller --size", message)
        assert found, message
        length, steps, limit = (int(found[k].replace(",", "")) for k in (1, 2, 3))
        assert limit == budgets.STEPS and steps > limit and abs(steps - 10 * length) <= 10
    # The default spacing on the same hoop is within the budget, and its preview is made.
    wide = client.post("/api/embroidery", json={"options": dict(SATIN, spacing="")})
    assert wide.status_code == 200 and wide.json()["stitches"] > 0


def test_the_controls_go_back_after_a_refused_threshold(loops, browser):
    server = StudioServer(StudioSession(loops), port=0).start()
    context = browser.new_context(viewport={"width": 1280, "height": 800})
    errors = []
    try:
        page = context.new_page()
        page.on("pageerror", lambda error: errors.append(str(error)))
        page.set_default_timeout(60000)
        page.goto(server.url)
        page.wait_for_function(f"window.studio.state !== null && {IDLE}", timeout=90000)
        curve = page.evaluate("JSON.stringify(window.studio.state.strokes)")
        refused_threshold(page, 0.08, "loose ends")
        assert page.evaluate("JSON.stringify(window.studio.state.strokes)") == curve
        page.screenshot(path=str(ARTIFACTS / "studio-budget-threshold-refused.png"))
    finally:
        context.close()
        server.stop()
    assert not errors, errors

"""The studio's API through Starlette's test client: the guard (token, Host, size), the
state and its edits, and downloads that are the CLI's bytes for the same edits and options."""

from __future__ import annotations

import time

import pytest
from click.testing import CliRunner
from starlette.testclient import TestClient

from fabrication.cli import main
from fabrication.studio.app import MAX_BODY, create_app
from fabrication.studio.session import StudioSession
from vectorize.refine.edits import PAIRINGS

HOST = "127.0.0.1:8765"
TOKEN = "test-token-123"


@pytest.fixture(scope="module")
def client(loop_png):
    session = StudioSession(loop_png, edits_path=loop_png.with_name("saved.edits.json"))
    app = create_app(session, token=TOKEN, hosts={HOST})
    with TestClient(app, base_url=f"http://{HOST}") as test_client:
        test_client.headers["X-Studio-Token"] = TOKEN
        yield test_client


def test_guard_token_host_and_size(loop_png):
    app = create_app(StudioSession(loop_png), token=TOKEN, hosts={HOST})
    with TestClient(app, base_url=f"http://{HOST}") as anonymous:
        assert anonymous.get("/api/state").status_code == 403
        assert anonymous.get("/api/state", headers={"X-Studio-Token": "wrong"}).status_code == 403
        assert anonymous.get("/static/app.js").status_code == 403
        page = anonymous.get(f"/?token={TOKEN}")
        assert page.status_code == 200 and "<canvas" in page.text
        # The page's cookie carries the token from then on (the client keeps it).
        assert anonymous.get("/static/app.js").status_code == 200
        assert anonymous.get(f"/?token={TOKEN}", headers={"Host": "evil.example:8765"}).status_code == 403
        # A change needs the token in its header: the cookie alone does not do.
        assert anonymous.post("/api/state", json={}).status_code == 403
        header = {"X-Studio-Token": TOKEN}
        big = b"x" * (MAX_BODY + 1)
        assert anonymous.post("/api/state", content=big, headers=header).status_code == 413
        assert anonymous.post("/api/send", json={"port": "socket://10.0.0.1:23"}, headers=header).status_code == 400
        assert anonymous.post("/api/send", json={"port": "sim://?profile=/etc/passwd"},
                              headers=header).status_code == 400


def test_state_pairing_edit_changes_the_order(client):
    state = client.get("/api/state").json()
    assert state["report"]["strokes"] == 1 and len(state["strokes"][0]["points"]) > 50
    junction = next(j for j in state["graph"]["junctions"] if j["role"] == "crossing")
    assert junction["decision"] in PAIRINGS and 0.5 <= junction["confidence"] <= 1
    other = PAIRINGS[(PAIRINGS.index(junction["decision"]) + 1) % 3]
    edits = dict(state["edits"], edits=[{"kind": "pairing", "at": junction["at"], "pairing": other}])
    changed = client.post("/api/state", json={"edits": edits}).json()
    fixed = next(j for j in changed["graph"]["junctions"] if j["role"] == "crossing")
    assert fixed["fixed"] and fixed["decision"] == other
    assert changed["strokes"][0]["points"] != state["strokes"][0]["points"]
    bad = client.post("/api/state", json={"edits": {"format": "nope"}})
    assert bad.status_code == 400 and "edits" in bad.json()["error"]


def test_save_and_load_edits(client, loop_png):
    edits = {"format": "onestroke-edits", "version": 1, "threshold": 0.45, "blur": 1.0, "multi": False,
             "tolerance": 8, "edits": [{"kind": "reverse", "at": [200, 100]}]}
    assert client.get("/api/edits").json()["exists"] is False  # the page then loads nothing
    saved = client.post("/api/edits", json={"edits": edits}).json()
    assert saved["saved"].endswith("saved.edits.json")
    loaded = client.get("/api/edits").json()
    assert loaded["exists"] is True and loaded["edits"]["edits"] == edits["edits"]
    assert loop_png.with_name("saved.edits.json").read_text().startswith("{")


def test_previews(client):
    state = client.get("/api/state").json()
    stitches = client.post("/api/embroidery", json={"edits": state["edits"], "options": {"size": "60mm"}}).json()
    assert stitches["stitches"] > 50 and any(line.startswith("stitches") for line in stitches["stats"])
    laser = client.post("/api/laser", json={"edits": state["edits"], "options": {"size": "50mm"}}).json()
    assert laser["profile"] and laser["seconds"] > 0 and laser["player"]["source"] == "gcode" and laser["player"]["n"] > 10
    assert stitches["player"]["source"] == "embroidery" and stitches["player"]["numberTotal"] > 50
    refused = client.post("/api/embroidery", json={"edits": state["edits"], "options": {"size": "-3mm"}})
    assert refused.status_code == 400 and "--size" in refused.json()["error"]


@pytest.mark.parametrize("kind, command, options, flags", [
    ("svg", "vectorize", {}, []),
    ("pes", "embroider", {"style": "zigzag", "size": "70mm", "color": "#1f3a93"},
     ["--style", "zigzag", "--size", "70mm", "--color", "#1f3a93"]),
    ("dst", "embroider", {"style": "triple", "size": "50mm"}, ["--style", "triple", "--size", "50mm"]),
    ("jef", "embroider", {"style": "arrows", "hoop": "130x180", "size": "120mm"},
     ["--style", "arrows", "--hoop", "130x180", "--size", "120mm"]),
    ("exp", "embroider", {"stitch_length": "3mm"}, ["--stitch-length", "3mm"]),
    ("vp3", "embroider", {"color": "#c01020"}, ["--color", "#c01020"]),
    ("gcode", "laser", {"size": "40mm", "feed": "1200mm/min", "power": "35%", "passes": "2"},
     ["--size", "40mm", "--feed", "1200mm/min", "--power", "35%", "--passes", "2"]),
    # A profile loaded in the page (K40_PROFILE, uploaded as text) = the CLI's --profile FILE.
    ("gcode", "laser", {"size": "40mm", "power": "35%", "arcs": True, "profile": "K40"},
     ["--size", "40mm", "--power", "35%", "--arcs", "--profile", "K40"]),
])
def test_downloads_are_the_cli_bytes(client, loop_png, tmp_path, kind, command, options, flags):
    if options.get("profile") == "K40":
        (tmp_path / "k40.toml").write_text(K40_PROFILE)
        loaded = client.post("/api/profiles", json={"name": "k40.toml", "text": K40_PROFILE})
        assert loaded.status_code == 200, loaded.text
        options = dict(options, profile=loaded.json()["id"])
        flags = [str(tmp_path / "k40.toml") if f == "K40" else f for f in flags]
    state = client.get("/api/state").json()
    junction = next(j for j in state["graph"]["junctions"] if j["role"] == "crossing")
    other = PAIRINGS[(PAIRINGS.index(junction["decision"]) + 1) % 3]
    edits = dict(state["edits"], blur=0.5, edits=[{"kind": "pairing", "at": junction["at"], "pairing": other}])
    page = client.post(f"/api/export/{kind}", json={"edits": edits, "options": options})
    assert page.status_code == 200, page.text
    import json

    (tmp_path / "edits.json").write_text(json.dumps(edits))
    out = tmp_path / f"cli.{kind}"
    run = CliRunner().invoke(main, [command, str(loop_png), "--edits", str(tmp_path / "edits.json"),
                                    "-o", str(out), *flags])
    assert run.exit_code == 0, run.output
    assert page.content == out.read_bytes()


K40_PROFILE = """name = "K40 test laser"
[bed]
size = "300x200mm"
[laser]
max_power = 255
air_assist = true
[motion]
max_rate_x = "4000mm/min"
acceleration_x = "300mm/s^2"
acceleration_y = "250mm/s^2"
"""


def test_machine_profiles(client):
    """The laser panel's profiles: the built-in one by default; a TOML loaded as text is
    checked, offered and drives the preview; a bad or oversize one is refused in one line
    and changes nothing."""
    state = client.get("/api/state").json()
    listed = client.get("/api/profiles").json()
    assert listed["default"] == "built-in:laser-default"
    assert [p["id"] for p in listed["profiles"]][0] == "built-in:laser-default"
    options = {"size": "50mm"}
    default = client.post("/api/laser", json={"edits": state["edits"], "options": options}).json()
    chosen = client.post("/api/laser", json={"edits": state["edits"],
                                             "options": dict(options, profile="built-in:laser-default")}).json()
    assert default["profile"] == chosen["profile"] == "Generic GRBL 1.1 diode laser, 400 x 400 mm"
    assert default["seconds"] == chosen["seconds"]

    loaded = client.post("/api/profiles", json={"name": "k40.toml", "text": K40_PROFILE}).json()
    assert loaded["name"] == "K40 test laser" and loaded["id"] in [p["id"] for p in loaded["profiles"]]
    k40 = client.post("/api/laser", json={"edits": state["edits"], "options": dict(options, profile=loaded["id"])}).json()
    assert k40["profile"] == "K40 test laser"
    assert k40["seconds"] > default["seconds"]  # slower accelerations: a longer planner estimate
    too_big = client.post("/api/laser", json={"edits": state["edits"],
                                              "options": {"size": "250mm", "profile": loaded["id"]}})
    assert too_big.status_code == 400 and "--profile" in too_big.json()["error"]  # the page names its select

    before = client.get("/api/profiles").json()
    for text, reason in [("name = \n[bed]", "not valid TOML"), ('[motion]\nmax_rate_z = "1mm/min"', "unknown key"),
                         ("[laser]\nmax_power = -5", "max_power"), ("x" * (65 * 1024), "too large")]:
        bad = client.post("/api/profiles", json={"name": "bad.toml", "text": text})
        assert bad.status_code == 400 and reason in bad.json()["error"], bad.text
        assert "\n" not in bad.json()["error"]
    assert client.get("/api/profiles").json() == before  # the previous choices kept
    assert client.post("/api/profiles", content=b"{" + b" " * MAX_BODY + b"}").status_code == 413
    unknown = client.post("/api/laser", json={"edits": state["edits"], "options": {"profile": "/etc/passwd"}})
    assert unknown.status_code == 400 and "not one of" in unknown.json()["error"]


def test_send_to_the_emulator(client):
    state = client.get("/api/state").json()
    started = client.post("/api/send", json={"edits": state["edits"], "options": {"size": "20mm"},
                                             "port": "sim://?speed=200"})
    assert started.status_code == 200, started.text
    deadline = time.monotonic() + 30
    status = started.json()
    while status["state"] in ("connecting", "streaming", "paused") and time.monotonic() < deadline:
        time.sleep(0.1)
        status = client.get("/api/send").json()
    assert status["state"] == "done", status
    assert status["acked"] == status["total"] > 10


def test_send_reads_the_baud_rate_as_the_command_line_does(loop_png):
    """One number grammar and one check: a text "9600" is 9600 (as `--baud 9600`); 0, a
    fraction, a flag or other digits than 0-9 are refused in the CLI's words, not read by
    int() nor replaced by the default."""
    from machines.stream_types import parse_baud
    from onestroke.errors import InputError

    session = StudioSession(loop_png, edits_path=loop_png.with_name("baud.edits.json"))
    with TestClient(create_app(session, token=TOKEN, hosts={HOST}), base_url=f"http://{HOST}",
                    headers={"X-Studio-Token": TOKEN}) as client:
        for bad in (0, "0", 9600.5, True, "9600.0", "\u0669\u0666\u0660\u0660", "1e5", 57601, [9600]):
            answer = client.post("/api/send", json={"options": {"size": "20mm"}, "port": "sim://", "baud": bad})
            with pytest.raises(InputError) as refused:
                parse_baud(bad)
            assert answer.status_code == 400 and answer.json()["error"] == str(refused.value), (bad, answer.text)
            assert session.sender is None
        started = client.post("/api/send", json={"options": {"size": "20mm"}, "port": "sim://?speed=200",
                                                 "baud": " 9600 "})
        assert started.status_code == 200, started.text
        assert session.sender.baud == 9600
        session.sender.wait(30)
        assert client.get("/api/send").json()["state"] == "done"


def test_send_pause_resume_abort(client):
    state = client.get("/api/state").json()
    started = client.post("/api/send", json={"edits": state["edits"], "options": {"size": "60mm", "passes": "3"},
                                             "port": "sim://?speed=2"})
    assert started.status_code == 200, started.text
    deadline = time.monotonic() + 20
    while client.get("/api/send").json()["state"] != "streaming" and time.monotonic() < deadline:
        time.sleep(0.05)
    assert client.post("/api/send/pause").json()["state"] == "paused"
    assert client.post("/api/send", json={"edits": state["edits"], "port": "sim://"}).status_code == 400  # busy
    assert client.post("/api/send/resume").json()["state"] == "streaming"
    client.post("/api/send/abort")
    status = client.get("/api/send").json()
    while status["state"] in ("streaming", "aborting") and time.monotonic() < deadline:
        time.sleep(0.05)
        status = client.get("/api/send").json()
    assert status["state"] == "aborted" and status["acked"] < status["total"], status


def test_an_svg_drawing_opens_and_exports(loop_png, tmp_path):
    from vectorize import vectorize_file
    from vectorize.svg_write import write_drawing

    svg = tmp_path / "loop.svg"
    write_drawing(vectorize_file(loop_png).drawing, svg)
    app = create_app(StudioSession(svg), token=TOKEN, hosts={HOST})
    with TestClient(app, base_url=f"http://{HOST}", headers={"X-Studio-Token": TOKEN}) as svg_client:
        state = svg_client.get("/api/state").json()
        assert state["report"]["strokes"] == 1 and state["graph"]["junctions"] == []
        assert svg_client.get("/api/image").headers["content-type"].startswith("image/svg+xml")
        assert svg_client.post("/api/export/svg", json={}).content.startswith(b"<?xml")


def test_multi_stroke_mode_and_a_bad_threshold(client):
    edits = client.get("/api/state").json()["edits"]
    multi = client.post("/api/state", json={"edits": dict(edits, multi=True)}).json()
    assert multi["settings"]["multi"] is True and multi["report"]["strokes"] >= 1
    assert multi["edits"]["multi"] is True
    # The threshold in use: Li's level when automatic, the given one otherwise.
    li = client.get("/api/state").json()["report"]["threshold"]
    assert 0 < li < 1 and multi["report"]["threshold"] == li
    given = client.post("/api/state", json={"edits": dict(edits, threshold=0.42)}).json()
    assert given["report"]["threshold"] == 0.42 and given["settings"]["threshold"] == 0.42
    answer = client.post("/api/state", json={"edits": dict(edits, threshold=1.5)})
    assert answer.status_code == 400 and "threshold" in answer.json()["error"]


def test_a_queued_state_request_gives_way_to_the_same_pages_newer_one(loop_png):
    """A slider dragged over values while a re-run takes a second: the requests that wait
    for the vectorizer are skipped once the page asked for a newer state."""
    import threading

    session = StudioSession(loop_png)
    app = create_app(session, token=TOKEN, hosts={HOST})
    with TestClient(app, base_url=f"http://{HOST}", headers={"X-Studio-Token": TOKEN}) as test_client:
        edits = test_client.get("/api/state").json()["edits"]
        answers = {}

        def post(threshold, page="p1"):
            answers[threshold, page] = test_client.post(
                "/api/state", json={"edits": dict(edits, threshold=threshold), "page": page}).json()

        def queued(count):
            deadline = time.monotonic() + 10
            while sum(session._tickets.values()) < count and time.monotonic() < deadline:
                time.sleep(0.01)

        threads = []
        with session.lock:  # a re-run in progress: the next requests queue behind it
            for n, (threshold, page) in enumerate([(0.42, "p1"), (0.43, "p2"), (0.44, "p1")], start=1):
                threads.append(threading.Thread(target=post, args=(threshold, page)))
                threads[-1].start()
                queued(n)
        for thread in threads:
            thread.join(30)
        assert answers[0.42, "p1"] == {"superseded": True}
        assert answers[0.44, "p1"]["settings"]["threshold"] == 0.44
        assert answers[0.43, "p2"]["settings"]["threshold"] == 0.43  # another page's request is its own


def test_abort_while_connecting(client):
    """Abort pressed before the controller has answered: no line is streamed."""
    state = client.get("/api/state").json()
    started = client.post("/api/send", json={"edits": state["edits"], "options": {"size": "20mm"},
                                             "port": "sim://?speed=2"})
    assert started.status_code == 200 and started.json()["state"] == "connecting", started.text
    assert client.post("/api/send/abort").json()["state"] == "aborting"
    deadline = time.monotonic() + 20
    status = client.get("/api/send").json()
    while status["state"] in ("connecting", "streaming", "aborting") and time.monotonic() < deadline:
        time.sleep(0.05)
        status = client.get("/api/send").json()
    assert status["state"] == "aborted" and status["acked"] < status["total"], status


def test_the_threshold_mask_is_the_binarization(client, loop_png):
    """GET /api/mask: the working pixels darker than the threshold (the library's own
    binarization of the image at that blur), refused in the CLI's words out of range."""
    from io import BytesIO

    import numpy as np
    from PIL import Image

    from vectorize.raster.binarize import ink_threshold, paper_gray
    from vectorize.raster.image_io import load_image

    image, _ = load_image(str(loop_png), max_size=1000)
    for query, threshold, blur in (("threshold=auto&blur=0", None, 0.0), ("threshold=0.6&blur=1.5", 0.6, 1.5)):
        answer = client.get(f"/api/mask?{query}")
        assert answer.status_code == 200 and answer.headers["content-type"] == "image/png"
        mask = np.asarray(Image.open(BytesIO(answer.content)))[..., 1] > 0
        gray, _ = paper_gray(image, max_size=1000, blur=blur)
        assert np.array_equal(mask, gray < ink_threshold(gray, threshold)) and mask.any()
    refused = client.get("/api/mask?threshold=auto&blur=30")
    assert refused.status_code == 400 and refused.json()["error"] == "--blur 30 must be from 0 px to 25 px"
    assert client.get("/api/mask?threshold=1").json()["error"] == "--threshold 1 must be above 0 to below 1"
    assert client.get("/api/mask?threshold=x").status_code == 400

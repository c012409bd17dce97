"""Every export button of the studio, clicked in a real browser after an edit and with
option values typed and picked in the panels, downloads the bytes the CLI writes for the
same drawing, edits file and flags (real `onestroke vectorize|embroider|laser` runs)."""

from __future__ import annotations

import json

import pytest

from tests.chromium import ARTIFACTS
from tests.studio.browser_page import cli_bytes, click_at, download, settle

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def edited(page):
    """The page after a user's edit: one junction clicked to its next pairing."""
    junction = page.evaluate("window.studio.state.graph.junctions.find(j => j.role === 'crossing')")
    click_at(page, junction["at"])
    settle(page, 1)
    edits = page.evaluate("window.studio.state.edits")
    assert edits["edits"][0]["kind"] == "pairing"
    return edits


def play_the_panel(page, panel: str) -> None:
    """The panel's player shows the finished job; its Play runs it from the start: the
    stitch (or line) number moves on, then stops where Play is pressed again."""
    number = f"#{panel}-player [data-role=number]"
    total = page.inner_text(number)
    page.click(f"#{panel}-player [data-role=play]")
    page.wait_for_timeout(700)
    page.click(f"#{panel}-player [data-role=play]")
    now = page.inner_text(number)
    count = int(now.split("/")[0].replace(",", "").strip())
    assert now != total and count > 0, (now, total)


@pytest.mark.parametrize("kind", ["svg", "json"])
def test_drawing_downloads(page, studio, edited, tmp_path, kind):
    page.click("nav .tab[data-tab=refine]")
    name, data = download(page, f"[data-export={kind}]")
    assert name == f"loops.{kind}"
    assert data == cli_bytes("vectorize", studio[1], edited, tmp_path, f".{kind}")


EMBROIDERY = [("pes", "zigzag", "70mm", "130x180", "#c01020"), ("dst", "triple", "60mm", "100x100", "#1f3a93"),
              ("jef", "arrows", "95mm", "130x180", "#1f3a93"), ("exp", "running", "50mm", "100x100", "#208040"),
              ("vp3", "running", "80mm", "100x100", "#c01020")]


@pytest.mark.parametrize("kind, style, size, hoop, color", EMBROIDERY)
def test_embroidery_downloads(page, studio, edited, tmp_path, kind, style, size, hoop, color):
    page.click("nav .tab[data-tab=embroidery]")
    form = "#embroidery-form"
    page.select_option(f"{form} select[name=style]", style)
    page.fill(f"{form} input[name=size]", size)
    page.select_option(f"{form} select[name=hoop]", hoop)
    page.fill(f"{form} input[name=stitch_length]", "3mm")
    page.fill(f"{form} input[name=color]", color)
    page.press(f"{form} input[name=stitch_length]", "Tab")  # a typed field reports its change on leaving it
    settle(page, extra="document.getElementById('embroidery-stats').textContent.includes('stitches')")
    # The hoop chosen is in the picture (drawn whole inside the preview), the design in it.
    box = page.evaluate("window.studio.players.embroidery.frameBox()")
    assert box and 0 <= box[0] < box[2] <= 1 and 0 <= box[1] < box[3] <= 1, box
    if kind == "pes":
        play_the_panel(page, "embroidery")
        page.screenshot(path=str(ARTIFACTS / "studio-make-embroidery.png"))
    name, data = download(page, f"[data-export={kind}]")
    assert name == f"loops.{kind}"
    assert data == cli_bytes("embroider", studio[1], edited, tmp_path, f".{kind}", "--style", style, "--size", size,
                             "--hoop", hoop, "--stitch-length", "3mm", "--color", color)


def test_gcode_download(page, studio, edited, tmp_path):
    page.click("nav .tab[data-tab=laser]")
    form = "#laser-form"
    page.fill(f"{form} input[name=size]", "60mm")
    page.fill(f"{form} input[name=feed]", "1200mm/min")
    page.fill(f"{form} input[name=power]", "35%")
    page.fill(f"{form} input[name=passes]", "2")
    page.select_option(f"{form} select[name=origin]", "center")
    page.check(f"{form} input[name=arcs]")
    settle(page, extra="document.getElementById('laser-time').textContent.includes('estimated')")
    play_the_panel(page, "laser")
    page.screenshot(path=str(ARTIFACTS / "studio-make-laser.png"))
    name, data = download(page, "[data-export=gcode]")
    assert name == "loops.gcode"
    assert data == cli_bytes("laser", studio[1], edited, tmp_path, ".gcode", "--size", "60mm", "--feed", "1200mm/min",
                             "--power", "35%", "--passes", "2", "--origin", "center", "--arcs")
    assert b"G2" in data or b"G3" in data  # the arcs box took effect


def test_options_that_fail_name_the_field_and_dim_the_old_preview(page):
    """A size the bed cannot hold: the error names the page's field ("Size", not the CLI's
    --size), the toolpath still shown is dimmed and said to be the last one that worked;
    a good value brings it back."""
    page.click("nav .tab[data-tab=laser]")
    settle(page, extra="document.getElementById('laser-time').textContent.includes('estimated')")
    size = page.input_value("#laser-form input[name=size]")
    page.fill("#laser-form input[name=size]", "900mm")
    page.press("#laser-form input[name=size]", "Tab")
    page.wait_for_function("document.getElementById('laser-stale').textContent.includes('does not fit the bed')")
    text = page.inner_text("#laser-stale")
    assert 'a smaller "Size"' in text and "--size" not in text and "last options that worked" in text, text
    assert page.is_visible("#laser-stale") and page.evaluate(
        "getComputedStyle(document.getElementById('laser-player')).opacity") == "0.35"
    page.screenshot(path=str(ARTIFACTS / "studio-make-laser-refused.png"))
    page.fill("#laser-form input[name=size]", size)
    page.press("#laser-form input[name=size]", "Tab")
    page.wait_for_function("document.getElementById('laser-stale').hidden")
    assert "does not fit" not in page.inner_text("#tab-laser")


K40 = """name = "K40 studio test laser"
[bed]
size = "300x200mm"
[laser]
max_power = 255
[motion]
acceleration_x = "300mm/s^2"
acceleration_y = "250mm/s^2"
"""


def test_load_a_machine_profile(page, studio, edited, tmp_path):
    """"Load a profile…" through the file input: a bad file is refused in one line and the
    profile in use kept; a good one is offered, chosen, named in the stats, drives the G-code
    (the CLI's bytes with --profile FILE) and the bed check, whose error names the select."""
    page.click("nav .tab[data-tab=laser]")
    form = "#laser-form"
    for name, value in (("size", "60mm"), ("feed", "1500mm/min"), ("power", "60%"), ("passes", "1")):
        page.fill(f"{form} input[name={name}]", value)
    page.select_option(f"{form} select[name=origin]", "lower-left")
    page.uncheck(f"{form} input[name=arcs]")
    settle(page, extra="document.getElementById('laser-time').textContent.includes('profile: Generic')")
    before = page.input_value("#profile")
    page.set_input_files("#profile-file", files=[{"name": "broken.toml", "mimeType": "text/plain",
                                                  "buffer": b"[motion]\nmax_rate_x = \n"}])
    page.wait_for_function("document.getElementById('profile-status').dataset.state === 'error'")
    status = page.inner_text("#profile-status")
    assert "not valid TOML" in status and "unchanged" in status and "\n" not in status, status
    assert page.input_value("#profile") == before and "profile: Generic" in page.inner_text("#laser-time")
    page.screenshot(path=str(ARTIFACTS / "studio-make-laser-profile-refused.png"))

    (tmp_path / "k40.toml").write_text(K40)
    page.set_input_files("#profile-file", str(tmp_path / "k40.toml"))
    page.wait_for_function("document.getElementById('profile-status').textContent.startsWith('loaded k40.toml')")
    settle(page, extra="document.getElementById('laser-time').textContent.includes('profile: K40 studio test laser')")
    assert page.input_value("#profile") != before
    page.screenshot(path=str(ARTIFACTS / "studio-make-laser-profile.png"))
    name, data = download(page, "[data-export=gcode]")
    assert data == cli_bytes("laser", studio[1], edited, tmp_path, ".gcode", "--size", "60mm", "--profile",
                             str(tmp_path / "k40.toml"))
    assert b"S153" in data  # 60 % of the loaded profile's max S 255

    page.fill(f"{form} input[name=size]", "350mm")  # fits the default 400 mm bed, not this 300 x 200 mm one
    page.press(f"{form} input[name=size]", "Tab")
    page.wait_for_function("!document.getElementById('laser-stale').hidden && "
                           "document.getElementById('laser-stale').textContent.includes('does not fit the bed')")
    text = page.inner_text("#laser-stale")
    assert '"Machine profile"' in text and "--profile" not in text, text
    page.select_option("#profile", before)  # the built-in profile's bed holds it
    page.wait_for_function("document.getElementById('laser-stale').hidden")
    assert "profile: Generic" in page.inner_text("#laser-time")
    page.fill(f"{form} input[name=size]", "60mm")
    page.press(f"{form} input[name=size]", "Tab")
    settle(page)


def test_header_actions_answer_in_the_panel_in_view(page, studio, tmp_path):
    """Open, load and save sit in the header, at hand on every tab: on the Embroidery tab
    what they say is in that panel (it used to go to the hidden Refine panel, and the
    user saw nothing)."""
    page.click("nav .tab[data-tab=embroidery]")
    settle(page, extra="document.getElementById('embroidery-stats').textContent.includes('stitches')")
    edits = page.evaluate("window.studio.state.edits")
    (tmp_path / "notes.json").write_text("these are not edits")
    page.set_input_files("#open", str(tmp_path / "notes.json"))
    page.wait_for_function("document.getElementById('embroidery-warnings').textContent.includes('notes.json')")
    assert page.inner_text("#embroidery-warnings") == "error: notes.json is not an edits file (not JSON)"
    (tmp_path / "other.json").write_text('{"format": "something else"}')
    page.set_input_files("#open", str(tmp_path / "other.json"))
    page.wait_for_function("document.getElementById('embroidery-warnings').textContent.includes('not an onestroke')")
    settle(page)
    assert page.is_visible("#embroidery-warnings") and page.evaluate("window.studio.state.edits") == edits
    saved = studio[1].with_suffix(".edits.json")
    if not saved.exists():
        page.click("#load")
        page.wait_for_function("document.getElementById('embroidery-warnings').textContent.includes('no edits saved')")
    page.click("#save")
    page.wait_for_function("document.getElementById('embroidery-warnings').textContent.startsWith('saved ')")
    assert saved.exists() and page.is_visible("#embroidery-warnings")
    page.click("#load")
    page.wait_for_function("document.getElementById('embroidery-warnings').textContent.includes('already')")
    # An edit made on the drawing meanwhile: new stitches, and the note makes way for the
    # panel's own warnings.
    junction = page.evaluate("window.studio.state.graph.junctions.find(j => j.role === 'crossing')")
    click_at(page, junction["at"])
    settle(page, extra="window.studio.state.edits.edits.some(e => e.kind === 'pairing' && e.pairing !== "
                       f"{json.dumps(junction['decision'])}) && "
                       "!document.getElementById('embroidery-warnings').textContent.includes('already')")
    page.click("#undo")
    settle(page)
    assert page.evaluate("window.studio.state.edits") == edits
    page.click("nav .tab[data-tab=refine]")

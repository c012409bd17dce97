"""The studio's refinement as a user clicks it, in a real browser (Playwright driving
Debian's Chromium): the curve on the page, a junction clicked through its three pairings,
undo/redo by button and keyboard, play and the scrubber, the threshold and blur sliders
dragged with the mouse (busy state shown, the latest value wins), multi-stroke, split,
merge, start, reverse, and the edits file saved, loaded and opened. Exports and "send to
laser": test_browser_make.py, test_browser_send.py. Screenshots go to
test-artifacts/ (kept by CI as artifacts of the run)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from tests.chromium import ARTIFACTS
from fabrication.cli import main
from tests.studio.browser_page import IDLE, click_at, coloured_pixels, download, drag_slider, curve_under_labels, settle

pytestmark = pytest.mark.slow

STATE = "window.studio.state"


def junction_near(page, at):
    return page.evaluate(f"""{STATE}.graph.junctions.filter(j => j.role === 'crossing').reduce((best, j) =>
        Math.hypot(j.at[0] - {at[0]}, j.at[1] - {at[1]}) < Math.hypot(best.at[0] - {at[0]}, best.at[1] - {at[1]})
        ? j : best)""")


def order(page):
    return page.evaluate(f"{STATE}.strokes.map(s => s.points)")


def test_click_a_junction_through_its_pairings_undo_redo_and_play(page):
    page.screenshot(path=str(ARTIFACTS / "studio-1-loaded.png"))
    assert coloured_pixels(page) > 3000  # the curve, coloured start to end, is on the canvas
    assert "1 stroke, 3 crossings" in page.inner_text("#summary")
    under = curve_under_labels(page)  # the three crossings' texts, beside the curve, not on it
    assert under == {"crossing 100%": 0}, under
    assert len(page.evaluate("window.studio.placed")) == 3
    count = page.evaluate(f"{STATE}.edits.edits.length")

    # Each click on a junction moves it to the next pairing (crossing -> touching -> third
    # -> crossing), re-runs traversal and fitting and changes the drawing order.
    start = page.evaluate(f"{STATE}.graph.junctions.find(j => j.role === 'crossing')")
    seen, orders = [start["decision"]], [order(page)]
    for click in range(3):
        click_at(page, start["at"])
        settle(page, count + 1)  # the click set the busy state at once: this waits for its answer
        junction = junction_near(page, start["at"])
        assert junction["fixed"] and "(yours; CNN: crossing 100%)" in page.inner_text("#junctions")
        seen.append(junction["decision"])
        orders.append(order(page))
        if click == 0:
            page.screenshot(path=str(ARTIFACTS / "studio-2-junction-clicked.png"))
    assert sorted(seen[:3]) == ["crossing", "third", "touching"] and seen[3] == seen[0], seen
    assert orders[1] != orders[0] and orders[2] != orders[1]
    assert len(page.evaluate(f"{STATE}.edits.edits")) == count + 1  # one pairing per junction, replaced

    # Undo and redo, by the buttons and by Ctrl+Z / Ctrl+Y.
    page.click("#undo")
    page.wait_for_function(f"window.studio.at === 2 && {IDLE}")
    assert junction_near(page, start["at"])["decision"] == seen[2] and order(page) == orders[2]
    page.keyboard.press("Control+z")
    page.wait_for_function(f"window.studio.at === 1 && {IDLE}")
    assert junction_near(page, start["at"])["decision"] == seen[1] and order(page) == orders[1]
    page.keyboard.press("Control+y")
    page.wait_for_function(f"window.studio.at === 2 && {IDLE}")
    page.click("#redo")
    page.wait_for_function(f"window.studio.at === 3 && {IDLE}")
    assert junction_near(page, start["at"])["decision"] == seen[3] and page.is_disabled("#redo")
    page.click("#undo")
    page.click("#undo")  # back to the first click's pairing: the later tests start from it
    page.wait_for_function(f"window.studio.at === 1 && {IDLE}")

    # Play: the pen moves along the curve; the part behind it is coloured, the rest grey.
    full = coloured_pixels(page)
    page.click("#play")
    page.wait_for_function("window.studio.pen > 0.2 && window.studio.pen < 0.8", polling=50)
    page.click("#play")  # pause
    pen = page.evaluate("window.studio.pen")
    assert 0.2 < pen < 0.8 and coloured_pixels(page) < full
    assert "/" in page.inner_text("#where")
    page.screenshot(path=str(ARTIFACTS / "studio-3-playing.png"))
    # The paused pen keeps its place on the drawing through later edits: put it on the first
    # stroke away from every junction, reverse that stroke (its share of the length turns
    # over), undo (back).
    share = page.evaluate(f"""(() => {{ const t = window.studio.line, n = {STATE}.strokes[0].points.length;
        for (let i = Math.floor(n / 5); i < n; i++) if ({STATE}.graph.junctions.every(j =>
            Math.hypot(j.at[0] - t.pts[i][0], j.at[1] - t.pts[i][1]) > 40)) return t.cum[i] / t.total; }})()""")
    page.eval_on_selector("#scrub", f"e => {{ e.value = {round(share * 1000)}; e.dispatchEvent(new Event('input')); }}")
    spot, pen = page.evaluate("window.studio.penPoint()"), page.evaluate("window.studio.pen")
    first = page.evaluate(f"{STATE}.strokes[0].length") / page.evaluate("window.studio.line.total")
    page.click("#reverse-all")
    settle(page, count + 2)
    moved = page.evaluate("window.studio.penPoint()")
    assert abs(moved[0] - spot[0]) < 2.5 and abs(moved[1] - spot[1]) < 2.5, (spot, moved)
    assert page.evaluate("window.studio.pen") == pytest.approx(first - pen, abs=0.003)
    assert page.evaluate("Number(document.getElementById('scrub').value)") == round(page.evaluate("window.studio.pen") * 1000)
    page.click("#undo")
    settle(page, count + 1)
    assert page.evaluate("window.studio.penPoint()") == spot
    assert page.evaluate("window.studio.pen") == pytest.approx(pen, abs=0.001)
    # The scrubber, dragged with the mouse, puts the pen where it is let go.
    drag_slider(page, "#scrub", 0.25)
    assert abs(page.evaluate("window.studio.pen") - 0.25) < 0.03
    quarter = coloured_pixels(page)
    assert quarter < full * 0.45
    # The space bar plays and pauses (focus on the drawing, not on a control).
    page.click("#canvas", position={"x": 5, "y": 5})
    page.keyboard.press("Space")
    page.wait_for_function("window.studio.playing && window.studio.pen > 0.3", polling=50)
    page.keyboard.press("Space")
    assert not page.evaluate("window.studio.playing")
    drag_slider(page, "#scrub", 1.0)
    assert page.evaluate("window.studio.pen") == 1 and coloured_pixels(page) == full


def test_sliders_dragged_show_busy_and_the_latest_value_wins(page):
    at = page.evaluate("window.studio.at")
    # Automatic: the slider rests on the level Li's method chose, and says it.
    li = page.evaluate(f"{STATE}.report.threshold")
    assert 0 < li < 1 and page.inner_text("#threshold-value") == f"auto {li:.2f}"
    assert float(page.eval_on_selector("#threshold", "e => e.value")) == pytest.approx(li, abs=0.005)
    # Threshold: dragging it leaves the automatic threshold and re-runs from binarization,
    # with a visible busy state until the answer is drawn.
    drag_slider(page, "#threshold", 0.45)
    value = float(page.eval_on_selector("#threshold", "e => e.value"))
    assert page.is_visible("#rerun") and page.is_visible("#busy") and not page.is_checked("#auto-threshold")
    page.screenshot(path=str(ARTIFACTS / "studio-4-threshold-busy.png"))
    settle(page, extra=f"{STATE}.settings.threshold === {value}")
    assert not page.is_visible("#rerun") and page.inner_text("#threshold-value") == f"{value:.2f}"
    assert page.evaluate("window.studio.at") == at + 1

    # Latest value wins: rest on one value long enough for its re-run to start, move on and
    # let go at another while it runs. The earlier answer is dropped; the page ends on the
    # value the slider shows, with one new step in the history.
    box = page.locator("#threshold").bounding_box()
    y = box["y"] + box["height"] / 2
    x_of = lambda f: box["x"] + 8 + f * (box["width"] - 16)  # noqa: E731 - as drag_slider
    page.mouse.move(x_of((value - 0.05) / 0.9), y)
    page.mouse.down()
    page.mouse.move(x_of(0.25), y, steps=4)
    page.wait_for_function("document.body.classList.contains('busy')")  # its preview re-run started
    resting = page.inner_text("#threshold-value")
    # From here on, every threshold the page draws is recorded.
    page.evaluate("""() => { window.drawn = [];
        new MutationObserver(() => window.drawn.push(document.getElementById('summary').textContent + ' @ ' +
            window.studio.state.settings.threshold)).observe(document.getElementById('summary'),
            {childList: true, characterData: true, subtree: true}); }""")
    page.mouse.move(x_of(0.6), y, steps=4)
    page.mouse.up()
    final = float(page.eval_on_selector("#threshold", "e => e.value"))
    assert abs(final - 0.59) < 0.011
    settle(page)
    drawn = page.evaluate("window.drawn")
    assert drawn and all(text.endswith(f"@ {final}") for text in drawn), (resting, drawn)  # never the old value
    assert page.evaluate(f"{STATE}.settings.threshold") == final
    assert page.evaluate(f"{STATE}.edits.threshold") == final
    assert page.inner_text("#threshold-value") == f"{final:.2f}"
    assert float(page.eval_on_selector("#threshold", "e => e.value")) == final
    assert page.evaluate("window.studio.at") == at + 2

    # Back to the automatic threshold; blur by dragging; multi-stroke by its checkbox.
    page.click("#auto-threshold")
    settle(page, extra=f"{STATE}.settings.threshold === null")
    assert page.inner_text("#threshold-value") == f"auto {li:.2f}"
    drag_slider(page, "#blur", 0.25)
    assert page.is_visible("#rerun")
    settle(page, extra=f"{STATE}.settings.blur === 1")
    assert page.inner_text("#blur-value") == "1"
    page.click("#multi")
    settle(page, extra=f"{STATE}.settings.multi === true")
    assert page.evaluate(f"{STATE}.report.strokes") >= 1 and page.is_checked("#multi")
    page.screenshot(path=str(ARTIFACTS / "studio-5-multi.png"))
    while page.evaluate("window.studio.at") > at:
        page.click("#undo")
    settle(page, extra=f"{STATE}.settings.threshold === null && {STATE}.settings.blur === 0 && "
                       f"{STATE}.settings.multi === false")
    assert page.is_checked("#auto-threshold") and not page.is_checked("#multi")


def test_split_merge_start_and_reverse_by_clicking(page):
    count = page.evaluate(f"{STATE}.edits.edits.length")
    crossings = page.evaluate(f"{STATE}.report.intersections")
    target = page.evaluate(f"{STATE}.graph.junctions.find(j => j.role === 'crossing' && !j.fixed)")

    # Split a crossing into its two degree-3 halves, then merge them back by their branch.
    page.check("input[name=tool][value=split]")
    click_at(page, target["at"])
    settle(page, count + 1)
    assert page.evaluate(f"{STATE}.report.intersections") == crossings - 1
    page.check("input[name=tool][value=merge]")
    branch = page.evaluate(f"""{STATE}.graph.branches.reduce((best, b) =>
        Math.hypot(b.at[0] - {target['at'][0]}, b.at[1] - {target['at'][1]}) <
        Math.hypot(best.at[0] - {target['at'][0]}, best.at[1] - {target['at'][1]}) ? b : best)""")
    page.screenshot(path=str(ARTIFACTS / "studio-6-split-merge-handles.png"))
    click_at(page, branch["at"])
    settle(page, count + 2)
    assert page.evaluate(f"{STATE}.report.intersections") == crossings

    # Start at the other end, then reverse: back where it started.
    strokes = page.evaluate(f"{STATE}.strokes.map(s => [s.points[0], s.points[s.points.length - 1]])")
    end = strokes[0][1]
    page.check("input[name=tool][value=start]")
    click_at(page, end)
    settle(page, count + 3)
    first = page.evaluate(f"{STATE}.strokes[0].points[0]")
    assert abs(first[0] - end[0]) < 3 and abs(first[1] - end[1]) < 3
    page.click("#reverse-all")
    settle(page, count + 4)
    last = page.evaluate(f"{STATE}.strokes[0].points.slice(-1)[0]")
    assert abs(last[0] - end[0]) < 3 and abs(last[1] - end[1]) < 3
    page.screenshot(path=str(ARTIFACTS / "studio-7-after-edits.png"))
    page.check("input[name=tool][value=pairing]")


def test_split_halves_a_pixel_apart_are_drawn_apart_and_each_clicks(page):
    """Split at (597, 366) leaves two unresolved degree-3 nodes 1 px apart: their markers
    fan out (each tied to its junction), each has its label, and a click on each says which
    it is and offers to merge it back or to undo the split."""
    before = page.evaluate(f"{STATE}.edits.edits.length")
    page.check("input[name=tool][value=split]")
    click_at(page, junction_near(page, (597, 366))["at"])
    # (a pairing chosen there by the first test goes with the split)
    settle(page, extra=f"{STATE}.edits.edits.some(e => e.kind === 'split' && Math.abs(e.at[0] - 597) < 3)")
    count = page.evaluate(f"{STATE}.edits.edits.length")
    assert count in (before, before + 1)
    halves = page.evaluate(f"{STATE}.graph.junctions.filter(j => j.role === 'unresolved')")
    assert len(halves) == 2 and abs(halves[0]["at"][0] - halves[1]["at"][0]) < 3
    places = [page.evaluate(f"window.studio.markerAt({j['id']})") for j in halves]
    assert abs(places[0][0] - places[1][0]) + abs(places[0][1] - places[1][1]) > 2 * 9  # apart: radius 7 + ring
    labels = page.evaluate("window.studio.placed.filter(p => p.text === 'unresolved').map(p => p.box)")
    assert len(labels) == 2
    a, b = labels
    assert a[0] + a[2] <= b[0] or b[0] + b[2] <= a[0] or a[1] + a[3] <= b[1] or b[1] + b[3] <= a[1]  # no overlap
    # Every two texts there ("unresolved" twice, the "×2" between them) stand apart: boxes
    # side by side used to read as one word ("unresolved×2").
    boxes = page.evaluate("window.studio.placed.map(p => p.box)")
    for i, p in enumerate(boxes):
        for q in boxes[i + 1:]:
            assert max(q[0] - (p[0] + p[2]), p[0] - (q[0] + q[2]), q[1] - (p[1] + p[3]), p[1] - (q[1] + q[3])) >= 6, (p, q)
    x, y = page.evaluate(f"window.studio.toScreen(597, 366)")
    page.screenshot(path=str(ARTIFACTS / "studio-7b-split-unresolved.png"), clip={"x": x - 160, "y": y - 90,
                                                                                  "width": 320, "height": 180})
    page.check("input[name=tool][value=pairing]")
    for j, place in zip(halves, places):
        page.mouse.click(*place)
        page.wait_for_function("!document.getElementById('hint').hidden")
        assert f"({j['at'][0]:.0f}, {j['at'][1]:.0f}) unresolved" in page.inner_text("#hint")
        assert page.locator("#hint button").count() == 2  # merge back, undo the split
    assert page.evaluate(f"{STATE}.edits.edits.length") == count  # a click there only explains
    page.screenshot(path=str(ARTIFACTS / "studio-7c-unresolved-hint.png"))
    page.click("#hint .merge-here")
    settle(page, count + 1)
    assert page.evaluate(f"{STATE}.edits.edits.slice(-1)[0].kind") == "merge"
    assert not page.evaluate(f"{STATE}.graph.junctions.filter(j => j.role === 'unresolved').length")
    assert junction_near(page, (597, 366))["role"] == "crossing" and page.is_hidden("#hint")
    # From the junction list, "undo the split here" drops the split instead.
    page.click("#undo")
    settle(page, count)
    page.click("#junctions li.unresolved .unsplit")
    settle(page, count - 1)
    assert junction_near(page, (597, 366))["role"] == "crossing"


def test_zoom_pan_and_reverse_one_stroke(page):
    count = page.evaluate(f"{STATE}.edits.edits.length")
    fitted = page.evaluate("({...window.studio.view})")
    junction = page.evaluate(f"{STATE}.graph.junctions.find(j => j.role === 'crossing')")
    x, y = page.evaluate(f"window.studio.toScreen({junction['at'][0]}, {junction['at'][1]})")
    # The wheel zooms about the pointer: the junction under it stays there.
    page.mouse.move(x, y)
    page.mouse.wheel(0, -400)
    page.wait_for_function(f"window.studio.view.scale > {fitted['scale'] * 1.5}")
    after = page.evaluate(f"window.studio.toScreen({junction['at'][0]}, {junction['at'][1]})")
    assert abs(after[0] - x) < 2 and abs(after[1] - y) < 2
    # A drag pans, even when it starts on a junction: no edit is made.
    page.mouse.move(x, y)
    page.mouse.down()
    page.mouse.move(x - 150, y - 60, steps=5)
    page.mouse.up()
    moved = page.evaluate(f"window.studio.toScreen({junction['at'][0]}, {junction['at'][1]})")
    assert abs(moved[0] - (x - 150)) < 2 and abs(moved[1] - (y - 60)) < 2
    page.wait_for_timeout(200)
    assert page.evaluate(f"{STATE}.edits.edits.length") == count and page.evaluate("window.studio.at") == \
        page.evaluate("window.studio.history.length") - 1
    page.screenshot(path=str(ARTIFACTS / "studio-8-zoomed.png"))
    # A resized window keeps the zoom the user chose (it used to fit the drawing again).
    scale = page.evaluate("window.studio.view.scale")
    page.set_viewport_size({"width": 1180, "height": 720})
    page.wait_for_timeout(100)
    assert page.evaluate("window.studio.view.scale") == scale
    page.set_viewport_size({"width": 1280, "height": 760})
    page.wait_for_timeout(100)
    # Clicks still find what is under the pointer in the zoomed, panned view.
    click_at(page, junction["at"])
    settle(page, count + 1 if not junction["fixed"] else count)
    assert junction_near(page, junction["at"])["fixed"]
    page.click("#undo")
    settle(page, count)
    # Double-click fits the drawing again.
    page.dblclick("#canvas", position={"x": 5, "y": 5})
    assert page.evaluate("window.studio.view.scale") == pytest.approx(fitted["scale"])

    # The reverse tool: a click on a stroke makes it run the other way.
    before = page.evaluate(f"{STATE}.strokes.map(s => [s.points[0], s.points[s.points.length - 1]])")
    point = page.evaluate(f"{STATE}.strokes[0].points[Math.floor({STATE}.strokes[0].points.length / 3)]")
    page.check("input[name=tool][value=reverse]")
    click_at(page, point)
    settle(page, count + 1)
    now = page.evaluate(f"{STATE}.strokes.map(s => [s.points[0], s.points[s.points.length - 1]])")
    assert now[0][0] == pytest.approx(before[0][1], abs=2) and now[0][1] == pytest.approx(before[0][0], abs=2)
    page.check("input[name=tool][value=pairing]")


def test_edits_file_save_load_and_open(page, studio, tmp_path):
    _, drawing = studio
    edits = page.evaluate(f"{STATE}.edits")
    assert edits["edits"], "the earlier tests left edits to save"

    # Load before anything was saved: says so and keeps the edits (it used to apply "none").
    steps = page.evaluate("window.studio.history.length")
    page.click("#load")
    page.wait_for_function("document.getElementById('hint').textContent.includes('no edits saved yet')")
    page.wait_for_timeout(200)
    assert page.evaluate(f"{STATE}.edits") == edits and page.evaluate("window.studio.history.length") == steps
    # Save writes the edits file named on the command line; the CLI replays it to the
    # page's SVG, byte for byte.
    page.click("#save")
    page.wait_for_function("document.getElementById('summary').textContent.includes('saved')")
    saved = drawing.with_suffix(".edits.json")
    assert json.loads(saved.read_text()) == edits
    name, svg = download(page, "[data-export=svg]")
    assert name == "loops.svg"
    run = CliRunner().invoke(main, ["vectorize", str(drawing), "--edits", str(saved), "-o", str(tmp_path / "r.svg")])
    assert run.exit_code == 0, run.output
    assert svg == (tmp_path / "r.svg").read_bytes()
    # The edits.json download is the same file.
    name, data = download(page, "[data-export=edits]")
    assert name == "loops.edits.json" and data == saved.read_bytes()
    (tmp_path / name).write_bytes(data)

    # Change something, then Load: back to the saved file.
    page.click("#reverse-all")
    settle(page, len(edits["edits"]) + 1)
    page.click("#load")
    settle(page, len(edits["edits"]))
    assert page.evaluate(f"{STATE}.edits") == edits

    # Change again, then open the downloaded file through the page's file picker.
    page.click("#reverse-all")
    settle(page, len(edits["edits"]) + 1)
    page.set_input_files("#open", str(tmp_path / name))
    settle(page, len(edits["edits"]))
    assert page.evaluate(f"{STATE}.edits") == edits
    # A file that is not an edits file is answered on the page, not applied.
    (tmp_path / "bad.json").write_text('{"format": "something else"}')
    page.set_input_files("#open", str(tmp_path / "bad.json"))
    page.wait_for_function("document.getElementById('warnings').textContent.includes('not an onestroke edits file')")
    settle(page)
    assert page.evaluate(f"{STATE}.edits") == edits

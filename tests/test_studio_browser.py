"""The studio page in a real browser (Playwright driving Debian's Chromium): load, see the
curve, click a junction and see the order change, move the threshold, undo, play, export
.pes and G-code and compare their bytes with the CLI's for the same edits. Screenshots go
to test-artifacts/ (kept by CI as artifacts of the run)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from conftest import ARTIFACTS
from fabrication.cli import main
from studio_fixtures import cli_bytes, click_at, coloured_pixels, page, settle, studio  # noqa: F401 - fixtures

pytestmark = pytest.mark.slow


def test_page_refine_play_and_export(page, studio, tmp_path):
    _, drawing = studio
    page.screenshot(path=str(ARTIFACTS / "studio-1-loaded.png"))
    assert coloured_pixels(page) > 3000  # the curve, coloured start to end, is on the canvas
    assert "1 stroke, 3 crossings" in page.inner_text("#summary")

    # Click a junction: its pairing cycles and the drawing order changes.
    before = page.evaluate("window.studio.state.strokes.map(s => s.points)")
    junction = page.evaluate("window.studio.state.graph.junctions.find(j => j.role === 'crossing')")
    x, y = page.evaluate(f"window.studio.toScreen({junction['at'][0]}, {junction['at'][1]})")
    page.mouse.click(x, y)
    settle(page, 1)
    after = page.evaluate("window.studio.state.graph.junctions.find(j => j.role === 'crossing' && j.fixed)")
    assert after is not None and after["decision"] != junction["decision"]
    assert page.evaluate("window.studio.state.strokes.map(s => s.points)") != before
    assert "fixed by you" in page.inner_text("#junctions")
    page.screenshot(path=str(ARTIFACTS / "studio-2-junction-clicked.png"))

    # The threshold slider re-runs from binarization; undo goes back to the automatic one.
    page.eval_on_selector("#auto-threshold", "e => { e.checked = false; }")
    page.eval_on_selector("#threshold", "e => { e.value = 0.3; e.dispatchEvent(new Event('change')); }")
    page.wait_for_function("window.studio.state.settings.threshold === 0.3 && !document.body.classList.contains('busy')")
    assert page.inner_text("#threshold-value") == "0.30"
    page.click("#undo")
    page.wait_for_function("window.studio.state.settings.threshold === null && !document.body.classList.contains('busy')")
    page.click("#redo")
    page.wait_for_function("window.studio.state.settings.threshold === 0.3 && !document.body.classList.contains('busy')")
    page.click("#undo")
    page.wait_for_function("window.studio.state.settings.threshold === null && !document.body.classList.contains('busy')")
    assert page.evaluate("window.studio.state.edits.edits.length") == 1

    # Play: the pen moves along the curve; part of the curve is drawn, the rest is grey.
    full = coloured_pixels(page)
    page.click("#play")
    page.wait_for_function("window.studio.pen > 0.2 && window.studio.pen < 0.8", polling=50)
    page.click("#play")  # pause
    pen = page.evaluate("window.studio.pen")
    assert 0.2 < pen < 0.8 and coloured_pixels(page) < full
    page.screenshot(path=str(ARTIFACTS / "studio-3-playing.png"))
    page.eval_on_selector("#scrub", "e => { e.value = 1000; e.dispatchEvent(new Event('input')); }")

    # Exports: the same bytes as the CLI for the same edits and options.
    edits = page.evaluate("window.studio.history[window.studio.at]")
    page.click("nav .tab[data-tab=embroidery]")
    page.select_option("#embroidery-form select[name=style]", "zigzag")
    settle(page)
    page.wait_for_function("document.getElementById('embroidery-stats').textContent.includes('stitches')")
    # The stitches play in the project's player: press its play, the stitch number moves.
    page.click("#embroidery-player [data-role=play]")
    page.wait_for_timeout(600)
    page.click("#embroidery-player [data-role=play]")
    assert page.inner_text("#embroidery-player [data-role=number]").strip() not in ("", "0")
    page.screenshot(path=str(ARTIFACTS / "studio-4-embroidery.png"))
    with page.expect_download() as download:
        page.click("[data-export=pes]")
    pes = Path(download.value.path()).read_bytes()
    assert download.value.suggested_filename == "loops.pes"
    assert pes == cli_bytes("embroider", drawing, edits, tmp_path, ".pes", "--style", "zigzag", "--size", "90mm",
                            "--color", "#1f3a93")
    page.click("nav .tab[data-tab=laser]")
    settle(page)
    page.wait_for_function("document.getElementById('laser-time').textContent.includes('estimated')")
    page.screenshot(path=str(ARTIFACTS / "studio-5-laser.png"))
    with page.expect_download() as download:
        page.click("[data-export=gcode]")
    gcode = Path(download.value.path()).read_bytes()
    assert gcode == cli_bytes("laser", drawing, edits, tmp_path, ".gcode", "--size", "80mm", "--feed", "1500mm/min",
                              "--power", "60%", "--passes", "1")

    # Save: the edits file beside the drawing replays to the page's SVG.
    page.click("nav .tab[data-tab=refine]")
    page.click("#save")
    saved = drawing.with_suffix(".edits.json")
    page.wait_for_function("document.getElementById('summary').textContent.includes('saved')")
    with page.expect_download() as download:
        page.click("[data-export=svg]")
    svg = Path(download.value.path()).read_bytes()
    run = CliRunner().invoke(main, ["vectorize", str(drawing), "--edits", str(saved), "-o", str(tmp_path / "r.svg")])
    assert run.exit_code == 0, run.output
    assert svg == (tmp_path / "r.svg").read_bytes()


def test_page_split_merge_blur_start_reverse_load(page, studio):
    _, drawing = studio
    count = page.evaluate("window.studio.state.edits.edits.length")
    crossings = page.evaluate("window.studio.state.report.intersections")
    target = page.evaluate("window.studio.state.graph.junctions.find(j => j.role === 'crossing' && !j.fixed)")

    # Split a crossing into its two degree-3 halves, then merge them back by their branch.
    page.check("input[name=tool][value=split]")
    click_at(page, target["at"])
    settle(page, count + 1)
    assert page.evaluate("window.studio.state.report.intersections") == crossings - 1
    page.check("input[name=tool][value=merge]")
    branch = page.evaluate(f"""window.studio.state.graph.branches.reduce((best, b) =>
        Math.hypot(b.at[0] - {target['at'][0]}, b.at[1] - {target['at'][1]}) <
        Math.hypot(best.at[0] - {target['at'][0]}, best.at[1] - {target['at'][1]}) ? b : best)""")
    page.screenshot(path=str(ARTIFACTS / "studio-6-split-merge-handles.png"))
    click_at(page, branch["at"])
    settle(page, count + 2)
    assert page.evaluate("window.studio.state.report.intersections") == crossings

    # Blur re-runs from binarization.
    page.eval_on_selector("#blur", "e => { e.value = 1; e.dispatchEvent(new Event('change')); }")
    page.wait_for_function("window.studio.state.settings.blur === 1 && !document.body.classList.contains('busy')")

    # Start at the other end, then reverse: back where it started.
    strokes = page.evaluate("window.studio.state.strokes.map(s => [s.points[0], s.points[s.points.length - 1]])")
    end = strokes[0][1]
    page.check("input[name=tool][value=start]")
    click_at(page, end)
    settle(page, count + 3)
    first = page.evaluate("window.studio.state.strokes[0].points[0]")
    assert abs(first[0] - end[0]) < 3 and abs(first[1] - end[1]) < 3
    page.click("#reverse-all")
    settle(page, count + 4)
    last = page.evaluate("window.studio.state.strokes[0].points.slice(-1)[0]")
    assert abs(last[0] - end[0]) < 3 and abs(last[1] - end[1]) < 3
    page.screenshot(path=str(ARTIFACTS / "studio-7-after-edits.png"))

    # Load edits: back to the file saved by the first test.
    page.click("#load")
    page.wait_for_function(f"window.studio.state.edits.edits.length === {count} && "
                           "!document.body.classList.contains('busy')")
    saved = json.loads(drawing.with_suffix(".edits.json").read_text())
    assert page.evaluate("window.studio.state.edits.edits") == saved["edits"]

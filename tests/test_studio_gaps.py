"""A pen gap the vectorizer bridged, kept open by an "unbridge" edit: through the library
(cached as fresh, matched or said to match nothing), through the studio's API (Starlette's
test client) and replayed by `onestroke vectorize --edits` byte for byte."""

from __future__ import annotations

import json

import pytest
from click.testing import CliRunner
from starlette.testclient import TestClient

from fabrication.cli import main
from fabrication.studio.app import create_app
from fabrication.studio.session import StudioSession
from tests.conftest import render_polylines
from vectorize import VectorizeOptions, vectorize_file
from vectorize.refine.edits import Edit, Edits
from vectorize.refine.refine import StageCache
from vectorize.svg_write import drawing_to_svg

OPTIONS = VectorizeOptions(classifier="geometric")
HOST, TOKEN = "127.0.0.1:8765", "gap-token"


@pytest.fixture(scope="module")
def two_strokes(tmp_path_factory):
    """Two strokes, 6 px wide, drawn end to end with 14 px of paper between them (under
    two stroke widths: the vectorizer takes it for a pen gap), the left one the longer."""
    from PIL import Image

    path = tmp_path_factory.mktemp("gaps") / "two-strokes.png"
    left = [(40.0, 200.0), (120.0, 170.0), (200.0, 200.0)]
    right = [(214.0, 200.0), (290.0, 230.0), (330.0, 210.0)]
    Image.fromarray(render_polylines([left, right])).save(path)
    return path


def middle(gap) -> tuple[float, float]:
    (ax, ay), (bx, by) = gap
    return ((ax + bx) / 2, (ay + by) / 2)


def test_an_opened_gap_leaves_the_largest_piece_with_a_warning(two_strokes):
    cache = StageCache()
    base = vectorize_file(two_strokes, OPTIONS, edits=Edits(), cache=cache)
    assert len(base.graph.bridges) == 1 and not base.graph.unbridged
    assert base.report.strokes == 1 and base.report.dropped_components == 0
    (gap,) = base.graph.bridges
    assert 200 < middle(gap)[0] < 214
    edits = Edits(items=(Edit(kind="unbridge", at=middle(gap)),))
    opened = vectorize_file(two_strokes, OPTIONS, edits=edits, cache=cache)
    fresh = vectorize_file(two_strokes, OPTIONS, edits=edits)
    assert drawing_to_svg(opened.drawing) == drawing_to_svg(fresh.drawing)
    assert not opened.graph.bridges and [middle(g) for g in opened.graph.unbridged] == [pytest.approx(middle(gap))]
    # Two pieces: single-line mode keeps the largest (the left stroke) and says so.
    assert opened.report.dropped_components == 1 and opened.report.strokes == 1
    assert any("1 separate ink piece(s) dropped" in w for w in opened.report.warnings)
    assert not any("matched nothing" in w for w in opened.report.warnings)
    (stroke,) = opened.drawing.strokes
    xs = stroke.flatten(0.5)[:, 0]
    assert xs.max() < 206 and xs.min() < 45
    # Multi-stroke mode bridges nothing: both pieces are strokes, the edit is not "unmatched".
    multi = vectorize_file(two_strokes, OPTIONS, edits=Edits(multi=True, items=edits.items), cache=cache)
    assert multi.report.strokes == 2 and not multi.report.warnings
    # Where no gap was bridged, the edit matched nothing and says so.
    astray = vectorize_file(two_strokes, OPTIONS, edits=Edits(items=(Edit(kind="unbridge", at=(60.0, 60.0)),)),
                            cache=cache)
    assert any("unbridge" in w and "matched nothing" in w for w in astray.report.warnings)
    # Without the edit the cached bridged answer comes back (undo).
    again = vectorize_file(two_strokes, OPTIONS, edits=Edits(), cache=cache)
    assert drawing_to_svg(again.drawing) == drawing_to_svg(base.drawing)


def test_the_page_opens_a_gap_and_the_cli_replays_it_byte_for_byte(two_strokes, tmp_path):
    session = StudioSession(two_strokes, edits_path=tmp_path / "saved.edits.json", classifier="geometric")
    with TestClient(create_app(session, token=TOKEN, hosts={HOST}), base_url=f"http://{HOST}") as client:
        client.headers["X-Studio-Token"] = TOKEN
        state = client.get("/api/state").json()
        (gap,) = state["graph"]["bridges"]
        assert state["report"]["dropped"] == 0 and state["graph"]["unbridged"] == []
        edits = dict(state["edits"], edits=[{"kind": "unbridge", "at": list(middle(gap))}])
        opened = client.post("/api/state", json={"edits": edits}).json()
        assert opened["graph"]["bridges"] == [] and opened["graph"]["unbridged"] == [gap]
        assert opened["report"]["dropped"] == 1 and opened["report"]["strokes"] == 1
        svg = client.post("/api/export/svg", json={"edits": edits})
        assert svg.status_code == 200
        assert client.post("/api/edits", json={"edits": edits}).status_code == 200
    saved = json.loads((tmp_path / "saved.edits.json").read_text())
    assert saved["edits"] == [{"kind": "unbridge", "at": [round(v, 3) for v in middle(gap)]}]
    run = CliRunner().invoke(main, ["vectorize", str(two_strokes), "--classifier", "geometric",
                                    "--edits", str(tmp_path / "saved.edits.json"), "-o", str(tmp_path / "cli.svg")])
    assert run.exit_code == 0, run.output
    assert (tmp_path / "cli.svg").read_bytes() == svg.content
    assert "dropped" in run.output

"""The studio's edits as plain data: JSON round trip, cached replay equal to a fresh run,
each edit kind acting where it should, and `--edits` on the command line."""

from __future__ import annotations

import json

import pytest
from click.testing import CliRunner

from fabrication.cli import main
from tests.conftest import alpha_loop, render_polylines
from vectorize import VectorizeOptions, vectorize_file
from vectorize.refine.edits import PAIRINGS, Edit, Edits, edits_from_json
from vectorize.refine.refine import StageCache
from vectorize.svg_write import drawing_to_svg

OPTIONS = VectorizeOptions(classifier="geometric")


@pytest.fixture(scope="module")
def loop_png(tmp_path_factory):
    from PIL import Image

    path = tmp_path_factory.mktemp("studio") / "loop.png"
    Image.fromarray(render_polylines([alpha_loop()])).save(path)
    return path


def crossing(result):
    return next(j for j in result.graph.junctions if j.role == "crossing")


def test_edits_json_round_trip():
    edits = Edits(threshold=0.4, blur=1.5, multi=False, tolerance=5.0,
                  items=(Edit(kind="pairing", at=(10.5, 20.25), pairing="third"), Edit(kind="split", at=(1, 2)),
                         Edit(kind="merge", at=(3, 4)), Edit(kind="reverse", at=(5, 6)), Edit(kind="start", at=(7, 8)),
                         Edit(kind="twice", at=(11, 12)), Edit(kind="once", at=(13, 14)),
                         Edit(kind="passes", at=(9, 10), passes=((10.5, 190.5), (70, 250), (130, 310)))))
    again = edits_from_json(edits.to_json())
    assert again == edits
    assert json.loads(edits.to_json())["edits"][0] == {"kind": "pairing", "at": [10.5, 20.25], "pairing": "third"}
    assert json.loads(edits.to_json())["edits"][-1]["passes"] == [[10.5, 190.5], [70.0, 250.0], [130.0, 310.0]]


def test_passes_name_a_triple_points_branches_by_direction():
    """An edit's directions go to the nearest branches, one each, whatever the slot order;
    a direction far from every branch, or a count that differs, matches nothing."""
    import numpy as np

    from vectorize.refine.pass_choices import as_angles, foot_angles, slots_of

    angles = foot_angles(np.array([[np.cos(a), np.sin(a)] for a in np.radians([200, 20, 265, 85, 330, 150])]))
    assert angles.tolist() == [200.0, 20.0, 265.0, 85.0, 330.0, 150.0]
    assert slots_of([[22, 198], [87, 262], [148, 331]], angles) == ((0, 1), (2, 3), (4, 5))
    assert slots_of([[20, 85], [150, 200], [265, 330]], angles) == ((0, 5), (1, 3), (2, 4))
    assert as_angles(((0, 5), (1, 3), (2, 4)), angles) == [[20.0, 85.0], [150.0, 200.0], [265.0, 330.0]]
    assert slots_of([[20, 85], [150, 200], [265, 40]], angles) is None  # 40 would go to 330, 70 degrees off
    assert slots_of([[20, 85], [150, 200]], angles) is None


@pytest.mark.parametrize("text, message", [
    ("{", "not JSON"), ('{"format": "x"}', "not an onestroke edits file"),
    ('{"format": "onestroke-edits", "version": 1, "edits": [{"kind": "fold", "at": [1, 2]}]}', "unknown edit kind"),
    ('{"format": "onestroke-edits", "version": 1, "edits": [{"kind": "pairing", "at": [1, 2]}]}', "pairing"),
    ('{"format": "onestroke-edits", "version": 1, "threshold": 2, "edits": []}', "threshold"),
    ('{"format": "onestroke-edits", "version": 1, "edits": [{"kind": "passes", "at": [1, 2], "passes": [[1, 2]]}]}',
     "three or more pairs"),
    ('{"format": "onestroke-edits", "version": 1, "edits": [{"kind": "passes", "at": [1, 2], "passes": "x"}]}',
     "passes: expected array or null"),
    ('{"format": "onestroke-edits", "version": 1, "edits": [{"kind": "split", "at": [1, 2], "passes": [[1, 2]]}]}',
     "takes no passes"),
])
def test_bad_edits_files_name_the_problem(text, message):
    from onestroke.errors import InputError

    with pytest.raises(InputError, match=message):
        edits_from_json(text)


def test_each_edit_kind_and_cached_replay_equal_fresh(loop_png):
    cache = StageCache()
    base = vectorize_file(loop_png, OPTIONS, edits=Edits(), cache=cache)
    plain = vectorize_file(loop_png, OPTIONS)
    assert drawing_to_svg(base.drawing) == drawing_to_svg(plain.drawing)
    junction = crossing(base)
    assert junction.merged and junction.decision in PAIRINGS
    other = PAIRINGS[(PAIRINGS.index(junction.decision) + 1) % 3]
    cases = {
        "pairing": Edits(items=(Edit(kind="pairing", at=junction.at, pairing=other),)),
        "split": Edits(items=(Edit(kind="split", at=junction.at),)),
        "reverse": Edits(items=(Edit(kind="reverse", at=junction.at),)),
        "threshold": Edits(threshold=0.3, blur=1.0),
    }
    results = {}
    for name, edits in cases.items():
        cached = vectorize_file(loop_png, OPTIONS, edits=edits, cache=cache)
        fresh = vectorize_file(loop_png, OPTIONS, edits=edits)
        assert drawing_to_svg(cached.drawing) == drawing_to_svg(fresh.drawing), name
        assert not any("matched nothing" in w for w in cached.report.warnings), name
        results[name] = cached
    fixed = crossing(results["pairing"])
    assert fixed.fixed and fixed.decision == other
    assert drawing_to_svg(results["pairing"].drawing) != drawing_to_svg(base.drawing)
    # Split: the crossing is gone, two degree-3 nodes and the branch between them remain.
    split = results["split"].graph
    assert not [j for j in split.junctions if j.role == "crossing"]
    bridge = min(split.branches, key=lambda b: (b.at[0] - junction.at[0]) ** 2 + (b.at[1] - junction.at[1]) ** 2)
    # The branch names the two nodes it joins (the page merges an unresolved junction by them).
    assert len(set(bridge.nodes)) == 2 and set(bridge.nodes) <= {j.id for j in split.junctions if j.degree == 3}
    # Merge by that branch: the crossing is back and the drawing is the automatic one again.
    merged = vectorize_file(loop_png, OPTIONS, edits=Edits(items=(Edit(kind="split", at=junction.at),
                                                                  Edit(kind="merge", at=bridge.at))), cache=cache)
    assert len([j for j in merged.graph.junctions if j.role == "crossing"]) == 1
    assert drawing_to_svg(merged.drawing) == drawing_to_svg(base.drawing)
    stroke, reversed_ = base.drawing.strokes[0], results["reverse"].drawing.strokes[0]
    assert (reversed_.start == stroke.end).all() and (reversed_.end == stroke.start).all()
    # Start at the current end: the same as reversing an open line.
    start = vectorize_file(loop_png, OPTIONS, edits=Edits(items=(Edit(kind="start", at=tuple(stroke.end)),)), cache=cache)
    assert drawing_to_svg(start.drawing) == drawing_to_svg(results["reverse"].drawing)


def test_mode_and_threshold_reuse_earlier_stages(loop_png):
    """Multi-stroke mode shares binarization and the medial axis with single-line mode, and a
    new threshold shares the paper-flattened gray: the cached answers equal fresh runs."""
    cache = StageCache()
    vectorize_file(loop_png, OPTIONS, edits=Edits(), cache=cache)
    for edits in (Edits(multi=True), Edits(threshold=0.45), Edits(threshold=0.45, multi=True)):
        cached = vectorize_file(loop_png, OPTIONS, edits=edits, cache=cache)
        fresh = vectorize_file(loop_png, OPTIONS, edits=edits)
        assert drawing_to_svg(cached.drawing) == drawing_to_svg(fresh.drawing), edits
    assert (len(cache.paper), len(cache.axis), len(cache.front)) == (1, 2, 4)


def test_unmatched_edit_is_a_warning(loop_png):
    result = vectorize_file(loop_png, OPTIONS, edits=Edits(items=(Edit(kind="split", at=(2.0, 2.0)),)))
    assert any("matched nothing" in w for w in result.report.warnings)


def test_cached_warnings_name_the_edits_a_fresh_run_names(loop_png):
    """A cached stage remembers the edits it acted on by what they say: the same split after
    another first edit (an undo, an opened file) is still heeded, and the edit that matched
    nothing is still the one named."""
    cache = StageCache()
    junction = crossing(vectorize_file(loop_png, OPTIONS, edits=Edits(), cache=cache))
    split, astray = Edit(kind="split", at=junction.at), Edit(kind="reverse", at=(2.0, 2.0))
    for items in ((astray, split), (split, astray), (split,)):
        cached = vectorize_file(loop_png, OPTIONS, edits=Edits(items=items), cache=cache)
        fresh = vectorize_file(loop_png, OPTIONS, edits=Edits(items=items))
        assert cached.report.warnings == fresh.report.warnings, items
        skipped = [w for w in cached.report.warnings if "matched nothing" in w]
        assert skipped == ([f"edit {items.index(astray) + 1} (reverse at 2, 2) matched nothing within 8 px and "
                            "was skipped"] if astray in items else [])


def test_cli_replays_edits_byte_for_byte(loop_png, tmp_path):
    cache = StageCache()
    base = vectorize_file(loop_png, OPTIONS, edits=Edits(), cache=cache)
    junction = crossing(base)
    other = PAIRINGS[(PAIRINGS.index(junction.decision) + 1) % 3]
    edits = Edits(blur=0.5, items=(Edit(kind="pairing", at=junction.at, pairing=other),
                                   Edit(kind="reverse", at=junction.at)))
    page = vectorize_file(loop_png, OPTIONS, edits=edits, cache=cache)
    (tmp_path / "edits.json").write_text(edits.to_json())
    run = CliRunner().invoke(main, ["vectorize", str(loop_png), "--classifier", "geometric",
                                    "--edits", str(tmp_path / "edits.json"), "-o", str(tmp_path / "out.svg")])
    assert run.exit_code == 0, run.output
    assert (tmp_path / "out.svg").read_text() == drawing_to_svg(page.drawing)


def test_cli_bad_edits_file_exit_2(loop_png, tmp_path):
    (tmp_path / "edits.json").write_text('{"format": "onestroke-edits", "version": 9}')
    run = CliRunner().invoke(main, ["vectorize", str(loop_png), "--edits", str(tmp_path / "edits.json"),
                                    "-o", str(tmp_path / "out.svg")])
    assert run.exit_code == 2 and "version" in run.output and "Traceback" not in run.output
    assert not (tmp_path / "out.svg").exists()


def test_a_stopped_run_leaves_the_cache_as_a_finished_one(loop_png):
    """A run stopped between stages (the studio: a newer edit arrived) raises `Cancelled`;
    the next run on the same cache gives the bytes of a fresh run."""
    from onestroke.errors import Cancelled

    edits = Edits(threshold=0.43, blur=0.5)
    fresh = drawing_to_svg(vectorize_file(loop_png, OPTIONS, edits=edits).drawing)
    for stop_after in (1, 3, 5):
        cache = StageCache()
        asked = []
        cache.cancel = lambda: asked.append(1) or len(asked) > stop_after
        with pytest.raises(Cancelled):
            vectorize_file(loop_png, OPTIONS, edits=edits, cache=cache)
        assert len(asked) == stop_after + 1
        cache.cancel = None
        assert drawing_to_svg(vectorize_file(loop_png, OPTIONS, edits=edits, cache=cache).drawing) == fresh

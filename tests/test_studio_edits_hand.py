"""The edits the hand drawings need, through the library (no browser): every pairing the
page offers at a triple point keeps the line one stroke and is drawn as chosen (in
multi-stroke mode: all 15, likeliest first, each drawn as chosen); the
session's cached answers to a triple point split and a crossing then paired, and to a merge
and a "twice" on the cursive word, are a fresh run's bytes (the browser test compares
passes, start, once and reverse with the CLI)."""

from __future__ import annotations

import pytest

from benchmarks.sets.hand_drawings import bench_drawing
from vectorize import VectorizeOptions, vectorize_file
from vectorize.refine.edits import Edit, Edits
from vectorize.refine.refine import StageCache
from vectorize.svg_write import drawing_to_svg

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def drawings(tmp_path_factory):
    folder = tmp_path_factory.mktemp("hand-edits")
    return {which: bench_drawing(folder, which) for which in ("triple", "little")}


def test_every_offered_triple_pairing_is_one_stroke_drawn_as_chosen(drawings):
    path, cache = drawings["triple"], StageCache()
    base = vectorize_file(path, VectorizeOptions(), edits=Edits(), cache=cache)
    (triple,) = [j for j in base.graph.junctions if j.role == "triple"]
    assert len(triple.options) >= 3 and triple.options[0]["passes"] == [list(p) for p in triple.passes]
    for option in triple.options:
        result = vectorize_file(path, VectorizeOptions(), cache=cache,
                                edits=Edits(items=(Edit(kind="passes", at=triple.at, passes=option["passes"]),)))
        (now,) = [j for j in result.graph.junctions if j.role == "triple"]
        assert result.report.strokes == 1 and not result.report.warnings
        assert [list(p) for p in now.passes] == option["passes"] and now.fixed


def test_multi_stroke_offers_all_fifteen_pairings_likeliest_first_each_drawn_as_chosen(drawings):
    path, cache = drawings["triple"], StageCache()
    single = vectorize_file(path, VectorizeOptions(), edits=Edits(), cache=cache)
    base = vectorize_file(path, VectorizeOptions(), edits=Edits(multi=True), cache=cache)
    (triple,) = [j for j in base.graph.junctions if j.role == "triple"]
    (one_line,) = [j for j in single.graph.junctions if j.role == "triple"]
    offered = [o["passes"] for o in triple.options]
    assert len(offered) == 15 and len({str(p) for p in offered}) == 15  # every pairing of six branches, once
    assert [o["passes"] for o in one_line.options] == [p for p in offered if p in [o["passes"] for o in one_line.options]]
    chances = [o["p"] for o in triple.options]
    assert chances == sorted(chances, reverse=True) and triple.options[0]["passes"] == [list(p) for p in triple.passes]
    for option in triple.options:
        edits = Edits(multi=True, items=(Edit(kind="passes", at=triple.at, passes=option["passes"]),))
        result = vectorize_file(path, VectorizeOptions(), edits=edits, cache=cache)
        (now,) = [j for j in result.graph.junctions if j.role == "triple"]
        assert [list(p) for p in now.passes] == option["passes"] and now.fixed
        assert not [w for w in result.report.warnings if "matched nothing" in w]


def test_cached_answers_are_a_fresh_runs_bytes(drawings):
    for which, edits_of in (("triple", _triple_edits), ("little", _little_edits)):
        path, cache = drawings[which], StageCache()
        base = vectorize_file(path, VectorizeOptions(), edits=Edits(), cache=cache)
        for items in edits_of(base):
            edits = Edits(items=tuple(items))
            cached = vectorize_file(path, VectorizeOptions(), edits=edits, cache=cache)
            fresh = vectorize_file(path, VectorizeOptions(), edits=edits)
            assert drawing_to_svg(cached.drawing) == drawing_to_svg(fresh.drawing), (which, items)
            assert not [w for w in cached.report.warnings if "matched nothing" in w], (which, items)


def test_once_everywhere_is_said_where_it_cannot_be_kept(drawings):
    """A line must go back over some stretch somewhere: marked "once" everywhere, the
    stretches still drawn twice are named in the warnings, cached as fresh."""
    path, cache = drawings["little"], StageCache()
    base = vectorize_file(path, VectorizeOptions(), edits=Edits(), cache=cache)
    edits = Edits(items=tuple(Edit(kind="once", at=r["at"]) for r in base.graph.retraces))
    result = vectorize_file(path, VectorizeOptions(), edits=edits, cache=cache)
    again = vectorize_file(path, VectorizeOptions(), edits=edits, cache=cache)  # from the solved cache
    still = [w for w in result.report.warnings if "still drawn twice" in w]
    assert still and again.report.warnings == result.report.warnings and result.report.strokes == 1
    for warning in still:
        x, y = (float(v) for v in warning.split(" at ")[1].split(" is ")[0].split(", "))
        assert any(min(abs(x - p[0]) + abs(y - p[1]) for p in r["points"]) < 3 for r in result.graph.retraces)


def _triple_edits(base):
    triple = next(j for j in base.graph.junctions if j.role == "triple")
    crossing = next(j for j in base.graph.junctions if j.role == "crossing")
    yield [Edit(kind="split", at=triple.at), Edit(kind="pairing", at=crossing.at, pairing="touching")]


def _little_edits(base):
    yield [Edit(kind="merge", at=base.graph.branches[0].at), Edit(kind="twice", at=base.drawing.strokes[0].start)]


def test_a_twice_the_line_cannot_keep_is_said(drawings):
    """"Draw a stretch twice here" where the line's cheapest route has no reason to come back
    (a lead-in whose tip is the chosen start) changes nothing: the warnings say so, and a
    twice the line keeps says nothing."""
    path, cache = drawings["little"], StageCache()
    base = vectorize_file(path, VectorizeOptions(), edits=Edits(), cache=cache)
    lead_in = min(base.graph.retraces, key=lambda r: r["at"][0])  # the word's lead-in, drawn out and back
    tip = min(base.graph.ends, key=lambda e: e[0])
    started = Edits(items=(Edit(kind="start", at=tuple(tip)),))
    start = vectorize_file(path, VectorizeOptions(), edits=started, cache=cache)
    assert not any(r["at"] == lead_in["at"] for r in start.graph.retraces)  # started at its tip: drawn once
    kept = Edits(items=started.items + (Edit(kind="twice", at=tuple(lead_in["at"])),))
    result = vectorize_file(path, VectorizeOptions(), edits=kept, cache=cache)
    assert drawing_to_svg(result.drawing) == drawing_to_svg(start.drawing)
    x, y = lead_in["at"]
    assert [w for w in result.report.warnings if "still drawn once" in w] == [
        f"the stretch at {x:.0f}, {y:.0f} is still drawn once: the line goes back over a stretch only where "
        "that is its shortest way on to the rest of the drawing, and it is not here"]
    # Between two junctions mid-word a twice is kept: the line is longer and nothing is said.
    middle = base.graph.branches[0]
    heeded = vectorize_file(path, VectorizeOptions(), cache=cache,
                            edits=Edits(items=(Edit(kind="twice", at=tuple(middle.at)),)))
    assert heeded.drawing.length > base.drawing.length + middle.length
    assert not [w for w in heeded.report.warnings if "still drawn" in w]
    # Multi-stroke mode draws no route over the whole drawing: there the same twice (and a
    # once on a stretch drawn twice) acts on nothing by the mode, and says that, not that
    # it "matched nothing" (the stretch is right there).
    items = (Edit(kind="twice", at=tuple(middle.at)), Edit(kind="once", at=tuple(lead_in["at"])))
    multi = vectorize_file(path, VectorizeOptions(), cache=cache, edits=Edits(multi=True, items=items))
    assert [w for w in multi.report.warnings if w.startswith("edit ")] == [
        f"edit 1 (twice at {middle.at[0]:.0f}, {middle.at[1]:.0f}) acts in single-line mode only and was skipped",
        f"edit 2 (once at {x:.0f}, {y:.0f}) acts in single-line mode only and was skipped"]

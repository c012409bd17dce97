"""The stitch counts and densities docs/embroidery.md quotes are the code's (issue 27: the
ampersand's 487 stitches had become 477 without the docs knowing)."""

from __future__ import annotations

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _figures_module():
    spec = importlib.util.spec_from_file_location("embroidery_figures", ROOT / "docs" / "embroidery_figures.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_docs_quote_the_codes_figures():
    figures = _figures_module()
    quoted = figures.quoted(figures.DOC.read_text(encoding="utf-8"))
    computed = figures.figures()
    assert set(quoted) == set(computed), "a figure in the docs has no code, or one is not quoted"
    stale = {name: (quoted[name], computed[name]) for name in computed if quoted[name] != computed[name]}
    assert not stale, f"docs vs code {stale}: run python -m docs.embroidery_figures --write"


def test_the_markers_are_replaced_and_nothing_else():
    figures = _figures_module()
    text = "a <!-- figure x -->1<!-- /figure --> b <!-- figure y -->2<!-- /figure --> c"
    assert figures.rewrite(text, {"x": "10"}) == "a <!-- figure x -->10<!-- /figure --> b <!-- figure y -->2<!-- /figure --> c"
    assert figures.quoted(text) == {"x": "1", "y": "2"}

"""A process's first vectorization starts the crossing CNN (onnxruntime's import and the
model's session, which hold the GIL) while qhull triangulates in another thread, where the
outline says the line meets itself (two holes or more) and a core is spare: the import leaves
the classification stage and the output stays the same."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from tests.children import child_env
from vectorize.front_stages import CNN_BESIDE_SAMPLES, _cnn_beside

ROOT = Path(__file__).resolve().parents[2]

# A fresh process (onnxruntime not loaded) vectorizes one drawing with `cores` spare cores (the
# machine's load decides that otherwise) and says whether onnxruntime was loaded when the
# stage after the medial axis began, and what it wrote.
CHILD = r"""
import json, sys
import vectorize.axis.medial_axis as medial
import vectorize.front_stages as front
import vectorize.vectorizer as vectorizer
out, drawing, cores = sys.argv[1], sys.argv[2], int(sys.argv[3])
front.idle_cores = medial.idle_cores = lambda: cores
loaded, simplify = [], vectorizer.simplify

def recorded(*args, **kwargs):
    loaded.append("onnxruntime" in sys.modules)
    return simplify(*args, **kwargs)

vectorizer.simplify = recorded
from vectorize import vectorize_file
from vectorize.svg_write import drawing_to_svg
svg = drawing_to_svg(vectorize_file(drawing).drawing)
with open(out, "w") as fh:
    json.dump({"loaded before simplification": loaded[0], "loaded at the end": "onnxruntime" in sys.modules,
               "svg": svg}, fh)
"""


def _first_call(tmp_path: Path, drawing: str, cores: int) -> dict:
    out = tmp_path / f"{drawing}-{cores}.json"
    subprocess.run([sys.executable, "-c", CHILD, str(out), str(ROOT / "examples" / drawing), str(cores)],
                   check=True, capture_output=True, text=True, env=child_env(), timeout=300)
    return json.loads(out.read_text())


def test_crossings_start_the_cnn_beside_qhull_with_the_same_output(tmp_path):
    """loops.png: three loops, four outline rings. With a spare core the CNN is loaded
    before the stages after the medial axis; without one, where the crossings ask for it."""
    spare, busy = _first_call(tmp_path, "loops.png", 2), _first_call(tmp_path, "loops.png", 1)
    assert spare["loaded before simplification"] and not busy["loaded before simplification"]
    assert busy["loaded at the end"]  # its crossings need the CNN either way
    assert spare["svg"] == busy["svg"]


def test_one_hole_does_not_start_the_cnn(tmp_path):
    """spike-drawing.png: one loop (two rings) and a spike: nothing says it crosses itself."""
    spare = _first_call(tmp_path, "spike-drawing.png", 2)
    assert not spare["loaded before simplification"]


def test_the_guess_asks_for_two_holes_a_spare_core_the_cnn_and_a_diagram_one_thread_makes_fast(monkeypatch):
    monkeypatch.delitem(sys.modules, "onnxruntime", raising=False)  # as in a fresh process
    assert _cnn_beside(3, 6000, "cnn", 2)
    assert not _cnn_beside(2, 6000, "cnn", 2)  # one hole: an O needs no classifier
    assert not _cnn_beside(3, 6000, "cnn", 1)  # no spare core: nothing to overlap
    assert not _cnn_beside(3, 6000, "geometric", 2)
    assert _cnn_beside(3, CNN_BESIDE_SAMPLES, "cnn", 2) and not _cnn_beside(3, CNN_BESIDE_SAMPLES + 1, "cnn", 2)


def test_a_loaded_onnxruntime_is_not_started_again():
    import onnxruntime  # noqa: F401 - loaded, as in a process that has classified before

    assert not _cnn_beside(4, 6000, "cnn", 2)

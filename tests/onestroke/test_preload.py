"""Later stages' libraries load in a background thread; a stage waits for it, and an import
that fails there is left for the stage to do (and report) itself."""

from __future__ import annotations

import subprocess
import sys
import threading
from pathlib import Path

from onestroke.preload import preload, wait


def test_a_preload_imports_in_its_own_thread_and_a_failed_one_is_harmless():
    seen = []
    preload("test-colorsys", ("colorsys",), lambda: seen.append(threading.current_thread().name))
    wait("test-colorsys")
    assert "colorsys" in sys.modules and seen == ["preload test-colorsys"]
    preload("test-missing", ("vectorize.no_such_module",))
    wait("test-missing")  # no exception here: the stage that needs it would raise
    preload("test-colorsys", ("vectorize.no_such_module",))  # once per name: not started again
    wait("test-colorsys")
    wait("never-started")


def test_the_fitting_libraries_load_beside_the_early_stages():
    # A real run: scipy.interpolate is first imported by the preload thread, not the main one.
    code = """
import sys, threading
from vectorize import VectorizeOptions, vectorize_file
loaded_by = {}
import builtins
original = builtins.__import__
def spy(name, *args, **kwargs):
    if name == "scipy.interpolate" and name not in sys.modules:
        loaded_by[name] = threading.current_thread().name
    return original(name, *args, **kwargs)
builtins.__import__ = spy
result = vectorize_file(sys.argv[1], VectorizeOptions())
print(result.report.strokes, loaded_by.get("scipy.interpolate"))
"""
    drawing = Path(__file__).resolve().parents[2] / "examples" / "loops.png"
    out = subprocess.run([sys.executable, "-c", code, str(drawing)], capture_output=True, text=True,
                         check=True, timeout=300).stdout.split()
    assert out == ["1", "preload", "fitting"]

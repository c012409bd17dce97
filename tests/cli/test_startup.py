"""`onestroke vectorize` imports only what its run uses (issue 10, whole-process time): no
debug overlay without --debug, no rich when stderr is not a terminal, no downscaling or
blurring code for an image that needs neither, no other command's modules. Checked on the
modules a real process has loaded when the command ends, not on a clock."""

from __future__ import annotations

import io
import json
import subprocess
import sys
from pathlib import Path

from tests.children import child_env
from vectorize.svg.svg_read import read_svg

ROOT = Path(__file__).resolve().parents[2]
DRAWING = ROOT / "examples" / "loops.png"  # 1000 x 600 px: no downscale at the default max_size

# Runs the real command line in this process, then lists what it imported.
CHILD = """
import json, sys
listing, argv = sys.argv[1], sys.argv[2:]
sys.argv = ["onestroke", *argv]
from fabrication.cli import main
try:
    main()
except SystemExit as done:
    code = done.code
import gc
fitting = sys.modules.get("vectorize.fit.fitting")
li = sys.modules.get("skimage.filters.thresholding")
collected = {id(o) for o in gc.get_objects()}  # what the collector still goes through
nx, ort = sys.modules.get("networkx"), sys.modules.get("onnxruntime")
with open(listing, "w") as fh:
    json.dump({"exit": code, "modules": sorted(sys.modules), "frozen": gc.get_freeze_count(),
               "fitting collected": fitting is not None and id(fitting.fit_stroke) in collected,
               "li collected": li is not None and id(li.threshold_li) in collected,
               "networkx collected": nx is not None and id(nx.min_weight_matching) in collected,
               "onnxruntime collected": ort is not None and id(ort.InferenceSession) in collected,
               "gc enabled": gc.isenabled()}, fh)
"""

# The same drawing through the library alone, as a long-running process (the studio) runs it.
LIBRARY_CHILD = """
import gc, json, sys
from vectorize import vectorize_file
vectorize_file(sys.argv[2])
collected = {id(o) for o in gc.get_objects()}
nx, ort = sys.modules["networkx"], sys.modules["onnxruntime"]
with open(sys.argv[1], "w") as fh:
    json.dump({"networkx collected": id(nx.min_weight_matching) in collected,
               "onnxruntime collected": id(ort.InferenceSession) in collected, "gc enabled": gc.isenabled()}, fh)
"""
# Free ends beside the spike: more than two odd nodes, so the route's matching imports networkx.
MANY_ENDS = ROOT / "examples" / "spike-drawing.png"

# Not on the path of a plain `onestroke vectorize IN.png -o OUT.svg` with stderr in a pipe.
# (xml.sax's saxutils would bring urllib.request, http.client and ssl; edits only with --edits.)
NOT_IMPORTED = ("rich", "vectorize.debug_overlay", "vectorize.refine.refine", "vectorize.refine.pass_choices", "skimage.transform._warps", "skimage.filters._gaussian",
                "fabrication.embroidery", "fabrication.laser", "fabrication.studio", "machines",
                "pyembroidery", "svgelements", "torch", "xml.sax", "urllib.request", "http.client", "ssl",
                "vectorize.refine.edits", "vectorize.raster.scan_bands", "mmap")  # bands: images over 2x max_size


def _run(tmp_path: Path, *args: str, drawing: Path = DRAWING) -> tuple[dict, subprocess.CompletedProcess]:
    listing = tmp_path / "modules.json"
    env = {k: v for k, v in child_env().items() if k not in ("FORCE_COLOR", "TTY_COMPATIBLE")}
    done = subprocess.run([sys.executable, "-c", CHILD, str(listing), "vectorize", str(drawing), *args],
                          capture_output=True, text=True, env=env, timeout=300)
    return json.loads(listing.read_text()), done


def _loaded(modules: list[str], name: str) -> bool:
    return any(m == name or m.startswith(name + ".") for m in modules)


def test_vectorize_imports_only_what_the_run_uses(tmp_path):
    out = tmp_path / "out.svg"
    result, done = _run(tmp_path, "-o", str(out))
    assert result["exit"] == 0, done.stderr
    assert len(read_svg(str(out)).strokes) == 1
    assert done.stdout.startswith(f"{out}: 1 stroke")
    modules = result["modules"]
    assert _loaded(modules, "vectorize.vectorizer") and _loaded(modules, "scipy.ndimage")  # the listing is real
    assert [name for name in NOT_IMPORTED if _loaded(modules, name)] == []
    # The libraries and the stages were loaded before the work and then left out of the
    # garbage collector's passes (`fabrication.cli.heap.freeze_loaded_objects`).
    assert result["frozen"] > 10_000 and not result["fitting collected"]
    # Li's threshold (scikit-image's filters) too, which the run's threshold stage uses.
    assert "skimage.filters.thresholding" in modules and not result["li collected"]

    # --debug asks for the overlay: then it is imported and its images written.
    debug = tmp_path / "debug"
    result, done = _run(tmp_path, "-o", str(tmp_path / "again.svg"), "--debug", str(debug))
    assert result["exit"] == 0, done.stderr
    assert _loaded(result["modules"], "vectorize.debug_overlay") and len(list(debug.glob("*.png"))) == 5
    assert not _loaded(result["modules"], "rich")
    assert done.stderr.strip() == f"debug: 5 stage images in {debug}"


def test_libraries_imported_in_the_work_are_loaded_for_good_by_the_command_only(tmp_path):
    """onnxruntime (crossings) and networkx (a route with more than two odd nodes) are
    imported in the middle of the work: a command leaves them out of the collector's passes,
    as it does the libraries it loads before (onestroke/lasting.py); the library alone, as
    the studio runs it, leaves the collector as it is."""
    result, done = _run(tmp_path, "-o", str(tmp_path / "out.svg"), drawing=MANY_ENDS)
    assert result["exit"] == 0, done.stderr
    assert _loaded(result["modules"], "networkx") and _loaded(result["modules"], "onnxruntime")
    assert not result["networkx collected"] and not result["onnxruntime collected"] and result["gc enabled"]

    listing = tmp_path / "library.json"
    done = subprocess.run([sys.executable, "-c", LIBRARY_CHILD, str(listing), str(MANY_ENDS)],
                          capture_output=True, text=True, env=child_env(), timeout=300)
    assert done.returncode == 0, done.stderr
    alone = json.loads(listing.read_text())
    assert alone == {"networkx collected": True, "onnxruntime collected": True, "gc enabled": True}


def test_plain_status_lines_read_as_rich_would_write_them(monkeypatch):
    """Off a terminal the CLI prints status lines without rich; the text is rich's own
    rendering there (markup tags dropped, an escaped tag kept), only never wrapped."""
    from rich.console import Console

    from fabrication.cli.common import console

    for name in ("FORCE_COLOR", "TTY_COMPATIBLE"):
        monkeypatch.delenv(name, raising=False)
    messages = ["[yellow]warning:[/yellow] file 'a[1].png' has \\[bold] in its name",
                "[red]failed:[/red] x.png: [0, 1] is out of range (see [link=https://x.org]here[/link])"]
    for message in messages:
        plain = io.StringIO()
        monkeypatch.setattr(sys, "stderr", plain)
        assert not console.is_terminal
        console.print(message, soft_wrap=True)
        reference = io.StringIO()
        Console(file=reference, highlight=False, force_terminal=False, soft_wrap=True).print(message)
        assert plain.getvalue() == reference.getvalue() and "[" in plain.getvalue()

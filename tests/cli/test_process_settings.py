"""The process settings `onestroke vectorize` makes for its own speed, checked in real
command processes: OpenBLAS's thread pool limited to one thread before numpy is imported
(its idle pool spins on the second core: `fabrication/cli/vectorize_cmd.py`), and glibc's
heap keeping freed memory for the next large array (`fabrication/cli/heap.py`)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from tests.children import child_env

ROOT = Path(__file__).resolve().parents[2]
DRAWING = ROOT / "examples" / "loops.png"

# Runs the real command line in this process, noting OPENBLAS_NUM_THREADS as it was when
# numpy's import began; then (when asked) counts the minor page faults of rounds of large
# arrays allocated together and freed together, as a vectorization's stages do.
CHILD = """
import json, os, resource, sys
report, run_command, argv = sys.argv[1], sys.argv[2] == "1", sys.argv[3:]
seen = {}

class Watch:
    def find_spec(self, name, path=None, target=None):
        if name == "numpy" and "numpy" not in seen:
            seen["numpy"] = os.environ.get("OPENBLAS_NUM_THREADS")
        return None

sys.meta_path.insert(0, Watch())
code = None
if run_command:
    sys.argv = ["onestroke", *argv]
    from fabrication.cli import main
    try:
        main()
    except SystemExit as done:
        code = done.code
import numpy as np
faults = []
for _ in range(6):
    before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    arrays = [np.ones(500_000) for _ in range(4)]  # 4 MB each
    del arrays
    faults.append(resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before)
with open(report, "w") as fh:
    json.dump({"exit": code, "openblas": seen.get("numpy"), "faults": faults}, fh)
"""


def _child(tmp_path: Path, run_command: bool, **env: str) -> dict:
    report = tmp_path / "report.json"
    args = ["vectorize", str(DRAWING), "-o", str(tmp_path / "out.svg")] if run_command else []
    done = subprocess.run([sys.executable, "-c", CHILD, str(report), "1" if run_command else "0", *args],
                          capture_output=True, text=True, env=child_env(**env), timeout=300)
    assert done.returncode == 0, done.stderr
    return json.loads(report.read_text())


def test_openblas_pool_is_one_thread_before_numpy_loads(tmp_path):
    env = {k: v for k, v in child_env().items() if k != "OPENBLAS_NUM_THREADS"}
    report = tmp_path / "report.json"
    done = subprocess.run([sys.executable, "-c", CHILD, str(report), "1", "vectorize", str(DRAWING), "-o",
                           str(tmp_path / "out.svg")], capture_output=True, text=True, env=env, timeout=300)
    assert done.returncode == 0, done.stderr
    result = json.loads(report.read_text())
    assert result["exit"] == 0 and (tmp_path / "out.svg").stat().st_size > 0
    assert result["openblas"] == "1"
    # A value the user set is kept.
    assert _child(tmp_path, True, OPENBLAS_NUM_THREADS="2")["openblas"] == "2"


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc's mallopt")
def test_vectorize_keeps_freed_heap_memory(tmp_path):
    tuned = _child(tmp_path, True)
    plain = _child(tmp_path, False)
    assert tuned["exit"] == 0
    # After the first round, arrays freed together are served again from the kept heap.
    later_tuned, later_plain = sum(tuned["faults"][1:]), sum(plain["faults"][1:])
    assert later_plain > 4 * 900  # 4 MB a round is ~1000 pages: glibc's defaults fault them again
    assert later_tuned < later_plain / 10, (tuned["faults"], plain["faults"])


# keep_freed_memory, then large arrays made and freed in a second thread (as the binarize
# stage's on a spare core), then the same sizes in the main thread: their minor page faults.
THREAD_CHILD = """
import json, resource, sys, threading
import numpy as np
from fabrication.cli.heap import keep_freed_memory
kept = keep_freed_memory() if sys.argv[2] == "1" else None

def made_and_freed():
    arrays = [np.ones(500_000) for _ in range(4)]  # 4 MB each
    del arrays

thread = threading.Thread(target=made_and_freed)
thread.start()
thread.join()
before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
arrays = [np.ones(500_000) for _ in range(4)]
with open(sys.argv[1], "w") as fh:
    json.dump({"kept": kept, "faults": resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before}, fh)
"""


def _reports_with_and_without(child: str, tmp_path) -> dict:
    """The JSON reports of the `child` script run in a fresh process with the setting on
    ("1") and off ("0"), its second argument."""
    report = tmp_path / "report.json"
    results = {}
    for setting in ("1", "0"):
        done = subprocess.run([sys.executable, "-c", child, str(report), setting], capture_output=True,
                              text=True, env=child_env(), timeout=120)
        assert done.returncode == 0, done.stderr
        results[setting] = json.loads(report.read_text())
    return results


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc's mallopt")
def test_memory_a_thread_freed_serves_the_main_thread(tmp_path):
    """With the heap kept (`keep_freed_memory`, which a command sets before its binarize
    thread starts), what a second thread frees is in the one heap the main thread's later
    arrays come from; by default that thread has an arena of its own."""
    results = _reports_with_and_without(THREAD_CHILD, tmp_path)
    assert results["1"]["kept"] is True
    assert results["0"]["faults"] > 4 * 900  # 16 MB: ~4,000 pages touched afresh
    assert results["1"]["faults"] < results["0"]["faults"] / 10, results


# keep_freed_memory, the heap touched ahead in a second thread or not, then arrays made in the
# main thread (as a command's imports and stages make them): the main thread's page faults.
AHEAD_CHILD = """
import json, resource, sys
import numpy as np
from fabrication.cli.heap import keep_freed_memory, touch_heap_beside
keep_freed_memory()
ahead = touch_heap_beside() if sys.argv[2] == "1" else None
if ahead is not None:
    ahead.join()
before = resource.getrusage(resource.RUSAGE_THREAD).ru_minflt
arrays = [np.ones(500_000) for _ in range(4)]
with open(sys.argv[1], "w") as fh:
    json.dump({"ahead": ahead is not None, "faults": resource.getrusage(resource.RUSAGE_THREAD).ru_minflt - before}, fh)
"""


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc's mallopt")
def test_the_heap_touched_ahead_in_another_thread_faults_no_page_in_this_one(tmp_path):
    """`touch_heap_beside` (a command with a core to spare, while it imports): the heap's
    pages are faulted in by a second thread and kept, so this thread's arrays take none."""
    results = _reports_with_and_without(AHEAD_CHILD, tmp_path)
    assert results["1"]["ahead"] is True
    assert results["0"]["faults"] > 4 * 900  # 16 MB: ~4,000 pages touched afresh
    assert results["1"]["faults"] < results["0"]["faults"] / 10, results

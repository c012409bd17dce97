"""The whole `onestroke vectorize` process against the floor its libraries set.

Importing the libraries a run needs takes most of a command's time, whatever the project
does. So the command is measured as a ratio: its wall time over that of a bare process that
imports exactly the same third-party modules and does nothing else, the two run one right
after the other (the order alternating) so that both see the same machine. The module list
is taken per drawing from an unmeasured run of the command inside a process that lists
`sys.modules` when it ends (a drawing without odd nodes, say, never imports networkx).
Used by `startup_cost.py --pairs N`.

The command imports its libraries with the garbage collector paused and then frozen
(`fabrication.cli.heap.loading_for_good`), which a plain import does not do: part of its
lead over the bare floor is loading the same libraries more cheaply, not vectorizing
faster. So each pair also runs a second floor that imports them the same way ("bare,
collector paused"), and its ratio says what the work itself adds.
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sysconfig
import tempfile
import time
from pathlib import Path

PROJECT = ("vectorize", "fabrication", "onestroke", "machines", "benchmarks")

# Runs the command line in this process, then writes the third-party modules it loaded.
LIST_CHILD = """
import json, sys
listing, argv = sys.argv[1], sys.argv[2:]
sys.argv = ["onestroke", *argv]
from fabrication.cli import main
try:
    main()
except SystemExit:
    pass
roots = {roots}
project = {project}
names = [name for name, module in list(sys.modules.items())
         if name.split(".")[0] not in project and any(str(getattr(module, "__file__", None) or "").startswith(r)
                                                      for r in roots)]
with open(listing, "w") as fh:
    json.dump(names, fh)
"""

# The bare process: imports the listed modules in the order the command first imported them.
BARE_CHILD = """
import importlib, json, sys
for name in json.load(open(sys.argv[1])):
    try:
        importlib.import_module(name)
    except Exception:
        pass
"""

# The same, loading the modules as the command does: collector paused, then frozen.
BARE_PAUSED_CHILD = """
import gc
gc.disable()
""" + BARE_CHILD + """
gc.freeze()
gc.enable()
"""


def third_party_roots() -> list[str]:
    """Folders third-party packages are installed in (site-packages of this interpreter; a
    regular install of the project reads them from there too, `user_install.py`)."""
    paths = sysconfig.get_paths()
    return sorted({paths["purelib"], paths["platlib"]})


def _run(cmd: list[str], env: dict, timeout: float, cwd: str) -> tuple[float, float]:
    """(wall s, CPU s) of one child process run to the end (CPU: user + sys, all threads)."""
    before = os.times()
    start = time.perf_counter()
    # in `cwd` (not the working tree, which `python -c` would put first on the import path)
    done = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=timeout, cwd=cwd)
    wall = time.perf_counter() - start
    after = os.times()
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd[:3])} ... exited {done.returncode}: {done.stderr.strip()[-300:]}")
    return wall, (after.children_user - before.children_user) + (after.children_system - before.children_system)


def ratio_pairs(picks: list, command: list[str], python: str, env: dict, timeout: float) -> int:
    """Run each drawing as the command and as the bare import floor (module doc), both with
    the interpreter `python` the command runs on; print the pairs and the median ratios."""
    from PIL import Image

    from benchmarks.common.render import render, to_uint8

    child = LIST_CHILD.format(roots=repr(third_party_roots()), project=repr(PROJECT))
    print(f"load average at the start {' '.join(f'{x:.1f}' for x in os.getloadavg())}", flush=True)
    rows = []
    with tempfile.TemporaryDirectory(prefix="onestroke-ratio-") as tmp:
        for k, gt in enumerate(picks):
            src, out, listing = (Path(tmp) / f"{k}.{ext}" for ext in ("png", "svg", "json"))
            Image.fromarray(to_uint8(render(gt.drawing))).save(src)
            subprocess.run([python, "-c", child, str(listing), "vectorize", str(src), "-o", str(out)],
                           capture_output=True, text=True, env=env, timeout=timeout, check=True, cwd=tmp)
            runs = {"command": command + ["vectorize", str(src), "-o", str(out)],
                    "bare": [python, "-c", BARE_CHILD, str(listing)],
                    "paused": [python, "-c", BARE_PAUSED_CHILD, str(listing)]}
            order = ("command", "bare", "paused") if k % 2 == 0 else ("paused", "bare", "command")
            times = {kind: _run(runs[kind], env, timeout, cwd=tmp) for kind in order}
            modules = json.loads(listing.read_text())
            rows.append((gt.name, len(modules), any(m.split(".")[0] == "networkx" for m in modules), times))
            (cw, cc), (bw, bc), (pw, _) = times["command"], times["bare"], times["paused"]
            print(f"  {gt.name:34s} command {cw:6.3f} s (CPU {cc:6.3f})  bare {bw:6.3f} s (CPU {bc:6.3f})  "
                  f"ratio {cw / bw:5.3f} (CPU {cc / bc:5.3f})  to the paused floor {cw / pw:5.3f}  {len(modules)} modules"
                  f"{' with networkx' if rows[-1][2] else ''}", flush=True)
    wall = [t["command"][0] / t["bare"][0] for *_, t in rows]
    cpu = [t["command"][1] / t["bare"][1] for *_, t in rows]
    paused = [t["command"][0] / t["paused"][0] for *_, t in rows]
    load = " ".join(f"{x:.1f}" for x in os.getloadavg())
    print(f"{len(rows)} pairs, {os.cpu_count()} CPUs, load average now {load}")
    print(f"command / bare import floor: median {statistics.median(wall):.3f} (wall), {statistics.median(cpu):.3f} "
          f"(CPU); command median {statistics.median(t['command'][0] for *_, t in rows):.3f} s, bare median "
          f"{statistics.median(t['bare'][0] for *_, t in rows):.3f} s")
    print(f"command / floor importing as the command does (collector paused, then frozen): median "
          f"{statistics.median(paused):.3f} (wall); that floor's median "
          f"{statistics.median(t['paused'][0] for *_, t in rows):.3f} s")
    return 0

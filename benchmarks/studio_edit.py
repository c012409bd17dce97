"""Benchmark: how fast the studio answers an edit (the page's POST /api/state round trip).

Prints wall-clock medians and, below them, the CPU seconds the answer took in this
process (all threads): on a loaded machine the wall time includes waiting for a core.

Run from the repo root: `python -m benchmarks.studio_edit [DRAWING ...]` (default: the
1000 px examples loops.png, touch-drawing.png and hershey ampersand). After the first
vectorization, each edit kind is sent --repeats (7) times through Starlette's test client, the
way the page sends it, and the median answer time is printed per kind. Every answer is
for an edit the cache has not seen in that form (a new threshold or blur value, a split
or merge with the simplification cache emptied first), so the figures are for the stages
each kind really re-runs: pairing, passes (a triple point's pairing) and start -> traversal
and fitting; reverse -> nothing but the orientation (the fitted curve of the same earlier
edits is cached); split/merge -> simplification on; threshold/blur/multi -> everything
from binarization.

`--hand` adds two 1000 px hand drawings of the benchmark's generators (the "triple" set's
second drawing: a triple point and three crossings; the cursive word "little", stems
drawn down and back up), rendered to a temporary folder. `--gaps` adds (alone: times only)
that word with two pen gaps wiped out, whose bridges the "unbridge" kind keeps open, one
at a time (a re-run from gap bridging on: pruning is redone, binarization to the medial
axis come from the cache).

The last columns are the slider steps of a session that precomputes (`onestroke studio`):
after each threshold or blur answer the server computes the neighbouring slider values
while it is idle; the next step (threshold +0.01, blur +0.25, as the page's sliders step)
is then timed, after waiting for that background work. "idle" is how long the background
work ran after an answer (the pause a user leaves between two steps for the next one to
be instant), and its CPU seconds are printed below it.

`--panels` also times what the page asks next when its Embroidery or Laser tab is open
(POST /api/embroidery and /api/laser with the page's default option values for the same
edits: the stitch or toolpath preview regenerated for the player), as CPU seconds.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from dataclasses import replace
from pathlib import Path
from statistics import median

if __name__ == "__main__" and Path(sys.path[0]).resolve() == Path(__file__).resolve().parent:
    sys.path[0] = str(Path(__file__).resolve().parents[1])  # run as a file: see benchmarks/__init__.py

from starlette.testclient import TestClient

from fabrication.studio.app import create_app
from fabrication.studio.session import StudioSession
from vectorize.refine.edits import PAIRINGS, Edits


REPEATS = 7
# The page's default panel values (fabrication/studio/static/index.html).
PANELS = {"embroidery": {"style": "running", "size": "90mm", "hoop": "100x100", "color": "#1f3a93", "fit": False},
          "laser": {"size": "80mm", "feed": "1500mm/min", "power": "60%", "passes": "1", "origin": "lower-left",
                    "arcs": False}}
DEFAULT = ["examples/loops.png", "examples/touch-drawing.png", "examples/hershey-HersheySans1-ampersand.png"]


def bench(path: Path, panels: bool = False, repeats: int = REPEATS) -> tuple[dict, dict, dict]:
    session = StudioSession(path, edits_path=Path(os.devnull))
    host = "127.0.0.1:1"
    client = TestClient(create_app(session, token="t", hosts={host}), base_url=f"http://{host}")
    client.headers["X-Studio-Token"] = "t"
    first = time.perf_counter()
    base = client.get("/api/state").json()
    first = time.perf_counter() - first
    edits = base["edits"]
    crossings = [j for j in base["graph"]["junctions"] if j["role"] == "crossing"] or [None]
    triples = [j for j in base["graph"]["junctions"] if j["role"] == "triple" and len(j["options"]) > 2]
    stroke = base["strokes"][0]["points"]
    bridges = base["graph"].get("bridges") or []

    cpu: dict[str, list[float]] = {}
    panel_cpu: dict[str, list[float]] = {}

    def post(extra: dict, items: list) -> float:
        start, start_cpu = time.perf_counter(), time.process_time()
        answer = client.post("/api/state", json={"edits": dict(edits, **extra, edits=items)})
        assert answer.status_code == 200, answer.text
        post.cpu = time.process_time() - start_cpu
        wall = time.perf_counter() - start
        post.panels = {}
        for panel, options in PANELS.items() if panels else ():
            start_cpu = time.process_time()
            answer = client.post(f"/api/{panel}", json={"edits": dict(edits, **extra, edits=items), "options": options})
            assert answer.status_code == 200, answer.text
            post.panels[panel] = time.process_time() - start_cpu
        return wall

    class Times(dict):
        """kind -> wall seconds; the CPU seconds of the same answer go to `cpu`."""

        def add(self, kind: str, seconds: float) -> None:
            self.setdefault(kind, []).append(seconds)
            cpu.setdefault(kind, []).append(post.cpu)
            for panel, seconds in post.panels.items():
                panel_cpu.setdefault((panel, kind), []).append(seconds)

    times = Times()
    for rep in range(repeats):
        j = crossings[rep % len(crossings)]
        if j is not None:
            other = PAIRINGS[(PAIRINGS.index(j["decision"]) + 1 + rep % 2) % 3]
            session.cache.solved.clear()
            times.add("pairing", post({}, [{"kind": "pairing", "at": j["at"], "pairing": other}]))
            session.cache.simplified.clear()
            session.cache.solved.clear()
            times.add("split", post({}, [{"kind": "split", "at": j["at"]}]))
            split = client.post("/api/state", json={"edits": dict(edits, edits=[{"kind": "split", "at": j["at"]}])})
            branch = min(split.json()["graph"]["branches"] or [{"at": j["at"]}],
                         key=lambda b: (b["at"][0] - j["at"][0]) ** 2 + (b["at"][1] - j["at"][1]) ** 2)
            session.cache.simplified.clear()
            session.cache.solved.clear()
            times.add("merge", post({}, [{"kind": "split", "at": j["at"]}, {"kind": "merge", "at": branch["at"]}]))
        for t in (triples[rep % len(triples)],) if triples else ():
            session.cache.solved.clear()
            option = t["options"][1 + rep % 2]["passes"]
            times.add("passes", post({}, [{"kind": "passes", "at": t["at"], "passes": option}]))
        for gap in (bridges[rep % len(bridges)],) if bridges else ():
            # A gap kept open re-runs from pruning (gap bridging) on; never seen in this form.
            for key in [k for k in session.cache.front if len(k) > 4]:  # keyed by the gaps kept open
                session.cache.front.pop(key)
            session.cache.simplified.clear()
            session.cache.solved.clear()
            middle = [(gap[0][0] + gap[1][0]) / 2, (gap[0][1] + gap[1][1]) / 2]
            times.add("unbridge", post({}, [{"kind": "unbridge", "at": middle}]))
        post({}, [])  # the page shows the automatic result before the user picks an end
        times.add("start", post({}, [{"kind": "start", "at": stroke[-1] if rep % 2 == 0 else stroke[0]}]))
        times.add("reverse", post({}, [{"kind": "reverse", "at": stroke[len(stroke) // 2]}]))
        times.add("threshold", post({"threshold": round(0.40 + 0.02 * rep, 2)}, []))
        times.add("blur", post({"blur": 0.5 + 0.25 * rep}, []))
        session.cache.front.pop(next((k for k in session.cache.front if k[2]), None), None)
        times.add("multi", post({"multi": True}, []))
    result = {k: median(v) for k, v in times.items() if v}
    result["first"] = first
    cpu = {k: median(v) for k, v in cpu.items() if v}
    for kind, (wall, seconds) in stepped(path, repeats).items():
        result[kind], cpu[kind] = wall, seconds
    return result, cpu, {k: median(v) for k, v in panel_cpu.items()}


def stepped(path: Path, repeats: int = REPEATS) -> dict[str, tuple[float, float]]:
    """kind -> (median wall s, median CPU s) of a precomputing session's slider steps, and
    of its background work after each answer ("idle")."""
    session = StudioSession(path, edits_path=Path(os.devnull), precompute=True)
    session.state(Edits())
    session.idle()
    found: dict[str, list[tuple[float, float]]] = {}

    def timed(kind: str, work) -> None:
        start, start_cpu = time.perf_counter(), time.process_time()
        work()
        found.setdefault(kind, []).append((time.perf_counter() - start, time.process_time() - start_cpu))

    for kind, first, step in (("thr step", Edits(threshold=0.40), 0.01), ("blur step", Edits(blur=0.5), 0.25)):
        session.state(first)
        session.idle()
        name = "threshold" if kind == "thr step" else "blur"
        for rep in range(1, repeats + 1):
            edits = replace(first, **{name: round(getattr(first, name) + rep * step, 2)})
            timed(kind, lambda: session.state(edits))
            timed("idle", session.idle)
    return {kind: (median(w for w, _ in values), median(c for _, c in values)) for kind, values in found.items()}


def hand_drawings() -> list[Path]:
    """The triple set's second drawing and the cursive word "little", as PNGs in a temporary folder."""
    import tempfile

    from PIL import Image

    from benchmarks.sets.drawings import generate_set
    from benchmarks.sets.handwriting import handwriting_drawing
    from benchmarks.common.render import render, to_uint8

    folder = Path(tempfile.mkdtemp(prefix="studio-edit-"))
    paths = []
    for truth in (generate_set("triple", 2, 0)[1], handwriting_drawing(0, 3)):
        paths.append(folder / f"{truth.name}.png")
        Image.fromarray(to_uint8(render(truth.drawing))).save(paths[-1])
    return paths


def gap_drawing() -> Path:
    """The cursive word "little" with two pen gaps wiped out, as the studio's browser tests
    draw it (`benchmarks.sets.hand_drawings.bench_drawing`), as a PNG in a temporary folder."""
    import tempfile

    from benchmarks.sets.hand_drawings import bench_drawing

    return bench_drawing(Path(tempfile.mkdtemp(prefix="studio-edit-gaps-")), "little")


def main() -> None:
    parser = argparse.ArgumentParser(description="Median answer time of each studio edit kind.")
    parser.add_argument("drawings", nargs="*", type=Path, help="raster drawings (default: three 1000 px examples)")
    parser.add_argument("--hand", action="store_true",
                        help="also two hand drawings of the benchmark's generators (triple point, cursive word)")
    parser.add_argument("--gaps", action="store_true",
                        help="also the cursive word with two pen gaps wiped out (the studio's browser-test drawing), "
                             "for the unbridge edit (alone: only it)")
    parser.add_argument("--panels", action="store_true",
                        help="also time the embroidery and laser previews the page asks for after each edit")
    parser.add_argument("--repeats", type=int, default=REPEATS, help=f"answers timed per edit kind (default {REPEATS})")
    args = parser.parse_args()
    paths = args.drawings or ([] if args.gaps and not args.hand else [Path(p) for p in DEFAULT])
    if args.hand:
        paths = list(paths) + hand_drawings()
    if args.gaps:
        paths = list(paths) + [gap_drawing()]
    print(f"load: {os.getloadavg()[0]:.2f} (1 min), {os.cpu_count()} cores; "
          f"median of {args.repeats} per edit kind, seconds")
    kinds = ("first", "pairing", "passes", "start", "reverse", "split", "merge", "unbridge", "threshold", "blur",
             "multi", "thr step", "blur step", "idle")
    print(f"{'drawing':40s} " + " ".join(f"{k:>9s}" for k in kinds))
    for path in paths:
        from PIL import Image

        with Image.open(path) as picture:
            size = "x".join(map(str, picture.size))
        wall, cpu, panel_cpu = bench(path, args.panels, args.repeats)
        print(f"{path.name + ' ' + size:40s} " + " ".join(f"{wall.get(k, float('nan')):9.3f}" for k in kinds))
        print(f"{'  CPU s of this process':40s} " + " ".join(f"{cpu.get(k, float('nan')):9.3f}" for k in kinds))
        for panel in PANELS if args.panels else ():
            print(f"{'  then ' + panel + ' preview, CPU s':40s} " +
                  " ".join(f"{panel_cpu.get((panel, k), float('nan')):9.3f}" for k in kinds))


if __name__ == "__main__":
    main()

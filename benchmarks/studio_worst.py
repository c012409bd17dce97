"""Benchmark: the studio's heaviest in-range request per endpoint (issue 25: no request may
take the server over 2 s or 500 MB, but a real job that is sent).

Each case is one request the page (or any client holding the token) can make with option
values inside their declared ranges (`onestroke.ranges`): the most passes at the finest
tolerance on the largest bed, the densest stitches on the largest hoop, the vectorizer's
extreme settings, the largest bodies. The session is made and its drawing vectorized
first (not timed); then each case runs --repeats times (a state request each time from a
setting never computed: the session's stage cache keeps only the gray images) through Starlette's test client and
the script prints, per case, the median wall and CPU seconds (this process, all threads:
on a loaded machine the wall time includes waiting for a core) and the peak memory of the
process during the request (VmHWM, reset before each request through /proc/self/clear_refs),
and per endpoint its worst case. The load average is printed with them.

Run from the repo root: `python -m benchmarks.studio_worst [--repeats 3] [--only laser,embroidery]`.
`--root DIR` imports onestroke from another checkout (e.g. to measure main before a change, in
a child interpreter: benchmarks/common/checkout.py)
while the cases stay these.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import sys
import time
import warnings
from pathlib import Path
from statistics import median

if __name__ == "__main__" and Path(sys.path[0]).resolve() == Path(__file__).resolve().parent:
    sys.path[0] = str(Path(__file__).resolve().parents[1])  # run as a file: see benchmarks/__init__.py

from benchmarks.common.checkout import needs_rerun, rerun_on

ROOT = Path(__file__).resolve().parents[1]

# An uploaded laser profile with the largest bed the profile ranges take (machines/laser_profile.py).
BIG_BED = """name = "largest bed"
[bed]
size = "{side}x{side}mm"
"""
EDITS = {"format": "onestroke-edits", "version": 1, "edits": []}


def cases(bed: float, hoop: float, budget_size: float) -> list[tuple[str, str, str, object]]:
    """(endpoint, label, method, body or query) of the heaviest requests found; budget_size:
    the size (mm) at which satin at 0.1 mm spacing makes the studio's step budget."""
    laser_worst = {"size": "400mm", "tolerance": "0.005mm", "passes": "100"}
    big = {"size": f"{bed:g}mm", "tolerance": "0.005mm", "passes": "100", "profile": "@big"}
    field = {"size": f"{hoop:g}mm", "hoop": f"{hoop:g}x{hoop:g}", "fit": True}  # shrunk into the hoop
    zigzag = dict(field, style="zigzag", spacing="0.1mm")
    satin = dict(field, style="satin", spacing="0.1mm")
    running = dict(field, style="running", stitch_length="0.1mm", min_stitch="0.1mm")
    triple = dict(field, style="triple", stitch_length="0.1mm", min_stitch="0.1mm", repeats="5")
    arrows = dict(field, style="arrows", arrow_size="0.1mm", spacing="0.2mm", min_stitch="0.1mm")
    at_budget = dict(satin, size=f"{budget_size:.0f}mm")  # the most steps the studio makes
    wide_satin = dict(field, style="satin")  # the default 0.4 mm spacing
    many = {"format": "onestroke-edits", "version": 1,
            "edits": [{"kind": "reverse", "at": [float(i % 997), float(i % 599)]} for i in range(9000)]}
    spots = [[float((i * 37) % 997), float((i * 13) % 599)] for i in range(12000)]  # a 1 MiB body holds ~15,000
    twice = dict(EDITS, edits=[{"kind": "twice", "at": at} for at in spots])
    split = dict(EDITS, edits=[{"kind": "split", "at": at} for at in spots])
    profile_text = BIG_BED.format(side=bed) + "# " + "x" * (60 * 1024) + "\n"
    return [
        ("state", "threshold 0.95", "POST", {"edits": dict(EDITS, threshold=0.95)}),
        ("state", "blur 25 px", "POST", {"edits": dict(EDITS, blur=25)}),
        ("state", "multi-stroke, threshold 0.05", "POST", {"edits": dict(EDITS, multi=True, threshold=0.05)}),
        ("state", "threshold 0.05", "POST", {"edits": dict(EDITS, threshold=0.05)}),
        ("state", "threshold 0.08", "POST", {"edits": dict(EDITS, threshold=0.08)}),
        ("state", "threshold 0.12", "POST", {"edits": dict(EDITS, threshold=0.12)}),
        ("state", "9,000 reverse edits", "POST", {"edits": many}),
        ("state", "12,000 twice edits", "POST", {"edits": twice}),
        ("state", "12,000 split edits", "POST", {"edits": split}),
        ("mask", "threshold 0.05, blur 25", "GET", "threshold=0.05&blur=25"),
        ("laser", "400 mm, 0.005 mm, 100 passes", "POST", {"options": laser_worst}),
        ("laser", "same with arcs", "POST", {"options": dict(laser_worst, arcs=True)}),
        ("laser", f"uploaded {bed:g} mm bed, {bed:g} mm, 0.005 mm, 100 passes", "POST", {"options": big}),
        ("export/gcode", "400 mm, 0.005 mm, 100 passes", "POST", {"options": laser_worst}),
        ("export/gcode", f"uploaded {bed:g} mm bed, 100 passes", "POST", {"options": big}),
        ("embroidery", f"zigzag 0.1 mm spacing, {hoop:g} mm hoop", "POST", {"options": zigzag}),
        ("embroidery", f"running 0.1 mm, {hoop:g} mm hoop", "POST", {"options": running}),
        ("embroidery", f"triple x5 0.1 mm, {hoop:g} mm hoop", "POST", {"options": triple}),
        ("embroidery", f"arrows 0.1 mm, {hoop:g} mm hoop", "POST", {"options": arrows}),
        ("embroidery", f"satin 0.1 mm spacing, {hoop:g} mm hoop", "POST", {"options": satin}),
        ("embroidery", f"satin 0.4 mm spacing, {hoop:g} mm hoop", "POST", {"options": wide_satin}),
        ("embroidery", f"satin 0.1 mm spacing, {budget_size:.0f} mm (step budget)", "POST", {"options": at_budget}),
        ("export/pes", f"satin 0.1 mm spacing, {budget_size:.0f} mm (step budget)", "POST", {"options": at_budget}),
        ("export/pes", f"zigzag 0.1 mm spacing, {hoop:g} mm hoop", "POST", {"options": zigzag}),
        ("export/dst", f"zigzag 0.1 mm spacing, {hoop:g} mm hoop", "POST", {"options": zigzag}),
        ("export/jef", f"zigzag 0.1 mm spacing, {hoop:g} mm hoop", "POST", {"options": zigzag}),
        ("export/exp", f"zigzag 0.1 mm spacing, {hoop:g} mm hoop", "POST", {"options": zigzag}),
        ("export/vp3", f"zigzag 0.1 mm spacing, {hoop:g} mm hoop", "POST", {"options": zigzag}),
        ("export/svg", "the drawing", "POST", {}),
        ("export/json", "the drawing", "POST", {}),
        ("edits", "save 9,000 edits", "POST", {"edits": many}),
        ("profiles", "a 61 kB profile", "POST", {"name": "big.toml", "text": profile_text}),
        ("image", "the drawing", "GET", ""),
        ("ports", "list", "GET", ""),
    ]


def size_at_step_budget(session, step: float) -> float:
    """The size (mm, 1 % under) at which the session's drawing, at a style step of `step` mm,
    makes the studio's embroidery step budget (`fabrication.studio.budgets.STEPS`): the most
    work a preview in budget does."""
    from fabrication.placement import PlacementOptions, place
    from fabrication.studio.budgets import STEPS
    from vectorize.refine.edits import Edits

    drawing = session.vectorize(Edits()).drawing
    per_mm = sum(s.length for s in place(drawing, PlacementOptions(size=1000.0)).strokes) / 1000.0
    return 0.99 * STEPS * step / per_mm


def _status(key: str) -> float:
    return int(re.search(key + r":\s+(\d+)", Path("/proc/self/status").read_text()).group(1)) / 1024


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("drawing", nargs="?", default=str(ROOT / "examples" / "loops.png"))
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--only", default="", help="comma-separated endpoints (default: all)")
    parser.add_argument("--root", default=str(ROOT), help="the checkout to import onestroke from")
    parser.add_argument("--bed", type=float, default=None, help="bed side of the uploaded profile (mm)")
    parser.add_argument("--hoop", type=float, default=None, help="custom hoop side (mm)")
    args = parser.parse_args()
    if needs_rerun(args.root):
        sys.exit(rerun_on(args.root, __file__, sys.argv[1:]))
    warnings.filterwarnings("ignore")
    from starlette.testclient import TestClient

    from fabrication.studio.app import create_app
    from fabrication.studio.session import StudioSession

    bed, hoop = args.bed, args.hoop
    if bed is None or hoop is None:  # the largest the declarations take
        try:
            from machines.hoops import HOOP_SIDE
            from machines.laser_profile import BED_SIDE
            bed, hoop = bed or BED_SIDE.high, hoop or HOOP_SIDE.high
        except ImportError:  # a checkout without them: no limit was declared
            bed, hoop = bed or 10_000.0, hoop or 11_000.0
    session = StudioSession(args.drawing, edits_path=Path(os.devnull), precompute=False)
    session.warm()
    try:
        budget_size = min(hoop, size_at_step_budget(session, 0.1))
    except ImportError:  # a checkout without the budget
        budget_size = 570.0
    host = "127.0.0.1:1"
    client = TestClient(create_app(session, token="t", hosts={host}), base_url=f"http://{host}")
    client.headers["X-Studio-Token"] = "t"
    client.get("/api/state")
    only = set(filter(None, args.only.split(",")))
    print(f"{Path(args.drawing).name}, from {args.root}; load average {os.getloadavg()[0]:.1f}; "
          f"rss after the first state {_status('VmRSS'):.0f} MB")
    worst: dict[str, tuple[float, float, float, str]] = {}
    for endpoint, label, method, body in cases(bed, hoop, budget_size):
        if only and endpoint not in only:
            continue
        body = json.loads(json.dumps(body))
        if isinstance(body, dict) and (body.get("options") or {}).get("profile") == "@big":
            uploaded = client.post("/api/profiles", json={"name": "big.toml", "text": BIG_BED.format(side=bed)})
            if uploaded.status_code != 200:
                print(f"{endpoint:13} {label}: the profile was refused: {uploaded.json()['error']}")
                continue
            body["options"]["profile"] = uploaded.json()["id"]
        walls, cpus, peaks = [], [], []
        for _ in range(args.repeats):
            if endpoint == "state":  # a setting never computed: only the gray images stay cached
                for store in (session.cache.axis, session.cache.front, session.cache.simplified,
                              session.cache.solved):
                    store.clear()
            Path("/proc/self/clear_refs").write_text("5")  # VmHWM := VmRSS
            started, cpu = time.perf_counter(), time.process_time()
            if method == "GET":
                answer = client.get(f"/api/{endpoint}" + (f"?{body}" if body else ""))
            else:
                answer = client.post(f"/api/{endpoint}", json=body)
            cpus.append(time.process_time() - cpu)
            walls.append(time.perf_counter() - started)
            peaks.append(_status("VmHWM"))
        said = answer.json().get("error", "") if answer.status_code != 200 else ""
        if endpoint == "state":  # the drawing's own state again (not timed), for the next cases
            client.get("/api/state")
        row = (median(walls), median(cpus), max(peaks), label)
        print(f"{endpoint:13} {label:50} {answer.status_code} wall {row[0]:6.2f} s  cpu {row[1]:6.2f} s  "
              f"peak {row[2]:5.0f} MB  {len(answer.content) / 1e6:5.1f} MB {said[:140]}", flush=True)
        if answer.status_code == 200 and (endpoint not in worst or row[1] > worst[endpoint][1]):
            worst[endpoint] = row
    print(f"\nworst case per endpoint (median of {args.repeats}; load average {os.getloadavg()[0]:.1f}):")
    for endpoint, (wall, cpu, peak, label) in worst.items():
        print(f"  {endpoint:13} wall {wall:6.2f} s  cpu {cpu:6.2f} s  peak {peak:5.0f} MB  ({label})")


if __name__ == "__main__":
    main()

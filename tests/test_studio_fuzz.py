"""Issue 25: the studio's API keeps the CLI's ranges and its work bounded.

An out-of-range option or edit is answered 400 with the line the command line gives, never
500. Hypothesis then posts random and adversarial JSON to every endpoint of a real studio
server in its own process: every answer is 200, 400 or 413; the server's CPU time per
request stays under 2 s and its peak memory under 500 MB (a job that is really sent to the
emulator is let run, then aborted, and not counted).
"""

from __future__ import annotations

import json
import math
import os
import re
import subprocess
import sys
import time
from pathlib import Path

import httpx
import pytest
from click.testing import CliRunner
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from starlette.testclient import TestClient

from fabrication.cli import main
from fabrication.studio.app import MAX_BODY, create_app
from benchmarks.studio_worst import size_at_step_budget
from fabrication.studio.session import EMBROIDERY_FIELDS, LASER_FIELDS, StudioSession

ROOT = Path(__file__).resolve().parents[1]
HOST = "127.0.0.1:8765"
TOKEN = "test-token-789"
EDITS = {"format": "onestroke-edits", "version": 1, "edits": []}


@pytest.fixture(scope="module")
def client(tmp_path_factory):
    folder = tmp_path_factory.mktemp("studio-ranges")
    drawing = folder / "loops.png"
    drawing.write_bytes((ROOT / "examples" / "loops.png").read_bytes())
    app = create_app(StudioSession(drawing), token=TOKEN, hosts={HOST})
    with TestClient(app, base_url=f"http://{HOST}", headers={"X-Studio-Token": TOKEN}) as test_client:
        yield test_client, drawing


# (endpoint, request body, the command line that gives the same line)
SAME_LINE = [
    ("laser", {"options": {"passes": 1000000000}}, ["laser", "-o", "{out}/a.gcode", "--passes", "1000000000"]),
    ("laser", {"options": {"passes": "1e9"}}, ["laser", "-o", "{out}/a.gcode", "--passes", "1e9"]),
    ("laser", {"options": {"feed": "1e12"}}, ["laser", "-o", "{out}/a.gcode", "--feed", "1e12"]),
    ("laser", {"options": {"size": "0.001mm"}}, ["laser", "-o", "{out}/a.gcode", "--size", "0.001mm"]),
    ("laser", {"options": {"power": "0%"}}, ["laser", "-o", "{out}/a.gcode", "--power", "0%"]),
    ("export/gcode", {"options": {"tolerance": "0.001mm"}},
     ["laser", "-o", "{out}/a.gcode", "--tolerance", "0.001mm"]),
    ("embroidery", {"options": {"rotate": 400}}, ["embroider", "-o", "{out}/a.pes", "--rotate", "400"]),
    ("embroidery", {"options": {"spm": "50"}}, ["embroider", "-o", "{out}/a.pes", "--spm", "50"]),
    ("embroidery", {"options": {"hoop": "11000x11000", "size": "10000mm", "style": "zigzag", "spacing": "0.1mm"}},
     ["embroider", "-o", "{out}/a.pes", "--hoop", "11000x11000", "--size", "10000mm", "--style", "zigzag",
      "--spacing", "0.1mm"]),
    ("export/pes", {"options": {"style": "zigzag", "spacing": "0.01mm"}},
     ["embroider", "-o", "{out}/a.pes", "--style", "zigzag", "--spacing", "0.01mm"]),
    ("export/dst", {"options": {"stitch_length": "0.2mm"}},
     ["embroider", "-o", "{out}/a.dst", "--stitch-length", "0.2mm"]),
    # the baud rate: the CLI's number grammar and check (it used to be int() of the value)
    ("send", {"port": "sim://", "baud": "1234"}, ["laser", "-o", "{out}/a.gcode", "--port", "sim://", "--baud", "1234"]),
    ("send", {"port": "sim://", "baud": "0"}, ["laser", "-o", "{out}/a.gcode", "--port", "sim://", "--baud", "0"]),
    ("send", {"port": "sim://", "baud": "fast"}, ["laser", "-o", "{out}/a.gcode", "--port", "sim://", "--baud", "fast"]),
    ("send", {"port": "sim://", "baud": "115200.0"},
     ["laser", "-o", "{out}/a.gcode", "--port", "sim://", "--baud", "115200.0"]),
    ("send", {"port": "sim://", "baud": "1e5"}, ["laser", "-o", "{out}/a.gcode", "--port", "sim://", "--baud", "1e5"]),
    ("state", {"edits": dict(EDITS, blur=1e9)}, ["vectorize", "-o", "{out}/a.svg", "--blur", "1e+09"]),
    ("state", {"edits": dict(EDITS, threshold=1.5)}, ["vectorize", "-o", "{out}/a.svg", "--threshold", "1.5"]),
    ("export/svg", {"edits": dict(EDITS, blur=-1)}, ["vectorize", "-o", "{out}/a.svg", "--blur", "-1"]),
]


@pytest.mark.parametrize("endpoint,body,argv", SAME_LINE, ids=[f"{e} {json.dumps(b)[:50]}" for e, b, _ in SAME_LINE])
def test_out_of_range_values_get_the_command_lines_answer(client, tmp_path, endpoint, body, argv):
    test_client, drawing = client
    started = time.perf_counter()
    answer = test_client.post(f"/api/{endpoint}", json=body)
    assert time.perf_counter() - started < 2.0
    assert answer.status_code == 400, answer.text
    result = CliRunner().invoke(main, [argv[0], str(drawing)] + [a.replace("{out}", str(tmp_path)) for a in argv[1:]])
    # A value read from the edits is named with the file it came from ("edits: --blur ...").
    where = "edits: " if "edits" in body else ""
    assert result.exit_code == 2 and f"error: {where}{result.stderr.strip()[len('error: '):]}" == \
        f"error: {answer.json()['error']}"


# -- the fuzz, against a server in its own process ---------------------------------------------

SERVER = """
import sys
from fabrication.studio.server import StudioServer
from fabrication.studio.session import StudioSession
server = StudioServer(StudioSession(sys.argv[1], precompute=False), port=0).start()
print(server.url, flush=True)
server.thread.join()
"""


class Server:
    """A studio server process; its CPU time and memory read from /proc."""

    def __init__(self, drawing: Path) -> None:
        self.drawing = drawing
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
        self.process = subprocess.Popen([sys.executable, "-c", SERVER, str(drawing)], stdout=subprocess.PIPE,
                                        text=True, env=env)
        url = self.process.stdout.readline().strip()
        match = re.fullmatch(r"(http://[^/]+)/\?token=(\S+)", url)
        assert match, url
        self.base, self.token = match.groups()
        self.client = httpx.Client(base_url=self.base, headers={"X-Studio-Token": self.token}, timeout=120)
        self.cpu_seconds: list[tuple[float, str]] = []
        self.wall_seconds: list[float] = []
        self.answers: dict[tuple[str, int], int] = {}

    def cpu(self) -> float:
        fields = Path(f"/proc/{self.process.pid}/stat").read_text().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")

    def peak_mb(self) -> float:
        status = Path(f"/proc/{self.process.pid}/status").read_text()
        return int(re.search(r"VmHWM:\s+(\d+) kB", status).group(1)) / 1024

    def request(self, method: str, path: str, content: bytes | None) -> httpx.Response:
        before, started = self.cpu(), time.perf_counter()
        answer = self.client.request(method, path, content=content,
                                     headers={"Content-Type": "application/json"} if content is not None else {})
        self.wall_seconds.append(time.perf_counter() - started)
        key = (f"{method} {path}", answer.status_code)
        self.answers[key] = self.answers.get(key, 0) + 1
        self.cpu_seconds.append((self.cpu() - before, f"{method} {path} {(content or b'')[:300]!r}"))
        if path == "/api/send" and method == "POST" and answer.status_code == 200:
            self.finish_job()
        return answer

    def finish_job(self) -> None:
        """A real job was sent: stop it and wait until its port is closed (not counted)."""
        self.client.post("/api/send/abort")
        deadline = time.monotonic() + 60
        while self.client.get("/api/send").json()["state"] in ("connecting", "streaming", "paused", "aborting"):
            assert time.monotonic() < deadline
            time.sleep(0.05)

    def stop(self) -> None:
        self.client.close()
        self.process.terminate()
        self.process.wait(10)


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    folder = tmp_path_factory.mktemp("studio-fuzz")
    drawing = folder / "loops.png"
    drawing.write_bytes((ROOT / "examples" / "loops.png").read_bytes())
    running = Server(drawing)
    yield running
    running.stop()


ENDPOINTS = [("GET", "/api/state"), ("POST", "/api/state"), ("POST", "/api/embroidery"), ("POST", "/api/laser"),
             ("POST", "/api/export/svg"), ("POST", "/api/export/json"), ("POST", "/api/export/edits"),
             ("POST", "/api/export/pes"), ("POST", "/api/export/dst"), ("POST", "/api/export/gcode"),
             ("POST", "/api/export/exe"), ("GET", "/api/edits"), ("POST", "/api/edits"), ("GET", "/api/send"),
             ("POST", "/api/send"), ("POST", "/api/send/pause"), ("POST", "/api/send/resume"),
             ("POST", "/api/send/abort"), ("POST", "/api/send/explode"), ("GET", "/api/ports"),
             ("GET", "/api/profiles"), ("POST", "/api/profiles"), ("GET", "/api/image"), ("GET", "/api/mask")]

huge = st.sampled_from([1e308, -1e308, 1e12, 1e9, -1e9, 2**63, -(2**63), 10**30, 0, -0.0, 1e-300, math.nan,
                        math.inf, -math.inf])
numbers = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.integers(-10**20, 10**20), huge)
units = st.sampled_from(["", "mm", "in", "cm", "m", "px", "pt", "%", "mm/min", "mm/s", "in/min", "km", "mm/h", " mm"])
number_text = st.one_of(st.builds(lambda n, u: f"{n}{u}", numbers, units), st.text(max_size=30),
                        st.sampled_from(["1e9", "1e999", "-0", "nan", "inf", "0x10", "1_000", "١٢", "90mm ",
                                         "100x100", "5x7", "0x0", "1e6x1e6", "#zzz", "red,,", "sim://"]))
scalars = st.one_of(st.none(), st.booleans(), numbers, number_text)
json_values = st.recursive(scalars, lambda inner: st.one_of(st.lists(inner, max_size=4),
                                                            st.dictionaries(st.text(max_size=8), inner, max_size=4)),
                           max_leaves=12)
option_names = st.sampled_from(sorted(set(EMBROIDERY_FIELDS) | set(LASER_FIELDS)) + ["profile_path", "x", ""])


def _declared() -> dict:
    """Page field -> the Ranges it is checked against (embroidery and laser may differ)."""
    from fabrication.embroidery.arrows import ARROW_SIZE
    from fabrication.embroidery.pipeline import EmbroideryJob
    from fabrication.embroidery.plan import PlanOptions
    from fabrication.embroidery.running import STITCH_LENGTH, TOLERANCE
    from fabrication.embroidery.triple import REPEATS
    from fabrication.embroidery.zigzag import PULL_COMPENSATION, SPACING, STITCH_WIDTH
    from fabrication.laser.gcode_write import FEED, PASSES, POWER
    from fabrication.laser.toolpath import TOLERANCE as LASER_TOLERANCE
    from fabrication.placement import ROTATE, SIDE
    from onestroke.ranges import ranges_of

    plan = ranges_of(PlanOptions)
    return {"size": [SIDE], "rotate": [ROTATE], "stitch_length": [STITCH_LENGTH], "tolerance": [TOLERANCE, LASER_TOLERANCE],
            "stitch_width": [STITCH_WIDTH], "spacing": [SPACING], "pull_comp": [PULL_COMPENSATION],
            "repeats": [REPEATS], "arrow_size": [ARROW_SIZE], "min_stitch": [plan["min_stitch"]],
            "max_stitch": [plan["max_stitch"]], "trim_distance": [plan["trim_distance"]],
            "spm": [ranges_of(EmbroideryJob)["stitches_per_minute"]], "feed": [FEED], "power": [POWER],
            "passes": [PASSES]}


def _edge_values(limits, inside: bool) -> list:
    """The bounds and the middle (inside), or values just outside, as the page sends them
    (text with unit) and as JSON numbers."""
    low, high = limits.low, limits.high
    points = [low, high, (low + high) / 2] if inside else [low - 1, high * 2]
    unit = {"mm": "mm", "mm/min": "mm/min", "%": "%"}.get(limits.unit, "")
    shown = [int(v) if limits.integer else v * limits.scale for v in points]
    return [f"{v:g}{unit}" if not limits.integer else str(v) for v in shown] + shown


def _edge_options(inside: bool):
    values = {name: st.sampled_from([v for limits in ranges for v in _edge_values(limits, inside)])
              for name, ranges in _declared().items()}
    styles = st.sampled_from(["running", "triple", "zigzag", "arrows"])
    return st.fixed_dictionaries({"style": styles}, optional=values)


options = st.one_of(_edge_options(True), _edge_options(False),
                    st.dictionaries(option_names, st.one_of(scalars, json_values), max_size=6))
edit_items = st.lists(st.fixed_dictionaries(
    {"kind": st.sampled_from(["pairing", "passes", "split", "merge", "reverse", "start", "twice", "once",
                              "unbridge", "nope"]),
     "at": st.one_of(st.tuples(numbers, numbers).map(list), json_values)},
    optional={"pairing": st.sampled_from(["crossing", "touching", "third", "x"]),
              "passes": st.one_of(json_values, st.lists(st.tuples(numbers, numbers).map(list), max_size=5))}),
    max_size=6)
edits = st.one_of(json_values, st.fixed_dictionaries(
    {"format": st.just("onestroke-edits"), "version": st.just(1)},
    optional={"threshold": st.one_of(scalars, st.floats(0, 1)), "blur": st.one_of(scalars, st.floats(0, 30)),
              "multi": scalars, "tolerance": st.one_of(scalars, numbers), "edits": st.one_of(edit_items, json_values)}))
ports = st.one_of(st.sampled_from(["sim://", "sim://?speed=1000", "sim://?pro%66ile=/etc/passwd", "/dev/ttyUSB9",
                                   "socket://127.0.0.1:1", "sim://?speed=1e9", "/etc/passwd", "COM1"]),
                  st.text(max_size=40), json_values)
bodies = st.one_of(
    st.fixed_dictionaries({}, optional={"edits": edits, "options": options, "port": ports, "baud": scalars,
                                        "page": scalars, "name": scalars, "text": st.one_of(scalars, st.text())}),
    json_values)


def _encode(body) -> bytes:
    return json.dumps(body, allow_nan=True).encode()


raw = st.one_of(bodies.map(_encode), st.binary(max_size=200),
                st.sampled_from([b"", b"{", b"[]", b"null", b"\xff\xfe", b'{"edits": ' * 500,
                                 b"[" * 100_000 + b"]" * 100_000, b"x" * (MAX_BODY + 10),
                                 b'{"options": {"size": "' + b"9" * 5000 + b'mm"}}']))


@settings(max_examples=int(os.environ.get("STUDIO_FUZZ_EXAMPLES", "150")), deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture,
                                 HealthCheck.data_too_large])
@given(endpoint=st.sampled_from(ENDPOINTS), content=raw)
def test_any_request_is_answered_200_400_or_413_within_bounds(server, endpoint, content):
    method, path = endpoint
    answer = server.request(method, path, content if method == "POST" else None)
    assert answer.status_code in (200, 400, 413), (answer.status_code, answer.text[:300], content[:300])
    if answer.status_code != 200:
        assert "internal error" not in answer.text
    cpu, what = server.cpu_seconds[-1]
    assert cpu < 2.0, (cpu, what)
    assert server.peak_mb() < 500, server.peak_mb()


def test_the_fuzz_figures(server):
    """Runs after the fuzz: prints its figures (a record, not a timing assertion)."""
    if not server.cpu_seconds:
        pytest.skip("the fuzz did not run")
    cpu = sorted(c for c, _ in server.cpu_seconds)
    wall = sorted(server.wall_seconds)
    print(f"\nstudio fuzz: {len(cpu)} requests, CPU s median {cpu[len(cpu) // 2]:.3f} max {cpu[-1]:.3f}; "
          f"wall s median {wall[len(wall) // 2]:.3f} max {wall[-1]:.3f}; peak {server.peak_mb():.0f} MB; "
          f"slowest: {max(server.cpu_seconds)[1][:200]}")
    print("answers:", ", ".join(f"{what} {code}: {n}" for (what, code), n in sorted(server.answers.items())))


# -- the heaviest requests in range (benchmarks/studio_worst.py times them) --------------------

LASER_WORST = {"size": "400mm", "tolerance": "0.005mm", "passes": "100"}  # 202,311 lines on loops.png
HOOP_WORST = {"size": "1500mm", "hoop": "1500x1500", "fit": True}  # the largest hoop HOOP_SIDE takes
HEAVIEST = [
    ("laser", {"options": LASER_WORST}, 200),
    ("laser", {"options": dict(LASER_WORST, arcs=True)}, 200),
    ("export/gcode", {"options": LASER_WORST}, 200),
    ("laser", {"options": dict(LASER_WORST, size="2500mm", profile="@big")}, 200),  # the largest bed a profile takes
    ("export/gcode", {"options": dict(LASER_WORST, size="2500mm", profile="@big")}, 200),
    # the most steps along the curve the studio's budget lets a preview make (the size: below)
    ("embroidery", {"options": dict(HOOP_WORST, style="satin", spacing="0.1mm", size="@budget")}, 200),
    ("export/pes", {"options": dict(HOOP_WORST, style="satin", spacing="0.1mm", size="@budget")}, 200),
    ("embroidery", {"options": dict(HOOP_WORST, style="triple", stitch_length="0.1mm", min_stitch="0.1mm",
                                    repeats="5", size="@budget")}, 200),
    # as many "draw twice" edits as a 1 MiB body holds, about: each matched to its nearest branch
    ("state", {"edits": dict(EDITS, edits=[{"kind": "twice", "at": [float(i * 37 % 997), float(i * 13 % 599)]}
                                           for i in range(12000)])}, 200),
    # beyond the studio's budgets: refused before the work (tests/test_studio_budgets.py)
    ("embroidery", {"options": dict(HOOP_WORST, style="zigzag", spacing="0.1mm")}, 400),
    ("export/pes", {"options": dict(HOOP_WORST, style="zigzag", spacing="0.1mm")}, 400),
    ("state", {"edits": dict(EDITS, threshold=0.05)}, 400),
    ("state", {"edits": dict(EDITS, threshold=0.05, multi=True)}, 400),
]


@pytest.mark.parametrize("endpoint,body,status", HEAVIEST, ids=[f"{e} {json.dumps(b)[:80]}" for e, b, _ in HEAVIEST])
def test_the_heaviest_requests_in_range_stay_within_500_mb(server, endpoint, body, status):
    """Each answered (200, or 400 where a budget refuses it), the server process's peak
    memory during the request (VmHWM, reset before it) under 500 MB. The CPU seconds are
    printed; timing is the benchmark's."""
    body = json.loads(json.dumps(body))
    if body.get("options", {}).get("profile") == "@big":
        text = 'name = "largest bed"\n[bed]\nsize = "2500x2500mm"\n'
        uploaded = server.client.post("/api/profiles", json={"name": "big.toml", "text": text})
        assert uploaded.status_code == 200, uploaded.text
        body["options"]["profile"] = uploaded.json()["id"]
    if body.get("options", {}).get("size") == "@budget":
        body["options"]["size"] = f"{size_at_step_budget(StudioSession(server.drawing), 0.1):.1f}mm"
    Path(f"/proc/{server.process.pid}/clear_refs").write_text("5")  # its peak := its memory now
    answer = server.request("POST", f"/api/{endpoint}", json.dumps(body).encode())
    assert answer.status_code == status, answer.text[:300]
    cpu, _ = server.cpu_seconds[-1]
    print(f"\n{endpoint} {json.dumps(body)[:120]}: CPU {cpu:.2f} s, wall {server.wall_seconds[-1]:.2f} s, "
          f"peak {server.peak_mb():.0f} MB")
    assert server.peak_mb() < 500, server.peak_mb()

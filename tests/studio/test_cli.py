"""`onestroke studio` as a user runs it: a real process on 127.0.0.1, its printed address,
the page and the API answering, Ctrl-C stopping it; bad input refused in one line."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
from pathlib import Path

import httpx
from click.testing import CliRunner

from fabrication.cli import main
from tests.children import child_env

ROOT = Path(__file__).resolve().parents[2]


def test_studio_serves_the_page_and_stops_on_ctrl_c(tmp_path):
    env = child_env()
    process = subprocess.Popen(
        [sys.executable, "-c", "import signal; signal.signal(signal.SIGINT, signal.default_int_handler); "
         "from fabrication.cli import main; main()", "studio", str(ROOT / "examples" / "loops.png"),
         "--no-browser", "--edits", str(tmp_path / "e.json")],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    try:
        line = process.stdout.readline()
        url = re.search(r"http://127\.0\.0\.1:\d+/\?token=\S+", line)
        assert url, line + process.stderr.read()
        with httpx.Client() as client:
            page = client.get(url.group(0))
            assert page.status_code == 200 and "onestroke studio" in page.text
            state = client.get(url.group(0).split("?")[0] + "api/state")  # the cookie carries the token
            assert state.status_code == 200 and state.json()["report"]["strokes"] == 1
            # Every file the page loads is served, and shipped in the package (package-data).
            for name in page_assets(client, url.group(0).split("?")[0], page.text):
                assert shipped(name), f"{name} is not in pyproject's package-data"
            assert httpx.get(url.group(0).split("?")[0] + "api/state").status_code == 403
    finally:
        process.send_signal(signal.SIGINT)
        out, err = process.communicate(timeout=20)
    assert process.returncode == 0, err
    assert "Traceback" not in err


def page_assets(client, base: str, html: str) -> set[str]:
    """The static files the page loads: its <link>/<script> files and the JS modules they
    import, each fetched (200, not empty)."""
    names, todo = set(), re.findall(r'(?:href|src)="static/([^"]+)"', html)
    while todo:
        name = todo.pop()
        if name in names:
            continue
        names.add(name)
        answer = client.get(base + "static/" + name)
        assert answer.status_code == 200 and answer.content, name
        if name.endswith(".js"):
            todo += re.findall(r'from "\./([^"]+)"', answer.text)
    assert {"app.js", "api.js", "panels.js", "player.js", "style.css", "player.css"} <= names
    return names


def shipped(name: str) -> bool:
    """Whether pyproject's package-data globs take static/NAME of the studio or the player."""
    import fnmatch
    import tomllib

    data = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]
    for package in ("fabrication.studio", "fabrication.player"):
        folder = ROOT / package.replace(".", "/") / "static"
        if (folder / name).is_file() and any(fnmatch.fnmatch(f"static/{name}", g) for g in data.get(package, [])):
            return True
    return False


def test_studio_refuses_bad_input(tmp_path):
    run = CliRunner().invoke(main, ["studio", str(tmp_path / "missing.png"), "--no-browser"])
    assert run.exit_code == 2 and "does not exist" in run.output
    (tmp_path / "bad.json").write_text("{")
    run = CliRunner().invoke(main, ["studio", str(ROOT / "examples" / "loops.png"), "--no-browser",
                                    "--edits", str(tmp_path / "bad.json")])
    assert run.exit_code == 2 and "not JSON" in run.output


def test_studio_refuses_a_folder_a_non_image_and_bad_ports(tmp_path):
    """One line each, exit 2, no traceback: a folder, a file that is no image, a port that
    is no number or out of range, and a port in use (refused before the vectorization, and
    without uvicorn's own log line)."""
    import socket

    loops = str(ROOT / "examples" / "loops.png")
    (tmp_path / "notes.png").write_text("not an image")
    busy = socket.socket()
    busy.bind(("127.0.0.1", 0))
    busy.listen()
    taken = busy.getsockname()[1]
    cases = [([str(tmp_path)], "is a directory, not an image"), ([str(tmp_path / "notes.png")], "is not an image"),
             ([loops, "--port", "abc"], "is not a whole number"), ([loops, "--port", "70000"], "from 0 to 65535")]
    try:
        for args, message in cases:
            run = CliRunner().invoke(main, ["studio", *args, "--no-browser"])
            assert run.exit_code == 2 and message in run.output, (args, run.output)
            assert len(run.output.strip().splitlines()) == 1, (args, run.output)
            assert run.exception is None or isinstance(run.exception, SystemExit), (args, run.exception)
        # A port in use, in a real process: its stderr is the one line (uvicorn logs nothing).
        run = subprocess.run([sys.executable, "-m", "fabrication.cli", "studio", loops, "--port", str(taken),
                              "--no-browser"], capture_output=True, text=True, timeout=60,
                             env={**os.environ, "NO_COLOR": "1"})
        assert run.returncode == 2, (run.stdout, run.stderr)
        assert f"cannot listen on 127.0.0.1:{taken}" in run.stderr and len(run.stderr.strip().splitlines()) == 1, \
            run.stderr
        assert "Traceback" not in run.stderr + run.stdout and "vectoriz" not in run.stdout, run.stdout
    finally:
        busy.close()

"""Issue 25, security: only the studio's own page drives the studio, and the server never
opens a path a request names.

The cross-origin test is a real attack in Chromium: the user has the studio open (its
cookie is in the browser), and a page served from another port of 127.0.0.1 (the same
site) tries everything a page can do, even knowing the token: no-cors and credentialed
fetches, form POSTs in the three encodings, an EventSource, a WebSocket and a frame.
Nothing may reach the studio's routes: no file written, no job started, no state computed.
"""

from __future__ import annotations

import http.server
import json
import threading

import pytest
from starlette.testclient import TestClient

from fabrication.studio.app import checked_port, create_app
from fabrication.studio.server import StudioServer
from fabrication.studio.session import StudioSession
from onestroke.errors import InputError
from tests.chromium import ARTIFACTS
from tests.studio.browser_page import IDLE

HOST = "127.0.0.1:8765"
TOKEN = "test-token-456"


@pytest.fixture
def session(loop_png):
    edits = loop_png.with_name("loop.edits.json")
    edits.unlink(missing_ok=True)
    return StudioSession(loop_png, edits_path=edits)


# (method, path, headers, status): what a request may do by where it comes from.
OWN = {"Origin": f"http://{HOST}", "Sec-Fetch-Site": "same-origin", "X-Studio-Token": TOKEN}
GUARD = [
    ("POST", "/api/edits", {"X-Studio-Token": TOKEN}, 200),                      # a client with the token
    ("POST", "/api/edits", OWN, 200),                                           # the page itself
    ("POST", "/api/edits", {"Cookie": "{cookie}"}, 403),                        # the cookie alone
    ("POST", f"/api/edits?token={TOKEN}", {}, 403),                             # the URL's token alone
    ("POST", "/api/edits", dict(OWN, Origin="http://127.0.0.1:9999"), 403),     # another local page
    ("POST", "/api/edits", dict(OWN, Origin="null"), 403),                      # a sandboxed frame, file://
    ("POST", "/api/edits", dict(OWN, **{"Sec-Fetch-Site": "same-site"}), 403),
    ("POST", "/api/edits", dict(OWN, **{"Sec-Fetch-Site": "cross-site"}), 403),
    ("POST", "/api/edits", dict(OWN, **{"Sec-Fetch-Site": "none"}), 403),
    ("OPTIONS", "/api/edits", {"Origin": "http://127.0.0.1:9999",                # a CORS preflight
                               "Access-Control-Request-Headers": "x-studio-token"}, 403),
    ("GET", "/api/state", {"Cookie": "{cookie}", "Sec-Fetch-Site": "same-site"}, 403),  # no-cors read
    ("GET", f"/?token={TOKEN}", {"Sec-Fetch-Site": "none"}, 200),                # the address opened
    ("GET", f"/?token={TOKEN}", {"Sec-Fetch-Site": "same-site", "Sec-Fetch-Dest": "iframe"}, 403),
    ("GET", "/static/app.js", {"Cookie": "{cookie}", "Sec-Fetch-Site": "same-origin"}, 200),
]


@pytest.mark.parametrize("method,path,headers,status", GUARD,
                         ids=[f"{m} {p.split('?')[0]} {sorted(h)}" for m, p, h, _ in GUARD])
def test_only_the_studios_own_page_acts(session, method, path, headers, status):
    from fabrication.studio.app import cookie_name

    app = create_app(session, token=TOKEN, hosts={HOST})
    cookie = f"{cookie_name(TOKEN)}={TOKEN}"
    headers = {k: v.replace("{cookie}", cookie) for k, v in headers.items()}
    body = json.dumps({"edits": {"format": "onestroke-edits", "version": 1, "edits": []}})
    with TestClient(app, base_url=f"http://{HOST}") as client:
        answer = client.request(method, path, headers=headers, content=body if method == "POST" else None)
    assert answer.status_code == status, answer.text
    assert answer.headers["x-frame-options"] == "DENY" and "frame-ancestors 'none'" in answer.headers[
        "content-security-policy"] and answer.headers["referrer-policy"] == "no-referrer"
    assert session.edits_path.exists() == (status == 200 and path.startswith("/api/edits"))


def test_a_websocket_is_refused(session):
    from starlette.websockets import WebSocketDisconnect

    app = create_app(session, token=TOKEN, hosts={HOST})
    with TestClient(app, base_url=f"http://{HOST}") as client:
        with pytest.raises(WebSocketDisconnect):
            with client.websocket_connect(f"/?token={TOKEN}", headers={"X-Studio-Token": TOKEN}):
                pass


PORTS_ACCEPTED = ["sim://", "sim://?speed=1", "sim://?sp%65ed=20", "sim://?rx=10", "/dev/ttyUSB0", "/dev/ttyACM1",
                  "/dev/cu.usbserial-1410", "/dev/serial/by-id/usb-1a86_USB2.0-Serial-if00-port0", "COM3"]
PORTS_REFUSED = ["sim://?pro%66ile={path}", "sim://?%70%72%6f%66%69%6c%65={path}", "sim://?speed=1&profile={path}",
                 "sim://?speed=1;profile={path}", "SIM://?profile={path}", "sim://?profile=%2Fetc%2Fpasswd",
                 "sim://{path}", "sim:{path}", "sim://?x=1", "sim://?speed=1e9", "sim://?speed=nan",
                 "{path}", "/dev/../{path}", "/dev/tty/../..{path}", "/dev/shm/x", "/dev/fd/0", "/dev/stdin",
                 "socket://127.0.0.1:23", "rfc2217://127.0.0.1:23", "loop://", "spy://{path}", "COM3/../x", ""]


@pytest.mark.parametrize("port", PORTS_ACCEPTED)
def test_send_ports_the_studio_takes(port):
    assert checked_port(port) == port


@pytest.mark.parametrize("port", PORTS_REFUSED)
def test_a_send_port_that_names_a_file_is_refused_after_decoding(session, tmp_path, port):
    """The port is decoded before it is checked, the answer is the same whether the file
    exists or not (and says nothing of its content), and no job starts."""
    present = tmp_path / "profile.toml"
    present.write_text("name = [broken\n")  # would give a TOML parse error if it were read
    answers = []
    app = create_app(session, token=TOKEN, hosts={HOST})
    with TestClient(app, base_url=f"http://{HOST}", headers={"X-Studio-Token": TOKEN}) as client:
        for path in (present, tmp_path / "absent.toml"):
            answer = client.post("/api/send", json={"port": port.replace("{path}", str(path)),
                                                    "options": {"size": "20mm"}})
            assert answer.status_code == 400, answer.text
            answers.append(answer.json()["error"].replace(str(path), "PATH"))
            with pytest.raises(InputError):
                checked_port(port.replace("{path}", str(path)))
    assert answers[0] == answers[1] and "TOML" not in answers[0] and "exist" not in answers[0]
    assert session.sender is None


# The attacker's page: everything a page on another port can send, with the token even.
ATTACK = """<!doctype html><html><head><meta charset="utf-8"><title>another local page</title></head><body>
<h1>another page on this machine</h1><pre id="log"></pre>
<script>
const studio = STUDIO, token = TOKEN;
const results = {};
const note = (name, value) => { results[name] = String(value); document.getElementById("log").textContent += name + ": " + value + "\\n"; };
const edits = {format: "onestroke-edits", version: 1, threshold: 0.3, blur: 0, multi: false, tolerance: 8, edits: []};
const bodies = {"/api/edits": {edits}, "/api/send": {edits, port: "sim://?speed=1000", options: {size: "20mm"}},
                "/api/state": {edits}, "/api/profiles": {name: "x.toml", text: "name = 'x'"},
                "/api/send/abort": {}, "/api/export/gcode": {edits}};
let frames = 0;
function submit(action, enctype, fields) {
  const frame = document.createElement("iframe"); frame.name = "sink" + (++frames); document.body.appendChild(frame);
  const form = document.createElement("form");
  form.method = "POST"; form.action = action; form.enctype = enctype; form.target = frame.name;
  for (const [name, value] of fields) {
    const input = document.createElement("input"); input.type = "hidden"; input.name = name; input.value = value;
    form.appendChild(input);
  }
  document.body.appendChild(form); form.submit();
}
async function attempt(name, run) {
  try { note(name, await run()); } catch (error) { note(name, "blocked: " + error.message); }
}
(async () => {
  for (const [path, body] of Object.entries(bodies)) {
    const json = JSON.stringify(body);
    for (const url of [studio + path, studio + path + "?token=" + token]) {
      await attempt("no-cors text/plain " + url, async () => (await fetch(url, {method: "POST", mode: "no-cors",
        credentials: "include", headers: {"Content-Type": "text/plain"}, body: json})).type);
      await attempt("simple cors " + url, async () => (await fetch(url, {method: "POST", credentials: "include",
        headers: {"Content-Type": "text/plain"}, body: json})).status);
      await attempt("cors with token header " + url, async () => (await fetch(url, {method: "POST",
        credentials: "include", headers: {"Content-Type": "application/json", "X-Studio-Token": token}, body: json})).status);
      // text/plain form: name + "=" + value spells the JSON body
      submit(url, "text/plain", [[json.slice(0, -1) + ', "x": "', '"}']]);
      submit(url, "application/x-www-form-urlencoded", [["edits", JSON.stringify(edits)], ["port", "sim://"], ["token", token]]);
      submit(url, "multipart/form-data", [["edits", JSON.stringify(edits)], ["port", "sim://"], ["token", token]]);
    }
  }
  await attempt("no-cors GET state", async () => (await fetch(studio + "/api/state?token=" + token,
    {mode: "no-cors", credentials: "include"})).type);
  await attempt("EventSource", () => new Promise((resolve) => {
    const source = new EventSource(studio + "/api/send?token=" + token, {withCredentials: true});
    source.onopen = () => { source.close(); resolve("opened"); };
    source.onerror = () => { source.close(); resolve("blocked: error"); };
  }));
  await attempt("WebSocket", () => new Promise((resolve) => {
    const socket = new WebSocket(studio.replace("http", "ws") + "/?token=" + token);
    socket.onopen = () => { socket.close(); resolve("opened"); };
    socket.onerror = () => resolve("blocked: error");
  }));
  const frame = document.createElement("iframe"); frame.src = studio + "/?token=" + token; document.body.appendChild(frame);
  await new Promise((resolve) => setTimeout(resolve, 1500));  // let the forms and the frame land
  window.finished = results;
})();
</script></body></html>"""


class _Counting:
    """ASGI wrapper around the studio's routes: counts the requests that got past the guard."""

    def __init__(self, app) -> None:
        self.app, self.reached = app, []

    async def __call__(self, scope, receive, send):
        if scope["type"] == "http":
            self.reached.append((scope["method"], scope["path"]))
        await self.app(scope, receive, send)


@pytest.fixture
def attacker():
    """A second local server on another port of 127.0.0.1 serving one page; (server, set_page)."""
    page = {"html": b""}

    class Handler(http.server.BaseHTTPRequestHandler):
        def do_GET(self):  # noqa: N802 - http.server's spelling
            self.send_response(200)
            self.send_header("Content-Type", "text/html; charset=utf-8")
            self.end_headers()
            self.wfile.write(page["html"])

        def log_message(self, *args):
            pass

    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield server, page
    server.shutdown()
    server.server_close()


def test_another_local_page_cannot_drive_the_studio(session, browser, attacker):
    server = StudioServer(session, port=0)
    counting = _Counting(server.app.app)
    server.app.app = counting
    server.start()
    refused = []
    try:
        context = browser.new_context(viewport={"width": 1000, "height": 700})
        studio_page = context.new_page()
        studio_page.set_default_timeout(60000)
        studio_page.goto(server.url)  # the user's studio: its cookie is now in the browser
        studio_page.wait_for_function(f"window.studio.state !== null && {IDLE}", timeout=90000)
        assert any(c["name"].startswith("onestroke_studio") for c in context.cookies())
        profiles_before = session.profile_list()
        counting.reached.clear()

        attack_server, page_html = attacker
        origin = f"http://127.0.0.1:{server.port}"
        page_html["html"] = ATTACK.replace("STUDIO", json.dumps(origin)).replace("TOKEN", json.dumps(server.token)).encode()
        assert attack_server.server_address[1] != server.port
        evil = context.new_page()
        evil.on("response", lambda r: refused.append(r.status) if r.url.startswith(origin) else None)
        evil.goto(f"http://127.0.0.1:{attack_server.server_address[1]}/")
        results = evil.wait_for_function("window.finished", timeout=60000).json_value()
        evil.screenshot(path=str(ARTIFACTS / "studio-security-attacker.png"))

        assert counting.reached == [], counting.reached  # nothing got past the guard
        assert not session.edits_path.exists()           # no file written
        assert session.sender is None                    # no job started
        assert session.profile_list() == profiles_before
        assert results["EventSource"].startswith("blocked") and results["WebSocket"].startswith("blocked")
        assert not any(v in ("200", "opened") for v in results.values()), results
        # The attempts did reach the server, and were refused there.
        assert refused and set(refused) == {403}, refused
        assert len(refused) >= 30

        # The studio's own page still works in the same browser.
        studio_page.click("#save")
        studio_page.wait_for_function(IDLE)
        studio_page.wait_for_timeout(300)
        assert session.edits_path.exists()
        context.close()
    finally:
        server.stop()

"""The studio's web app (Starlette): the page, its static files and a small JSON API.

Security: the server binds 127.0.0.1 only (see `serve`), and only the studio's own page
drives it. Every request needs a Host header naming this server and the session's random
token; a request that changes anything (POST) must carry the token in the X-Studio-Token
header, which a page of another origin cannot set without a CORS preflight, and the
preflight is refused. A request whose Origin is not this server's, or whose Sec-Fetch-Site
is not same-origin, is refused (127.0.0.1 on another port is the same site, so the
SameSite cookie alone would not keep other local pages out); the page itself may also be
opened directly (Sec-Fetch-Site: none), never framed. Reads (GET) may carry the token in
the URL of the first load or the page's cookie. Request bodies are bounded; files are read
and written only where the command line said (the drawing, its edits file, a laser
profile); a profile the user loads in the page arrives as text and is parsed in memory; a
send port is a serial device or the emulator, its URL decoded before it is checked, never a
file path; downloads are made in memory.
"""

from __future__ import annotations

import hashlib
import json
import re
import secrets
import urllib.parse
from importlib import resources

from starlette.applications import Starlette
from starlette.concurrency import run_in_threadpool
from starlette.requests import Request
from starlette.responses import JSONResponse, PlainTextResponse, Response
from starlette.routing import Route

from fabrication.studio.session import StudioSession, Superseded
from onestroke.errors import InputError, OnestrokeError
from vectorize.refine.edits import Edits, edits_from_dict

MAX_BODY = 1 << 20  # 1 MiB: an edits list and option values are a few kB
COOKIE = "onestroke_studio"  # + a digest of the token: cookies ignore ports, two studios must not mix


def cookie_name(token: str) -> str:
    return f"{COOKIE}_{hashlib.sha256(token.encode()).hexdigest()[:10]}"
STATIC = {"app.js": "text/javascript", "api.js": "text/javascript", "panels.js": "text/javascript",
          "view.js": "text/javascript", "marks.js": "text/javascript", "edits.js": "text/javascript",
          "hint.js": "text/javascript", "tools.js": "text/javascript", "junctions.js": "text/javascript",
          "style.css": "text/css", "index.html": "text/html"}
# The toolpath player's files, served from its own package (`fabrication.player`).
PLAYER = {"player.js": "text/javascript", "player.css": "text/css"}
IMAGE_TYPES = {".png": "image/png", ".jpg": "image/jpeg", ".jpeg": "image/jpeg", ".svg": "image/svg+xml",
               ".gif": "image/gif", ".webp": "image/webp"}


def _static(name: str) -> bytes:
    return resources.files("fabrication.studio").joinpath("static", name).read_bytes()


class TooLarge(InputError):
    """A request body over MAX_BODY (answered 413)."""


# Sent with every answer: never framed by another page (clickjacking), no referrer (the
# address carries the token), content types taken as given.
SECURITY_HEADERS = [(b"x-frame-options", b"DENY"), (b"content-security-policy", b"frame-ancestors 'none'"),
                    (b"referrer-policy", b"no-referrer"), (b"x-content-type-options", b"nosniff")]


class Guard:
    """ASGI middleware: Host, Origin, Sec-Fetch-Site, token and body size checked before any
    route runs (see the module docstring)."""

    def __init__(self, app, *, token: str, hosts: set[str]) -> None:
        self.app, self.token, self.hosts = app, token, hosts
        self.origins = {f"http://{host}" for host in hosts}

    def _token(self, offered: str) -> bool:
        return secrets.compare_digest(offered.encode("latin-1", "replace"), self.token.encode())

    def allowed(self, scope) -> bool:
        """Whether the request comes from this studio's own page (or a client holding the token
        that is no browser page of another origin)."""
        headers = {k.decode("latin-1").lower(): v.decode("latin-1") for k, v in scope["headers"]}
        if headers.get("host", "") not in self.hosts:
            return False
        if "origin" in headers and headers["origin"] not in self.origins:
            return False
        method = scope.get("method", "GET")
        site = headers.get("sec-fetch-site")
        opened = site == "none" and method == "GET" and scope.get("path") == "/"  # typed or clicked address
        if site is not None and site != "same-origin" and not opened:
            return False
        if self._token(headers.get("x-studio-token", "")):
            return True
        if method not in ("GET", "HEAD"):
            return False  # a change needs the header: a form or a no-cors fetch cannot send it
        query = urllib.parse.parse_qs(scope.get("query_string", b"").decode("latin-1"))
        cookies = {}
        for part in headers.get("cookie", "").split(";"):
            key, _, value = part.strip().partition("=")
            cookies[key] = value
        return self._token(query.get("token", [""])[-1]) or self._token(cookies.get(cookie_name(self.token), ""))

    async def __call__(self, scope, receive, send):
        if scope["type"] == "websocket":  # the studio has none: refuse before any handshake
            return await send({"type": "websocket.close", "code": 1008})
        if scope["type"] != "http":
            return await self.app(scope, receive, send)

        async def send_secured(message):
            if message["type"] == "http.response.start":
                message = dict(message, headers=list(message.get("headers", [])) + SECURITY_HEADERS)
            await send(message)

        if not self.allowed(scope):
            return await PlainTextResponse("forbidden", status_code=403)(scope, receive, send_secured)
        headers = dict(scope["headers"])
        length = headers.get(b"content-length")
        if length is not None and (not length.isdigit() or int(length) > MAX_BODY):
            return await PlainTextResponse("request too large", status_code=413)(scope, receive, send_secured)
        seen = 0

        async def bounded():
            nonlocal seen
            message = await receive()
            seen += len(message.get("body", b""))
            if seen > MAX_BODY:
                raise TooLarge("request too large")
            return message

        return await self.app(scope, bounded, send_secured)


# A serial device as the port list names them: /dev/ttyUSB0, /dev/ttyACM0, /dev/cu.usbserial-1410,
# /dev/serial/by-id/usb-1a86_USB2.0-Serial-if00-port0, COM3. No other path, no other URL.
SERIAL_DEVICE = re.compile(r"/dev/(tty|cu\.)[A-Za-z0-9_.-]+|/dev/serial/by-(id|path)/[A-Za-z0-9_.:+-]+|COM[0-9]{1,3}")
# What the studio's emulator may be told: every sim:// parameter but `profile` (a file path).
SIM_KEYS = ("speed", "rx", "blocks", "laser", "travel", "drop_hold")


def checked_port(port: str) -> str:
    """A serial device or the emulator (`sim://`, `sim://?speed=N`), after percent-decoding;
    never another pyserial URL (socket://, rfc2217:// reach the network) nor an emulator
    told to read a file (`profile=`)."""
    text = str(port).strip()
    if SERIAL_DEVICE.fullmatch(text) and "/../" not in text:
        return text
    parts = urllib.parse.urlsplit(text)
    if parts.scheme.lower() == "sim" and not parts.netloc and parts.path in ("", "/") and not parts.fragment:
        keys = [key for key, _ in urllib.parse.parse_qsl(parts.query, keep_blank_values=True)]
        if set(keys) <= set(SIM_KEYS):
            from machines.sim_url.protocol_sim import parse_sim_url

            try:
                parse_sim_url(text)  # the values are the emulator's to check
            except ValueError as error:
                raise InputError(f"port {text!r}: {error}") from None
            return text
        raise InputError(f"port {text!r}: the studio's emulator takes {', '.join(SIM_KEYS)} "
                         "(e.g. sim://?speed=1), no file")
    raise InputError(f"port {text!r}: give a serial device (/dev/ttyUSB0, COM3) or sim:// for a dry run")


def _malloc_trim():
    """glibc's malloc_trim, or None (another C library): see `release_memory`."""
    import ctypes
    import ctypes.util

    try:
        return ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6").malloc_trim
    except (OSError, AttributeError):
        return None


MALLOC_TRIM = _malloc_trim()


def release_memory() -> None:
    """Give the memory a request freed back to the system. glibc keeps freed blocks in the
    arena of the thread that used them (each request runs in a pool thread), so without this
    a session's resident memory crept from 180 to 365 MB over eight of the heaviest requests
    (and the next one peaked from there); with it, it stays near 180 MB. A few ms."""
    if MALLOC_TRIM is not None:
        MALLOC_TRIM(0)


def _error(error: Exception) -> JSONResponse:
    status = 413 if isinstance(error, TooLarge) else 400 if isinstance(error, InputError) else 500
    return JSONResponse({"error": str(error)}, status_code=status)


def create_app(session: StudioSession, *, token: str, hosts: set[str]) -> Guard:
    """The ASGI app of one session; `hosts`: accepted Host headers ("127.0.0.1:8765", ...)."""

    async def payload(request: Request) -> tuple[Edits, dict, dict]:
        try:
            data = json.loads(await request.body() or b"{}")
        except (json.JSONDecodeError, UnicodeDecodeError):
            raise InputError("the request body is not JSON") from None
        except RecursionError:
            raise InputError("the request body is nested too deeply") from None
        if not isinstance(data, dict):
            raise InputError("the request body must be a JSON object")
        edits = edits_from_dict(data["edits"]) if data.get("edits") is not None else Edits()
        return edits, data.get("options") or {}, data

    def api(handler):
        async def endpoint(request: Request):
            try:
                return await handler(request)
            except OnestrokeError as error:
                return _error(error)
            except Exception as error:  # noqa: BLE001 - the page shows one line, never a bare "500"
                return JSONResponse({"error": f"internal error: {type(error).__name__}: {error}"}, status_code=500)
            finally:
                if request.method == "POST":  # the requests that make G-code, stitches or a state
                    release_memory()
        return endpoint

    async def index(request: Request):
        response = Response(_static("index.html"), media_type="text/html")
        response.set_cookie(cookie_name(token), token, httponly=True, samesite="strict")
        response.headers["Cache-Control"] = "no-store"
        return response

    async def static(request: Request):
        name = request.path_params["name"]
        if name in PLAYER:
            from fabrication.player import asset_text

            return Response(asset_text(name), media_type=PLAYER[name])
        if name not in STATIC:
            return PlainTextResponse("not found", status_code=404)
        return Response(_static(name), media_type=STATIC[name])

    async def image(request: Request):
        path = session.drawing_path
        kind = IMAGE_TYPES.get(path.suffix.lower())
        if kind is not None:
            return Response(path.read_bytes(), media_type=kind)
        from io import BytesIO

        from PIL import Image

        buffer = BytesIO()
        with Image.open(path) as picture:
            picture.convert("RGBA").save(buffer, format="PNG")
        return Response(buffer.getvalue(), media_type="image/png")

    async def mask(request: Request):
        from onestroke.units import parse_number

        query = request.query_params
        threshold = query.get("threshold", "auto")
        threshold = None if threshold == "auto" else parse_number(threshold, what="--threshold")
        blur = parse_number(query.get("blur", "0"), what="--blur")
        return Response(await run_in_threadpool(session.mask, threshold, blur), media_type="image/png")

    async def state(request: Request):
        if request.method == "GET":
            return JSONResponse(await run_in_threadpool(session.state, session.saved_edits()))
        edits, _, data = await payload(request)
        superseded = session.ticket(str(data["page"])) if data.get("page") else None
        try:
            return JSONResponse(await run_in_threadpool(session.state, edits, superseded=superseded))
        except Superseded:
            # The page sent a newer state request meanwhile and ignores this answer.
            return JSONResponse({"superseded": True})

    async def embroidery(request: Request):
        edits, options, _ = await payload(request)
        return JSONResponse(await run_in_threadpool(session.embroidery_preview, edits, options))

    async def laser(request: Request):
        edits, options, _ = await payload(request)
        return JSONResponse(await run_in_threadpool(session.laser_preview, edits, options))

    async def export(request: Request):
        edits, options, _ = await payload(request)
        name, media, data = await run_in_threadpool(session.export, request.path_params["kind"], edits, options)
        return Response(data, media_type=media, headers={"Content-Disposition": f'attachment; filename="{name}"'})

    async def save_edits(request: Request):
        _, _, data = await payload(request)
        edits = await run_in_threadpool(session.save_edits, data.get("edits") or {})
        return JSONResponse({"saved": str(session.edits_path), "edits": edits.to_dict()})

    async def load_edits(request: Request):
        return JSONResponse({"path": str(session.edits_path), "exists": session.edits_path.is_file(),
                             "edits": session.saved_edits().to_dict()})

    async def send(request: Request):
        from fabrication.studio.sender import LaserSender
        from machines.stream_types import parse_baud

        if request.method == "GET":
            return JSONResponse(session.sender.status() if session.sender else {"state": "idle"})
        edits, options, data = await payload(request)
        if session.sender is not None and session.sender.running:
            raise InputError("a job is already being sent; abort it first")
        port = checked_port(str(data.get("port") or ""))
        # the CLI's grammar and check (a text "115200" as a number; 0 refused, not the default)
        baud = 115200 if data.get("baud") in (None, "") else parse_baud(data["baud"], name="--baud")
        name, _, content = await run_in_threadpool(session.export, "gcode", edits, options)
        session.sender = LaserSender(content.decode(), port=port, baud=baud, name=name).start()
        return JSONResponse(session.sender.status())

    async def profiles(request: Request):
        if request.method == "GET":
            return JSONResponse(session.profile_list())
        _, _, data = await payload(request)  # {"name": file name, "text": its TOML}: parsed, never a path
        return JSONResponse(await run_in_threadpool(session.add_profile, data.get("name") or "", data.get("text")))

    async def ports(request: Request):
        from machines.ports import list_ports

        found = await run_in_threadpool(list_ports, probe=False)
        return JSONResponse({"ports": [{"device": "sim://", "description": "GRBL emulator (dry run)"}] +
                             [{"device": p.device, "description": p.description, "problem": p.problem}
                              for p in found]})

    async def control(request: Request):
        action = request.path_params["action"]
        if session.sender is None or action not in ("pause", "resume", "abort"):
            raise InputError(f"nothing to {action}")
        await run_in_threadpool(getattr(session.sender, action))
        return JSONResponse(session.sender.status())

    routes = [
        Route("/", index),
        Route("/static/{name}", static),
        Route("/api/image", image),
        Route("/api/mask", api(mask), methods=["GET"]),
        Route("/api/state", api(state), methods=["GET", "POST"]),
        Route("/api/embroidery", api(embroidery), methods=["POST"]),
        Route("/api/laser", api(laser), methods=["POST"]),
        Route("/api/export/{kind}", api(export), methods=["POST"]),
        Route("/api/edits", api(load_edits), methods=["GET"]),
        Route("/api/edits", api(save_edits), methods=["POST"]),
        Route("/api/send", api(send), methods=["GET", "POST"]),
        Route("/api/send/{action}", api(control), methods=["POST"]),
        Route("/api/ports", api(ports), methods=["GET"]),
        Route("/api/profiles", api(profiles), methods=["GET", "POST"]),
    ]
    return Guard(Starlette(routes=routes), token=token, hosts=hosts)

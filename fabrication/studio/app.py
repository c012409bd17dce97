"""The studio's web app (Starlette): the page, its static files and a small JSON API.

Security: the server binds 127.0.0.1 only (see `serve`); every request must carry the
session's random token (in the URL of the first load, then a SameSite cookie or the
X-Studio-Token header) and a Host header naming this server, so neither another page
in the browser nor another user on the machine can drive it; request bodies are
bounded; files are read and written only where the command line said (the drawing, its
edits file, a laser profile); a profile the user loads in the page arrives as text and is
parsed in memory; downloads are made in memory.
"""

from __future__ import annotations

import hashlib
import json
import re
import secrets
from importlib import resources

from starlette.applications import Starlette
from starlette.concurrency import run_in_threadpool
from starlette.requests import Request
from starlette.responses import JSONResponse, PlainTextResponse, Response
from starlette.routing import Route

from fabrication.studio.session import StudioSession, Superseded
from onestroke.errors import InputError, OnestrokeError
from vectorize.edits import Edits, edits_from_dict

MAX_BODY = 1 << 20  # 1 MiB: an edits list and option values are a few kB
COOKIE = "onestroke_studio"  # + a digest of the token: cookies ignore ports, two studios must not mix


def cookie_name(token: str) -> str:
    return f"{COOKIE}_{hashlib.sha256(token.encode()).hexdigest()[:10]}"
STATIC = {"app.js": "text/javascript", "api.js": "text/javascript", "panels.js": "text/javascript",
          "view.js": "text/javascript", "marks.js": "text/javascript", "edits.js": "text/javascript",
          "hint.js": "text/javascript", "tools.js": "text/javascript",
          "style.css": "text/css", "index.html": "text/html"}
# The toolpath player's files, served from its own package (`fabrication.player`).
PLAYER = {"player.js": "text/javascript", "player.css": "text/css"}
IMAGE_TYPES = {".png": "image/png", ".jpg": "image/jpeg", ".jpeg": "image/jpeg", ".svg": "image/svg+xml",
               ".gif": "image/gif", ".webp": "image/webp"}


def _static(name: str) -> bytes:
    return resources.files("fabrication.studio").joinpath("static", name).read_bytes()


class Guard:
    """ASGI middleware: Host header, token and body size checked before any route runs."""

    def __init__(self, app, *, token: str, hosts: set[str]) -> None:
        self.app, self.token, self.hosts = app, token, hosts

    def _allowed(self, scope) -> tuple[bool, bool]:
        headers = {k.decode("latin-1").lower(): v.decode("latin-1") for k, v in scope["headers"]}
        if headers.get("host", "") not in self.hosts:
            return False, False
        query = dict(pair.split("=", 1) for pair in scope.get("query_string", b"").decode().split("&") if "=" in pair)
        cookies = {}
        for part in headers.get("cookie", "").split(";"):
            if "=" in part:
                key, value = part.strip().split("=", 1)
                cookies[key] = value
        offered = [query.get("token", ""), headers.get("x-studio-token", ""), cookies.get(cookie_name(self.token), "")]
        by_url = secrets.compare_digest(offered[0].encode(), self.token.encode())
        return any(secrets.compare_digest(o.encode(), self.token.encode()) for o in offered), by_url

    async def __call__(self, scope, receive, send):
        if scope["type"] != "http":
            return await self.app(scope, receive, send)
        ok, _ = self._allowed(scope)
        if not ok:
            return await PlainTextResponse("forbidden", status_code=403)(scope, receive, send)
        headers = dict(scope["headers"])
        length = headers.get(b"content-length")
        if length is not None and (not length.isdigit() or int(length) > MAX_BODY):
            return await PlainTextResponse("request too large", status_code=413)(scope, receive, send)
        seen = 0

        async def bounded():
            nonlocal seen
            message = await receive()
            seen += len(message.get("body", b""))
            if seen > MAX_BODY:
                raise InputError("request too large")
            return message

        return await self.app(scope, bounded, send)


def _checked_port(port: str) -> str:
    """A serial device or the emulator; never another pyserial URL (socket://, rfc2217://
    reach the network) nor an emulator reading a file the command line did not name."""
    if port.startswith("sim://") and "profile" not in port:
        return port
    if re.fullmatch(r"/dev/[A-Za-z0-9._/-]+|COM[0-9]+", port) and ".." not in port:
        return port
    raise InputError(f"port {port!r}: give a serial device (/dev/ttyUSB0, COM3) or sim:// for a dry run")


def _error(error: Exception) -> JSONResponse:
    status = 400 if isinstance(error, InputError) else 500
    return JSONResponse({"error": str(error)}, status_code=status)


def create_app(session: StudioSession, *, token: str, hosts: set[str]) -> Guard:
    """The ASGI app of one session; `hosts`: accepted Host headers ("127.0.0.1:8765", ...)."""

    async def payload(request: Request) -> tuple[Edits, dict, dict]:
        try:
            data = json.loads(await request.body() or b"{}")
        except (json.JSONDecodeError, UnicodeDecodeError):
            raise InputError("the request body is not JSON") from None
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

        if request.method == "GET":
            return JSONResponse(session.sender.status() if session.sender else {"state": "idle"})
        edits, options, data = await payload(request)
        if session.sender is not None and session.sender.running:
            raise InputError("a job is already being sent; abort it first")
        port = _checked_port(str(data.get("port") or ""))
        try:
            baud = int(data.get("baud") or 115200)
        except (TypeError, ValueError):
            raise InputError(f"baud rate {data.get('baud')!r} is not a whole number") from None
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

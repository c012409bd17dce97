"""Running the studio: uvicorn on 127.0.0.1, a fresh token, the URL to open."""

from __future__ import annotations

import secrets
import socket
import threading

import uvicorn

from fabrication.studio.app import create_app
from fabrication.studio.session import StudioSession

HOST = "127.0.0.1"  # never another interface: the page drives files and a laser


class StudioServer:
    """A running studio. `url` carries the token; `stop()` shuts it down."""

    def __init__(self, session: StudioSession, *, port: int = 0) -> None:
        # The socket is bound here, before any other work, and handed to uvicorn: a port in
        # use is one line at once (uvicorn would log its own error, after the vectorization),
        # and port 0's free port cannot be taken by someone else in between.
        from onestroke.errors import InputError

        self.socket = socket.socket()
        self.socket.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)  # as uvicorn's own: a restart may reuse it
        try:
            self.socket.bind((HOST, port))
        except OSError as error:
            self.socket.close()
            raise InputError(f"--port {port}: cannot listen on {HOST}:{port} ({error.strerror or error}); "
                             "choose another port, or 0 for any free one") from None
        port = self.socket.getsockname()[1]
        self.port = port
        self.token = secrets.token_urlsafe(24)
        hosts = {f"{HOST}:{port}", f"localhost:{port}"}
        self.app = create_app(session, token=self.token, hosts=hosts)
        config = uvicorn.Config(self.app, host=HOST, port=port, log_level="warning", access_log=False,
                                lifespan="off")
        self.server = uvicorn.Server(config)
        self.thread = threading.Thread(target=self.server.run, kwargs={"sockets": [self.socket]},
                                       name="studio-server", daemon=True)

    @property
    def url(self) -> str:
        return f"http://{HOST}:{self.port}/?token={self.token}"

    def start(self, timeout: float = 10.0) -> "StudioServer":
        self.thread.start()
        for _ in range(int(timeout / 0.02)):
            if self.server.started or not self.thread.is_alive():
                break
            self.thread.join(0.02)
        if not self.server.started:
            from onestroke.errors import OnestrokeError

            raise OnestrokeError(f"the studio could not listen on {HOST}:{self.port} (port in use?)")
        return self

    def stop(self) -> None:
        self.server.should_exit = True
        self.thread.join(5.0)

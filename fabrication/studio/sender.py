""""Send to laser": stream a G-code program over a port in a background thread, with the
state, progress, pause/resume and abort the page polls and drives. The protocol is
`machines.streamer.GrblStreamer`'s; nothing of GRBL is done here."""

from __future__ import annotations

import threading
import time

from machines.gcode_program import program_from_text
from machines.ports import open_port
from machines.streamer import GrblStreamer, StreamProgress
from onestroke.errors import OnestrokeError


ACTIVE = ("connecting", "streaming", "paused", "aborting")


class LaserSender:
    """One job to one port. `status()` is a plain dict for the page."""

    def __init__(self, text: str, *, port: str, baud: int = 115200, name: str = "job") -> None:
        self.program = program_from_text(text, source=name)
        self.port, self.baud = port, baud
        self.state = "connecting"
        self.message = ""
        self.progress: StreamProgress | None = None
        self.started = time.monotonic()
        self._streamer: GrblStreamer | None = None
        self._before = None  # the status report from before the stream: not the machine's state in it
        self._abort = threading.Event()  # asked for at any time, also while connecting
        self._thread = threading.Thread(target=self._run, name="studio-send", daemon=True)

    def start(self) -> "LaserSender":
        self._thread.start()
        return self

    def _run(self) -> None:
        # The final state is set only once the port is closed: a "done" job can be sent
        # again at once.
        state, message = "failed", ""
        try:
            handle = open_port(self.port, baud=self.baud)
            with GrblStreamer(handle, name=self.port) as streamer:
                self._streamer = streamer
                info = streamer.connect()
                if info.alarm:
                    raise OnestrokeError(f"{self.port} is locked in ALARM: home it ($H) or unlock it ($X) first")
                if self._abort.is_set():
                    state, message = "aborted", "stopped before the first line was sent"
                else:
                    self._before = streamer.status
                    self.state = "streaming"
                    result = streamer.stream(self.program, on_progress=self._on_progress)
                    state, message = "done", f"{result.lines} lines in {result.elapsed:.1f} s"
        except OnestrokeError as error:
            state, message = ("aborted" if self._abort.is_set() else "failed"), str(error)
        except Exception as error:  # noqa: BLE001 - a thread has no caller: the page shows it
            state, message = "failed", f"{type(error).__name__}: {error}"
        finally:
            self._streamer = None
            self.state, self.message = state, message

    def _on_progress(self, progress: StreamProgress) -> None:
        self.progress = progress
        if self._abort.is_set() and self._streamer is not None:
            # An abort that came as the stream started (which clears the streamer's own
            # flag) is passed on again at the next acknowledged line.
            self._streamer.abort()

    def pause(self) -> None:
        if self._streamer is not None and self.state == "streaming" and not self._abort.is_set():
            self._streamer.pause()
            self.state = "paused"

    def resume(self) -> None:
        if self._streamer is not None and self.state == "paused":
            self._streamer.resume()
            self.state = "streaming"

    def abort(self) -> None:
        """Stop the job safely (hold, reset: beam off); while connecting, before any line."""
        if self.state in ("streaming", "paused", "connecting"):
            self._abort.set()
            self.state = "aborting"
            streamer = self._streamer
            if streamer is not None:
                streamer.abort()

    @property
    def running(self) -> bool:
        """True until the job ended and its port is closed."""
        return self.state in ACTIVE

    def wait(self, timeout: float) -> None:
        self._thread.join(timeout)

    def status(self) -> dict:
        """State, progress and the machine's own latest status report (e.g. "Hold:0"
        while paused: no line is acknowledged during a hold, so the last progress report
        would still say "Run")."""
        p = self.progress
        streamer = self._streamer
        report = streamer.status if streamer is not None else None
        if report is not None and report is self._before:
            machine = None  # connect's "Idle": no report since the stream started
        else:
            machine = report.full_state if report is not None else (p.state if p else None)
        return {"state": self.state, "message": self.message, "port": self.port,
                "acked": p.acked if p else 0, "total": p.total if p else len(self.program),
                "elapsed": round(p.elapsed, 2) if p else 0.0, "machine": machine,
                "line": p.last_line if p else 0}

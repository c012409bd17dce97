"""Connecting to GRBL: soft reset and welcome, or attaching without a reset (status
first, refusing a busy controller); `$I`, `$$`, `$#` and the position; send-response
commands. A mixin of `GrblStreamer` (the reply queue and threads live there)."""

from __future__ import annotations

import queue
import time

import serial

from machines.grbl_codes import describe_alarm, describe_error
from machines.grbl_protocol import (SOFT_RESET, Alarm, ErrorReply, Message, Ok, Reply, Setting, Unknown, Welcome,
                                    parse_options)
from machines.stream_types import Disconnected, MachineInfo
from onestroke.errors import MachineError


class StreamConnect:
    """connect / attach and send-response commands of `GrblStreamer`."""

    def connect(self, *, reset: bool = True) -> MachineInfo:
        """Soft-reset, wait for the welcome, then read `$I`, `$$`, `$#` and the position.

        reset: False attaches without resetting (a reset would kill a job another program
        started): it asks for a status first and refuses a controller that is busy
        (Run, Hold, Jog, Home, Door) - streaming into a running job would mix two jobs.
        """
        try:
            self.port.reset_input_buffer()
        except (serial.SerialException, OSError):
            pass
        self._drain_replies()
        if reset:
            version = self._reset_and_greet()
        else:
            version = self._attach()
        for reply in self._optional("$I"):  # without [OPT:...] the GRBL 1.1 sizes hold
            if isinstance(reply, Message) and reply.kind == "OPT":
                self.planner_blocks, self.rx_buffer = parse_options(reply.text)
            elif isinstance(reply, Message) and reply.kind == "VER" and version is None:
                version = reply.text.split(":")[0].rsplit(".", 1)[0]
        settings = {r.number: r.value for r in self._collect("$$") if isinstance(r, Setting)}
        offsets = {}
        for reply in self._optional("$#"):
            if isinstance(reply, Message) and reply.kind.startswith("G") and reply.kind[1:3].isdigit():
                try:
                    offsets[reply.kind] = tuple(float(v) for v in reply.text.split(":")[0].split(","))
                except ValueError:
                    pass
        status = self.wait_status(lambda s: True, timeout=2.0)
        position = (0.0, 0.0, 0.0)
        if status is not None and status.mpos is not None:
            position = status.mpos
        elif status is not None and status.wpos is not None:
            wco = offsets.get("G54", (0.0, 0.0, 0.0))
            position = tuple(w + o for w, o in zip(status.wpos, wco))
        alarm = self._alarm_locked or (status is not None and status.state == "Alarm")
        return MachineInfo(version or "1.1", self.rx_buffer, self.planner_blocks, settings, offsets,
                           tuple(position), alarm)

    def _reset_and_greet(self) -> str:
        """Soft reset and the welcome that answers it; returns the firmware version."""
        self._write(SOFT_RESET)
        welcome = self._wait_welcome(self.options.connect_timeout)
        if welcome is None:
            raise MachineError(
                f"no answer from {self.name} within {self.options.connect_timeout:g} s: not a GRBL board, "
                "wrong baud rate (--baud), or still booting; check the cable and 'onestroke ports'; "
                "nothing was sent, no line was acknowledged")
        # A board that reboots when the port opens may greet twice (its boot, then our
        # reset); a reset arriving after the next command would swallow it, so wait it out.
        while (again := self._wait_welcome(0.3)) is not None:
            welcome = again
        if welcome.version.startswith("0."):
            raise MachineError(f"{self.name} runs GRBL {welcome.version}; onestroke speaks GRBL 1.1 (status "
                               "reports and real-time commands differ): update the firmware to 1.1")
        return welcome.version

    def _attach(self) -> str | None:
        """Attach without a reset: status first; refuse a controller that is busy."""
        status = self.wait_status(lambda s: True, self.options.connect_timeout)
        if status is None:
            raise MachineError(
                f"no status from {self.name} within {self.options.connect_timeout:g} s (attaching without a "
                "reset): not a GRBL 1.1 board, wrong baud rate (--baud), or still booting; nothing was sent")
        if status.state in ("Run", "Hold", "Jog", "Home", "Door"):
            raise MachineError(
                f"{self.name} is busy ({status.full_state}): another program's job is running; onestroke does not "
                "stream into a running job - wait for it to end (or stop it there), then run again")
        self._drain_replies()
        return None

    def _optional(self, line: str) -> list[Reply]:
        """Replies to an informational command, or none if this firmware refuses it."""
        try:
            return self._collect(line)
        except MachineError as error:
            if "refused" not in str(error):
                raise
            return []

    def _drain_replies(self) -> list[Reply]:
        drained = []
        while True:
            try:
                drained.append(self._replies.get_nowait())
            except queue.Empty:
                return drained

    def _wait_welcome(self, timeout: float) -> Welcome | None:
        deadline = time.monotonic() + timeout
        while (left := deadline - time.monotonic()) > 0:
            reply = self._next_reply(min(left, 0.1))
            if isinstance(reply, Disconnected):
                raise MachineError(f"lost the connection to {self.name}: {reply.error}")
            if isinstance(reply, Welcome):
                return reply
        return None

    def _collect(self, line: str, timeout: float = 5.0) -> list[Reply]:
        """Send-response: send `line`, return the replies up to its `ok`; raise on `error:N`."""
        self._write(line.encode("ascii") + b"\n")
        replies: list[Reply] = []
        deadline = time.monotonic() + timeout
        while (left := deadline - time.monotonic()) > 0:
            reply = self._next_reply(min(left, 0.1))
            if reply is None or isinstance(reply, Unknown):
                continue
            if isinstance(reply, Disconnected):
                raise MachineError(f"lost the connection to {self.name}: {reply.error}")
            if isinstance(reply, Ok):
                return replies
            if isinstance(reply, ErrorReply):
                raise MachineError(f"GRBL refused {line!r}: {describe_error(reply.code)}")
            if isinstance(reply, Alarm):
                raise MachineError(f"{describe_alarm(reply.code)} (while sending {line!r})")
            replies.append(reply)
        raise MachineError(f"no answer to {line!r} from {self.name} within {timeout:g} s")

    def command(self, line: str, timeout: float = 5.0) -> list[Reply]:
        """Send one line and wait for its answer (for `$` commands and EEPROM writes)."""
        return self._collect(line, timeout)

"""When the host's bytes reach the emulated machine, in machine time: the wire and the
ideal host.

Every line from the host gets a machine send time: the earliest moment a host that reacts
at once could have sent it, knowing what it knew. A host that pipelines (it once sent a
line while an earlier one was unanswered) is taken for a character-counting host: a line
goes out once the answers that reached it free room for the whole line in GRBL's RX
buffer (`rx_buffer`, 128 bytes), and an EEPROM writer (`$x=`, `G10 L2`, ...) goes out
alone: after every earlier answer, and nothing after it before its own answer (grbl.md).
A host that never pipelines is a send-response host: each line after the previous
answer. A host that sent earlier than that (it ignored the buffer or the EEPROM rule) is
taken at its word: the line goes out when the newest reply it could have read reached
it. Then the line travels after the USB latency at 10 bits a byte (`baud`), behind the
bytes before it; its bytes enter the RX buffer as the clock reaches their arrival (at
once if the clock is past it: a host computer that was slow to send costs nothing),
dropped when the buffer is full or an EEPROM write is under way, as on the firmware.

So a busy host computer costs no machine time: the clock waits for it (`emulator_clock`).
The job-time estimate models the same host analytically (`job_time.link_schedule`); this
model works byte by byte and answer by answer, on what actually crossed the pty.
Real-time bytes act at once and take no wire time. A mixin of `GrblEmulator`.
"""

from __future__ import annotations

import bisect
import math
from collections import deque

from machines.grbl_protocol import clean_line, is_eeprom_writer

BITS_PER_BYTE = 10  # 8-N-1


class EmulatorHost:
    """Machine send and arrival times of the host's lines, and the RX buffer's input."""

    def _init_host(self) -> None:
        self._wire: deque[tuple[float, bytes]] = deque()  # (clock of the last byte's arrival, line)
        self._wire_free = 0.0  # clock when the wire is free again
        self._rx_cum = 0  # bytes of the host's complete lines so far
        self._ack_cum = [0]  # bytes of answered lines, after each answer ...
        self._ack_at = [-math.inf]  # ... and the clock when that answer reached the host
        self._answering = 0  # bytes of the line being handled (its answer frees them)
        self._acked_written = 0  # _ack_cum of the newest answer written to the pty
        self._written_due = -math.inf  # clock at which the newest written reply reaches the host
        self._host_pipelines = False
        self._host_sent = -math.inf  # machine send time of the host's last line
        self._last_eeprom = False  # the host's last line writes EEPROM
        self._eeprom_window = (math.inf, -math.inf)  # clock interval of the running EEPROM write
        self._job_start: float | None = None
        self._mark_pending = False
        self._last_ok = 0.0  # clock when the newest `ok` reaches the host

    @property
    def _byte_time(self) -> float:
        return BITS_PER_BYTE / self.options.baud / self.scale

    def mark_job_start(self) -> None:
        """Time a job: it starts when the host sends its next line (see `EmulatorStats.job_time`)."""
        with self._cond:
            self._job_start, self._mark_pending = None, True

    def _ack_time(self, cum: int) -> float:
        """Clock when answers freeing `cum` bytes had reached the host (inf: not yet)."""
        index = bisect.bisect_left(self._ack_cum, cum)
        return self._ack_at[index] if index < len(self._ack_at) else math.inf

    def _record_answer(self, due: float, *, all_lines: bool = False) -> int:
        """An `ok` / `error:N` (or, all_lines, a welcome: buffers gone) leaves for the host."""
        if all_lines:
            cum = self._rx_cum
        elif self._answering:
            cum = self._ack_cum[-1] + self._answering
            self._answering = 0
        else:
            return -1
        self._ack_cum.append(cum)
        self._ack_at.append(due)
        return cum

    def _ideal_send(self, size: int, eeprom: bool) -> float:
        """When the ideal host could send the next line of `size` bytes (lock held)."""
        if not self._host_pipelines:
            return self._ack_time(self._rx_cum)
        t = self._ack_time(self._rx_cum + size - self.options.rx_buffer)
        if eeprom or self._last_eeprom:
            t = max(t, self._ack_time(self._rx_cum))
        return t

    def _host_bound(self) -> float:
        """The earliest clock at which a line the host has not sent yet could arrive (behind
        the bytes already on the wire)."""
        send = max(self._ideal_send(1, False), self._host_sent) + self.options.usb_latency / self.scale
        return max(send, self._wire_free) + self._byte_time

    def _line_from_host(self, data: bytes, pipelined: bool, known: float) -> None:
        """A complete line arrived on the pty (lock held). pipelined: an earlier line was
        still unanswered when its first byte came; known: the clock at which the newest
        reply written before then reached the host."""
        self._host_pipelines = self._host_pipelines or pipelined
        eeprom = is_eeprom_writer(clean_line(data.decode("latin-1")))
        send = max(min(self._ideal_send(len(data), eeprom), known), self._host_sent)
        self._host_sent = send
        latency = self.options.usb_latency / self.scale
        start = max(send + latency, self._wire_free)
        if self._host_quiet:  # the machine ran on without this host: its line starts now
            start = max(start, self._clock)
        end = start + len(data) * self._byte_time
        self._wire_free = end
        self._wire.append((end, data))
        self._rx_cum += len(data)
        self._last_eeprom = eeprom
        self._host_quiet = False
        if self._mark_pending:
            self._job_start, self._mark_pending = start - latency, False

    def _deliver_due(self) -> None:
        """(lock held) Bytes whose arrival the clock has reached enter the RX buffer."""
        byte_time = self._byte_time
        rx_size = self.options.rx_buffer
        eeprom_from, eeprom_until = self._eeprom_window
        while self._wire and self._wire[0][0] <= self._clock:
            end, data = self._wire.popleft()
            last = len(data) - 1
            for index, byte in enumerate(data):
                if eeprom_from <= end - (last - index) * byte_time < eeprom_until:
                    self.eeprom_lost += 1  # interrupts are off while EEPROM is written
                elif len(self.rx) >= rx_size:
                    self.rx_overflow += 1  # the firmware drops the byte silently
                else:
                    self.rx.append(byte)
            self.max_rx = max(self.max_rx, len(self.rx))

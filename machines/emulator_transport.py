"""The emulator's transport: a pseudo-terminal, its reader and writer threads.

The reader acts on real-time bytes at once (at the machine time matching the wall time
they came) and hands complete lines to `emulator_host`, which times their way over the
wire into the 128-byte RX buffer. Replies go out at the wire rate after the USB latency,
on the machine clock; the writer thread puts them on the pty when wall time reaches
them (`emulator_clock`). A mixin of `GrblEmulator`: the state it uses is created there.
"""

from __future__ import annotations

import errno
import os
import select
import threading
import time
import tty


class EmulatorTransport:
    """pty, reader (the serial interrupt) and writer threads of `GrblEmulator`."""

    def start_pty(self) -> str:
        """Open a pseudo-terminal, serve GRBL on it, and return the device path for the host."""
        master, slave = os.openpty()
        tty.setraw(slave)  # no echo, no line editing: a plain byte pipe like a UART
        self._slave_fd = slave
        self.device = os.ttyname(slave)
        self.attach(master)
        return self.device

    def attach(self, fd: int) -> None:
        """Serve GRBL on an already open file descriptor (threads start now)."""
        os.set_blocking(fd, False)
        self._fd = fd
        for target, name in ((self._reader_loop, "rx"), (self._protocol_loop, "protocol"),
                             (self._motion_loop, "motion"), (self._writer_loop, "tx"), (self._clock_loop, "clock")):
            thread = threading.Thread(target=target, name=f"grbl-emu-{name}", daemon=True)
            self._threads.append(thread)
            thread.start()

    def stop(self) -> None:
        """Stop the threads and close the pty."""
        with self._cond:
            self._stopping = True
            self._wake_all()
        with self._out_cond:
            self._out_cond.notify_all()
        for thread in self._threads:
            if thread is not threading.current_thread():
                thread.join(timeout=2.0)
        self._close_fds()

    def _close_fds(self) -> None:
        """Close both ends of the pty (once; later calls do nothing)."""
        for fd in (self._fd, self._slave_fd):
            if fd is not None:
                try:
                    os.close(fd)
                except OSError:
                    pass
        self._fd = self._slave_fd = None

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.stop()

    def _send(self, text: str | bytes, *, answer: bool = False, welcome: bool = False) -> None:
        """Queue bytes for the host (lock held or not); they reach it after the USB latency
        and their wire time, on the machine clock. answer: an `ok` / `error:N` that frees
        its line's bytes; welcome: a (re)boot that empties every buffer."""
        if self.options.faults.silent or self._fd is None:
            return
        data = text.encode("ascii") if isinstance(text, str) else text
        with self._cond, self._out_cond:  # (_cond is reentrant; always taken before _out_cond)
            start = max(self._now() + self.options.usb_latency / self.scale, self._out_free)
            self._out_free = start + len(data) * self._byte_time
            cum = self._record_answer(self._out_free, all_lines=welcome) if answer or welcome else -1
            self._outbox.append((self._out_free, data, cum))
            self._out_cond.notify()

    def _writer_loop(self) -> None:
        # Paced in wall time: a reply due at clock t goes out at wall time offset + t.
        while True:
            with self._out_cond:
                while not self._outbox and not self._stopping:
                    self._out_cond.wait(0.05)
                if self._stopping and not self._outbox:
                    return
                due, data, cum = self._outbox[0]
                wait = self._offset + due - time.monotonic()
                if wait > 0:
                    self._out_cond.wait(min(wait, 0.05))
                    continue
                self._outbox.popleft()
                # before the write: a host may answer before this thread runs again
                self._written_due = due
                if cum >= 0:
                    self._acked_written = cum
            with self._write_lock:
                while data and self._fd is not None:
                    try:
                        data = data[os.write(self._fd, data):]
                    except BlockingIOError:
                        time.sleep(0.001)  # host not reading yet: the pty holds 4 KB, wait
                    except (OSError, TypeError):
                        break

    def _reply(self, line: str) -> None:
        answer = line == "ok" or line.startswith("error:")
        self._send(line + "\r\n", answer=answer)
        if line == "ok":
            self._last_ok = self._out_free

    def _reader_loop(self) -> None:
        partial = bytearray()
        pipelined, known = False, 0.0
        while not self._stopping and self._fd is not None:
            fd = self._fd
            if fd is None:
                return
            try:
                ready, _, _ = select.select([fd], [], [], 0.05)
            except (OSError, ValueError, TypeError):
                return
            if not ready:
                continue
            try:
                data = os.read(fd, 4096)
            except BlockingIOError:
                continue
            except (TypeError, ValueError):
                return
            except OSError as error:
                if error.errno == errno.EIO:  # no host has the port open
                    time.sleep(0.01)
                    continue
                return
            with self._cond:
                self._sync_to_wall("line")  # an idle machine's clock runs with wall time
                lines = 0
                for byte in data:
                    if byte in (0x18, 0x3F, 0x7E, 0x21) or byte >= 0x80:
                        self._sync_to_wall("query" if byte == 0x3F else "control")
                        self._realtime(byte)
                        continue
                    if not partial:  # what the host knew when it began this line
                        pipelined = self._rx_cum > self._acked_written
                        known = self._written_due
                    partial.append(byte)
                    if byte in (0x0A, 0x0D):
                        self._line_from_host(bytes(partial), pipelined, known)
                        partial.clear()
                        lines += 1
                if lines:
                    self._wake_all()

    def _unplug(self) -> None:
        """The USB cable is pulled: the board loses power (beam off) and the port vanishes."""
        with self._cond:
            self.planner.clear()
            self.spindle_mode, self.spindle_s = "M5", 0.0
            self.spindle_history.append(("M5", 0.0))
            self.disconnected = True
            self._stopping = True
            self._wake_all()
        with self._write_lock:
            self._close_fds()

"""The emulator's transport: a pseudo-terminal, the wire and the serial interrupt.

Bytes from the host arrive at the wire rate (10 bits a byte at `baud`, after the USB
adapter's latency); the interrupt routine picks out real-time bytes and puts the rest into
the 128-byte RX buffer, DROPPING what does not fit, as GRBL's serial.c does. Replies go
out through a writer thread at the wire rate too. A mixin of `GrblEmulator`: the state it
uses is created there.
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
                             (self._motion_loop, "motion"), (self._writer_loop, "tx")):
            thread = threading.Thread(target=target, name=f"grbl-emu-{name}", daemon=True)
            self._threads.append(thread)
            thread.start()

    def stop(self) -> None:
        """Stop the threads and close the pty."""
        with self._cond:
            self._stopping = True
            self._cond.notify_all()
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

    def _send(self, text: str | bytes) -> None:
        """Queue bytes for the host; they arrive after the USB latency and their wire time."""
        if self.options.faults.silent or self._fd is None:
            return
        data = text.encode("ascii") if isinstance(text, str) else text
        byte_time = 10.0 / self.options.baud / self.scale
        with self._out_cond:
            start = max(time.monotonic() + self.options.usb_latency / self.scale, self._out_free)
            self._out_free = start + len(data) * byte_time
            self._outbox.append((self._out_free, data))
            self._out_cond.notify()

    def _writer_loop(self) -> None:
        while True:
            with self._out_cond:
                while not self._outbox and not self._stopping:
                    self._out_cond.wait(0.05)
                if self._stopping and not self._outbox:
                    return
                due, data = self._outbox[0]
                wait = due - time.monotonic()
                if wait > 0:
                    self._out_cond.wait(wait)
                    continue
                self._outbox.popleft()
            with self._write_lock:
                while data and self._fd is not None:
                    try:
                        data = data[os.write(self._fd, data):]
                    except BlockingIOError:
                        time.sleep(0.001)  # host not reading yet: the pty holds 4 KB, wait
                    except (OSError, TypeError):
                        break

    def _reply(self, line: str) -> None:
        self._send(line + "\r\n")

    def _reader_loop(self) -> None:
        byte_time = 10.0 / self.options.baud / self.scale
        pending = bytearray()
        wire_t = 0.0
        while not self._stopping and self._fd is not None:
            now = time.monotonic()
            if pending:
                wait = max(0.0003, min(wire_t + byte_time * min(len(pending), 16) - now, 0.05))
            else:
                wait = 0.05
            fd = self._fd
            if fd is None:
                return
            try:
                ready, _, _ = select.select([fd], [], [], wait)
            except (OSError, ValueError, TypeError):
                return
            if ready:
                try:
                    data = os.read(fd, 4096)
                except BlockingIOError:
                    data = b""
                except (TypeError, ValueError):
                    return
                except OSError as error:
                    if error.errno == errno.EIO:  # no host has the port open
                        time.sleep(0.01)
                        continue
                    return
                if data:
                    if not pending:  # a new burst: the USB adapter delivers it after its latency
                        wire_t = max(wire_t, time.monotonic() + self.options.usb_latency / self.scale)
                    pending += data
            if pending:
                now = time.monotonic()
                count = min(len(pending), int((now - wire_t) / byte_time))
                if count > 0:
                    chunk = bytes(pending[:count])
                    del pending[:count]
                    wire_t += count * byte_time
                    self._deliver(chunk, now)

    def _deliver(self, chunk: bytes, now: float) -> None:
        with self._cond:
            notify = False
            for byte in chunk:
                if byte in (0x18, 0x3F, 0x7E, 0x21) or byte >= 0x80:
                    self._realtime(byte)
                    continue
                if now < self._eeprom_until:
                    self.eeprom_lost += 1  # interrupts are off while EEPROM is written
                elif len(self.rx) >= self.options.rx_buffer:
                    self.rx_overflow += 1  # the firmware drops the byte silently
                else:
                    self.rx.append(byte)
                    if byte in (0x0A, 0x0D):
                        notify = True
            self.max_rx = max(self.max_rx, len(self.rx))
            if notify:
                self._cond.notify_all()

    def _unplug(self) -> None:
        """The USB cable is pulled: the board loses power (beam off) and the port vanishes."""
        with self._cond:
            self.planner.clear()
            self.spindle_mode, self.spindle_s = "M5", 0.0
            self.spindle_history.append(("M5", 0.0))
            self.disconnected = True
            self._stopping = True
            self._cond.notify_all()
        with self._write_lock:
            self._close_fds()

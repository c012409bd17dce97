"""The emulator's protocol: GRBL 1.1h's main loop as a sender sees it.

Real-time bytes (status `?`, hold `!`, resume `~`, reset 0x18, overrides), one line at a
time out of the RX buffer (parse time per line), `$` system commands and settings (EEPROM
writes lose serial input meanwhile), status reports, check mode, soft reset and the
welcome. G-code lines go through `machines.gcode_interpreter` and their actions to the
motion mixin. A mixin of `GrblEmulator`.
"""

from __future__ import annotations

import time

import numpy as np

from machines.gcode_interpreter import GcodeError, MachineConfig
from machines.grbl_protocol import MAX_LINE_CHARS, clean_line
from machines.grbl_settings import INTEGER_SETTINGS
from machines.planner_model import BlockBuilder, Kinematics
from machines.system_commands import system_answer

VERSION = "1.1h"
BUILD_DATE = "20190825"


class Reset(Exception):
    """Raised inside the protocol thread when a soft reset arrived."""


class EmulatorProtocol:
    """Real-time bytes, the line loop, `$` commands and status reports of `GrblEmulator`."""

    def _realtime(self, byte: int) -> None:
        """Handle a real-time byte (called with the lock held)."""
        if byte == 0x18:
            self.reset_times.append(time.monotonic())
            self._reset_was_moving = self._moving()
            self._reset_pending = True
            self._wake_all()
        elif byte == 0x3F:
            self._reply(self._status_report())
        elif byte == 0x21:
            if self._holds_to_drop > 0:
                self._holds_to_drop -= 1  # lost on the way: the firmware never sees it
                return
            self.hold_times.append(time.monotonic())
            if not self.hold and not self.alarm and not self.check_mode:
                self.hold = True
                self.hold_complete = not self._motion_busy
                self._wake_all()
        elif byte == 0x7E:
            if self.hold and self.hold_complete:  # a resume during deceleration is ignored
                self.hold = self.hold_complete = False
                self._wake_all()
            elif self.stalled:
                self.stalled = False
                self._wake_all()
        elif 0x90 <= byte <= 0x94:
            self.feed_ov = {0x90: 100, 0x91: self.feed_ov + 10, 0x92: self.feed_ov - 10,
                            0x93: self.feed_ov + 1, 0x94: self.feed_ov - 1}[byte]
            self.feed_ov = min(200, max(10, self.feed_ov))
        elif 0x95 <= byte <= 0x97:
            self.rapid_ov = {0x95: 100, 0x96: 50, 0x97: 25}[byte]
        elif 0x99 <= byte <= 0x9D:
            self.spindle_ov = {0x99: 100, 0x9A: self.spindle_ov + 10, 0x9B: self.spindle_ov - 10,
                               0x9C: self.spindle_ov + 1, 0x9D: self.spindle_ov - 1}[byte]
            self.spindle_ov = min(200, max(10, self.spindle_ov))
        elif byte == 0xA0:
            self.coolant = self.coolant ^ {"M8"}

    def _status_report(self) -> str:
        pos = self._current_position()
        mask = int(self.settings[10])
        wco = np.array(self.interp.state.coord_systems[self.interp.state.coord_index]) + np.array(
            self.interp.state.g92)
        fields = [self.state]
        if mask & 1:
            fields.append("MPos:" + ",".join(f"{v:.3f}" for v in pos))
        else:
            fields.append("WPos:" + ",".join(f"{v:.3f}" for v in pos - wco))
        if mask & 2:
            fields.append(f"Bf:{self.options.planner_blocks - len(self.planner)},"
                          f"{self.options.rx_buffer - len(self.rx)}")
        feed = 0.0
        if self._current is not None and self._motion_busy:
            planned, profile, t0 = self._current
            feed = profile.speed_at((self._now() - t0) * self.scale) * 60.0
        spindle = self.spindle_s * self.spindle_ov / 100.0 if self.spindle_mode != "M5" else 0.0
        fields.append(f"FS:{feed:.0f},{spindle:.0f}")
        self._status_count += 1
        if self._status_count % 10 == 1:
            fields.append(f"WCO:{wco[0]:.3f},{wco[1]:.3f},{wco[2]:.3f}")
        else:
            fields.append(f"Ov:{self.feed_ov},{self.rapid_ov},{self.spindle_ov}")
        accessories = ("S" if self.spindle_mode == "M3" else "C" if self.spindle_mode == "M4" else "") + (
            "F" if "M8" in self.coolant else "") + ("M" if "M7" in self.coolant else "")
        if accessories:
            fields.append(f"A:{accessories}")
        return "<" + "|".join(fields) + ">"

    def _protocol_loop(self) -> None:
        self._boot_messages()
        busy_until = 0.0
        while not self._stopping:
            try:
                raw = self._next_line()
                if raw is None:
                    return
                # the line costs parse_time on the machine clock, however long Python takes
                with self._cond:
                    busy_until = max(busy_until, self._now()) + self.options.parse_time / self.scale
                    self._wait(lambda: self._now() >= busy_until, until=busy_until)
                    self._answering = len(raw) + 1  # its answer frees these bytes (`emulator_host`)
                self._handle_line(raw)
            except Reset:
                while True:  # a second reset may arrive while handling the first
                    try:
                        self._do_reset()
                        break
                    except Reset:
                        continue
            except OSError:
                return

    def _boot_messages(self) -> None:
        self._send(f"\r\nGrbl {VERSION} ['$' for help]\r\n", welcome=True)
        if self.alarm:
            self._reply("[MSG:'$H'|'$X' to unlock]")

    def _check_reset(self) -> None:
        if self._reset_pending:
            raise Reset()

    def _wait(self, predicate, timeout: float | None = None, *, until: float | None = None) -> bool:
        """Wait (lock held) until predicate() or a reset; raise Reset on reset. timeout (a
        duration) or until (a clock time): give up then (the clock stops there for it)."""
        deadline = until if timeout is None else self._now() + timeout
        while not predicate():
            self._check_reset()
            if self._stopping:
                raise OSError("emulator stopped")
            if deadline is not None and self._now() >= deadline:
                return False
            self._clock_wait(deadline)
        self._check_reset()
        return True

    def _next_line(self) -> bytes | None:
        with self._cond:
            while True:
                self._check_reset()
                if self._stopping:
                    return None
                if not self.critical:
                    for index, byte in enumerate(self.rx):
                        if byte in (0x0A, 0x0D):
                            line = bytes(self.rx[:index])
                            del self.rx[:index + 1]
                            return line
                self._parser_idle = True  # the clock may wait for the host (`emulator_clock`)
                try:
                    self._clock_wait()
                finally:
                    self._parser_idle = False

    def _handle_line(self, raw: bytes) -> None:
        text = clean_line(raw.decode("latin-1"))
        if len(text) > MAX_LINE_CHARS:
            self._reply("error:11")
            return
        if not text:
            self._reply("ok")  # an empty line still gets an answer: why "\r\n" yields two
            return
        if text.startswith("$"):
            self.commands.append(text)
            self._system_command(text)
            return
        if self.alarm:
            self._reply("error:9")
            return
        self.program_lines += 1
        number = self.program_lines
        faults = self.options.faults
        if faults.error_at == number:
            self._reply("error:20")
            return
        if faults.alarm_at == number:
            self._hard_limit()
            return
        try:
            actions = self.interp.execute(text)
        except GcodeError as error:
            self._reply(f"error:{error.code}")
            return
        if not self._run_actions(actions, number):
            return
        with self._cond:
            self.executed.append(text)
            self._wake_all()
        if faults.drop_ok_at != number:
            self._reply("ok")
        if faults.garbage_at == number:
            self._send(b"\xfe\xff\x13o\x8bk\x00 \xe5rr\r\n")
        if faults.stall_at == number:
            with self._cond:
                self._stall_pending = True
        if faults.disconnect_at == number:
            self._unplug()

    def _do_reset(self) -> None:
        with self._cond:
            was_moving = self._reset_was_moving
            # The motion thread drops its block as soon as it sees the pending reset.
            while self._motion_busy and not self._stopping:
                self._clock_wait()
            self.planner.clear()
            self.rx.clear()
            alarm = self.alarm or was_moving
            self.resets += 1
            self._reset_state()
            self._host_pipelines = False  # a new connection: learn the host again
            self.alarm = alarm
            self.spindle_history.append(("M5", 0.0))
            if was_moving:
                self.alarms.append(3)
            self._wake_all()
        if was_moving:
            self._reply("ALARM:3")
        self._boot_messages()

    def _system_command(self, text: str) -> None:
        busy = self.state.startswith(("Run", "Hold"))
        answer = system_answer(text, self.settings, idle=not busy)  # GRBL's error codes, as the pre-check
        if answer.code:
            return self._reply(f"error:{answer.code}")
        if text == "$":
            self._reply("[HLP:$$ $# $G $I $N $x=val $Nx=line $J=line $SLP $C $X $H ~ ! ? ctrl-x]")
        elif text == "$$":
            if busy:
                return self._reply("error:8")
            for number in sorted(self.settings):
                value = self.settings[number]
                shown = f"{int(value)}" if number in INTEGER_SETTINGS else f"{value:.3f}"
                self._reply(f"${number}={shown}")
        elif text == "$I":
            self._reply(f"[VER:{VERSION}.{BUILD_DATE}:]")
            self._reply(f"[OPT:V,{self.options.planner_blocks},{self.options.rx_buffer}]")
        elif text == "$G":
            self._reply(f"[GC:{self.interp.state.modal_report()}]")
        elif text == "$#":
            st = self.interp.state
            for i, system in enumerate(st.coord_systems):
                self._reply(f"[G{54 + i}:" + ",".join(f"{v:.3f}" for v in system) + "]")
            self._reply("[G28:" + ",".join(f"{v:.3f}" for v in st.g28) + "]")
            self._reply("[G30:" + ",".join(f"{v:.3f}" for v in st.g30) + "]")
            self._reply("[G92:" + ",".join(f"{v:.3f}" for v in st.g92) + "]")
            self._reply("[TLO:0.000]")
            self._reply("[PRB:0.000,0.000,0.000:0]")
        elif text == "$N":
            self._reply("$N0=")
            self._reply("$N1=")
        elif text == "$C":
            if busy:
                return self._reply("error:8")
            if self.check_mode:
                self._reply("[MSG:Disabled]")
                self._reply("ok")
                with self._cond:  # leaving check mode soft-resets the machine
                    self._reset_pending = True
                    self._reset_was_moving = False
                raise Reset()
            self.check_mode = True
            self._reply("[MSG:Enabled]")
        elif text == "$X":
            if self.alarm:
                self.alarm = False
                self._reply("[MSG:Caution: Unlocked]")
        elif text == "$H":
            if not self.settings[22]:
                return self._reply("error:5")
            with self._cond:
                self._homing = True
                self._wait(lambda: False, timeout=0.5 / self.scale)
                self.position = np.zeros(3)
                self._homing = False
                self.alarm = False
        elif text.startswith("$N") and "=" in text:
            self._eeprom_write()
        elif text.startswith("$") and "=" in text:
            return self._set_setting(text)
        elif text.startswith("$J="):
            return self._reply("error:20")  # jogging is not emulated
        else:
            return self._reply("error:3")
        self._reply("ok")

    def _set_setting(self, text: str) -> None:
        key, _, value = text[1:].partition("=")
        try:
            number, number_value = int(key), float(value)
        except ValueError:
            return self._reply("error:3" if not key.isdigit() else "error:2")
        if number not in self.settings:
            return self._reply("error:3")
        if number_value < 0:
            return self._reply("error:4")
        if number == 20 and number_value and not self.settings[22]:
            return self._reply("error:10")
        if self.state.startswith(("Run", "Hold")):
            return self._reply("error:8")
        self.settings[number] = number_value
        self._eeprom_write()
        with self._cond:
            self.kin = Kinematics.from_settings(self.settings, planner_blocks=self.options.planner_blocks)
            self.config = MachineConfig(laser_mode=bool(self.settings[32]), soft_limits=bool(self.settings[20]),
                                        max_travel=(self.settings[130], self.settings[131], self.settings[132]),
                                        arc_tolerance=self.settings[12])
            self.interp.config = self.config
            self._builder = BlockBuilder(self.kin)
        self._reply("ok")

    def _eeprom_write(self) -> None:
        """Write EEPROM like the AVR: the line's answer waits, and serial input is lost meanwhile."""
        with self._cond:
            until = self._now() + self.options.eeprom_write_time / self.scale
            self._eeprom_window = (self._now(), until)
            self._wait(lambda: self._now() >= until, until=until)

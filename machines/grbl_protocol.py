"""GRBL 1.1 serial protocol: real-time bytes, line cleaning and parsing of every reply.

Replies are parsed one line at a time (without the line end) into small frozen
dataclasses. Answers (`Ok`, `ErrorReply`) retire the oldest line sent; everything else
is a push message and never counts for character counting.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from machines.grbl_codes import describe_alarm, describe_error

# Real-time bytes: picked out of the stream by GRBL's serial interrupt, never buffered.
SOFT_RESET = b"\x18"
STATUS_QUERY = b"?"
CYCLE_START = b"~"
FEED_HOLD = b"!"
JOG_CANCEL = b"\x85"
FEED_OV_RESET, FEED_OV_PLUS_10, FEED_OV_MINUS_10, FEED_OV_PLUS_1, FEED_OV_MINUS_1 = (
    b"\x90", b"\x91", b"\x92", b"\x93", b"\x94")
RAPID_OV_100, RAPID_OV_50, RAPID_OV_25 = b"\x95", b"\x96", b"\x97"
SPINDLE_OV_RESET, SPINDLE_OV_PLUS_10, SPINDLE_OV_MINUS_10, SPINDLE_OV_PLUS_1, SPINDLE_OV_MINUS_1 = (
    b"\x99", b"\x9a", b"\x9b", b"\x9c", b"\x9d")
SPINDLE_STOP = b"\x9e"
FLOOD_TOGGLE = b"\xa0"
REALTIME_BYTES = frozenset(b"\x18?~!" + bytes(range(0x80, 0x100)))

# LINE_BUFFER_SIZE is 80 in protocol.h and the parser flags overflow at
# char_counter >= LINE_BUFFER_SIZE-1, so 79 characters survive (spaces/comments excluded).
MAX_LINE_CHARS = 79
DEFAULT_RX_BUFFER = 128
DEFAULT_PLANNER_BLOCKS = 15

_PLAIN = re.compile(r"^[!-'*-.0-:<-~]*$")  # printable, no '(', ')', '/', ';': nothing to strip


def clean_line(text: str) -> str:
    """What GRBL keeps of a line (protocol.c): no spaces or control characters, no block
    delete '/', no '(...)' or ';' comments, upper case. The one line cleaner of onestroke:
    the sender sends this form (it saves RX-buffer space and wire time) and the emulator
    reads received lines through it.
    """
    if _PLAIN.match(text):
        return text.upper()
    out = []
    comment = ""
    for ch in text:
        if comment:
            if comment == "(" and ch == ")":
                comment = ""
            continue
        if ch <= " " or ch == "/":
            continue
        if ch in "(;":
            comment = ch
        else:
            out.append(ch)
    return "".join(out).upper()


_EEPROM_WRITER = re.compile(r"^(\$\d+=|\$N\d*=|\$RST=|\$I=)|G10L[2]|G10L20|G28\.1|G30\.1")


def is_eeprom_writer(clean: str) -> bool:
    """True for lines that write EEPROM ($x=, $N, $RST, G10 L2/L20, G28.1, G30.1).

    GRBL disables interrupts while it writes EEPROM, so bytes arriving meanwhile are lost:
    such lines are sent one at a time (send-response).
    """
    return bool(_EEPROM_WRITER.search(clean))


# ----------------------------------------------------------------------------- replies


@dataclass(frozen=True)
class Ok:
    """`ok`: the oldest line sent was executed."""


@dataclass(frozen=True)
class ErrorReply:
    """`error:N`: the oldest line sent was rejected."""

    code: int

    def describe(self) -> str:
        return describe_error(self.code)


@dataclass(frozen=True)
class Alarm:
    """`ALARM:N` push message: the machine stopped and is locked."""

    code: int

    def describe(self) -> str:
        return describe_alarm(self.code)


@dataclass(frozen=True)
class Welcome:
    """`Grbl 1.1h ['$' for help]`: the firmware (re)started; its buffers are empty."""

    version: str


@dataclass(frozen=True)
class Message:
    """A bracketed push message: `[MSG:...]`, `[GC:...]`, `[VER:...]`, `[OPT:...]`, `[HLP:...]`, ..."""

    kind: str
    text: str


@dataclass(frozen=True)
class Setting:
    """One `$N=value` line of the `$$` dump."""

    number: int
    value: float


@dataclass(frozen=True)
class StatusReport:
    """`<State|MPos:..|Bf:..|FS:..|...>` parsed by key; every field but the state may be None.

    Positions are (3,) tuples in mm; `planner_free` and `rx_free` come from `Bf:`.
    """

    state: str
    substate: int | None = None
    mpos: tuple[float, ...] | None = None
    wpos: tuple[float, ...] | None = None
    wco: tuple[float, ...] | None = None
    planner_free: int | None = None
    rx_free: int | None = None
    line_number: int | None = None
    feed: float | None = None
    spindle: float | None = None
    overrides: tuple[int, int, int] | None = None
    pins: str | None = None
    accessories: str | None = None
    fields: dict[str, str] = field(default_factory=dict, compare=False)

    @property
    def full_state(self) -> str:
        return self.state if self.substate is None else f"{self.state}:{self.substate}"


@dataclass(frozen=True)
class Unknown:
    """A line that is none of the above: noise, a wrong baud rate, another firmware."""

    raw: bytes


Reply = Ok | ErrorReply | Alarm | Welcome | Message | Setting | StatusReport | Unknown

# GRBL 1.1 "Grbl 1.1h ['$' for help]"; forks: "GrblHAL 1.1f ['$' or '$HELP' for help]",
# "Grbl 3.7 [FluidNC v3.7.8 (wifi) '$' for help]".
_WELCOME = re.compile(r"^Grbl\w*\s+(\S+)\s+\[.*for help\]$")
_SETTING = re.compile(r"^\$(\d+)=([-+]?\d*\.?\d+)")
_NUMBER_LIST = re.compile(r"^[-+]?\d*\.?\d+(,[-+]?\d*\.?\d+)*$")


def _floats(text: str) -> tuple[float, ...]:
    return tuple(float(v) for v in text.split(","))


def parse_status(text: str) -> StatusReport:
    """Parse the inside of `<...>` (without the angle brackets)."""
    parts = text.split("|")
    state, _, sub = parts[0].partition(":")
    values: dict[str, str] = {}
    for part in parts[1:]:
        key, _, value = part.partition(":")
        values[key] = value
    kwargs: dict = {"state": state, "substate": int(sub) if sub.isdigit() else None, "fields": values}
    for key, name in (("MPos", "mpos"), ("WPos", "wpos"), ("WCO", "wco")):
        if key in values and _NUMBER_LIST.match(values[key]):
            kwargs[name] = _floats(values[key])
    if "Bf" in values and _NUMBER_LIST.match(values["Bf"]):
        blocks, rx = (int(v) for v in values["Bf"].split(",")[:2])
        kwargs.update(planner_free=blocks, rx_free=rx)
    if "Ln" in values and values["Ln"].isdigit():
        kwargs["line_number"] = int(values["Ln"])
    for key in ("FS", "F"):
        if key in values and _NUMBER_LIST.match(values[key]):
            numbers = _floats(values[key])
            kwargs["feed"] = numbers[0]
            kwargs["spindle"] = numbers[1] if len(numbers) > 1 else None
    if "Ov" in values and _NUMBER_LIST.match(values["Ov"]):
        ov = tuple(int(float(v)) for v in values["Ov"].split(","))
        if len(ov) == 3:
            kwargs["overrides"] = ov
    kwargs["pins"] = values.get("Pn")
    kwargs["accessories"] = values.get("A")
    return StatusReport(**kwargs)


def parse_reply(raw: bytes | str) -> Reply:
    """Parse one reply line (line end already removed) into a `Reply`.

    Anything that is not printable ASCII or not a known form comes back as `Unknown`.
    """
    data = raw.encode("latin-1") if isinstance(raw, str) else bytes(raw)
    data = data.strip(b"\r\n")
    if any(b < 0x20 or b > 0x7E for b in data):
        return Unknown(data)
    text = data.decode("ascii").strip()
    if text == "ok":
        return Ok()
    if text.startswith("error:") and text[6:].isdigit():
        return ErrorReply(int(text[6:]))
    if text.startswith("ALARM:") and text[6:].isdigit():
        return Alarm(int(text[6:]))
    if text.startswith("<") and text.endswith(">") and len(text) > 2:
        return parse_status(text[1:-1])
    if text.startswith("[") and text.endswith("]"):
        kind, _, body = text[1:-1].partition(":")
        return Message(kind, body)
    match = _WELCOME.match(text)
    if match:
        return Welcome(match.group(1))
    match = _SETTING.match(text)
    if match:
        return Setting(int(match.group(1)), float(match.group(2)))
    return Unknown(data)


def parse_options(option_text: str) -> tuple[int, int]:
    """Planner blocks and RX buffer size from the body of `[OPT:V,15,128]`."""
    parts = option_text.split(",")
    try:
        return int(parts[1]), int(parts[2])
    except (IndexError, ValueError):
        return DEFAULT_PLANNER_BLOCKS, DEFAULT_RX_BUFFER


def is_alarm_lock_message(reply: Reply) -> bool:
    """True for `[MSG:'$H'|'$X' to unlock]`, sent right after a welcome when booted in ALARM."""
    return isinstance(reply, Message) and reply.kind == "MSG" and "to unlock" in reply.text

"""The one framing program of onestroke: trace a job's bounding box to check its placement.

By default the beam stays off (`M5`, moves at the framing feed so the eye can follow);
with a power above zero the box is traced in `M4` at that low power, which leaves a faint
mark on most materials. Written to a file beside a job (`onestroke laser --frame`) or
streamed in machine coordinates (`onestroke stream --frame`, `G53`, back to where the
head started).
"""

from __future__ import annotations

from collections.abc import Sequence

from onestroke.errors import InputError
from onestroke.ranges import Range

DEFAULT_FRAME_FEED = 3000.0  # mm/min: slow enough to follow by eye
# The trace's power, a fraction of max S shown in percent; 0 keeps the beam off.
FRAME_POWER = Range(0.0, 1.0, unit="%", name="--frame-power", scale=100.0)


def _num(value: float) -> str:
    text = ("%.3f" % value).rstrip("0").rstrip(".")
    return "0" if text == "-0" else text


def framing_lines(bounds: tuple[float, float, float, float], *, feed: float = DEFAULT_FRAME_FEED,
                  power_s: float = 0.0, max_s: float = 1000.0, loops: int = 1,
                  machine_coordinates: bool = False,
                  return_to: Sequence[float] | None = None) -> list[str]:
    """G-code lines tracing the box (xmin, ymin, xmax, ymax) in mm.

    feed: mm/min; power_s: S of the trace (0 keeps the laser off), at most max_s ($30);
    loops: times around. machine_coordinates: every move in G53 (machine frame), for a
    sender that knows where the machine is; return_to: (x, y) mm to go back to with G0.
    """
    if not feed > 0:
        raise InputError(f"framing feed {feed!r} mm/min must be greater than 0")
    if not 0.0 <= power_s <= max_s:
        raise InputError(f"framing power S{power_s:g} must lie between 0 and $30 = {max_s:g}")
    if isinstance(loops, bool) or not isinstance(loops, int) or loops < 1:
        raise InputError(f"framing loops {loops!r} must be a whole number >= 1")
    xmin, ymin, xmax, ymax = (_num(v) for v in bounds)
    lit = power_s > 0
    state = "laser at S%s" % _num(power_s) if lit else "laser off"
    g53 = "G53" if machine_coordinates else ""
    lines = [f"; onestroke framing: {bounds[2] - bounds[0]:.1f} x {bounds[3] - bounds[1]:.1f} mm, {state}",
             "G21", "G90", "M4S0" if lit else "M5", f"{g53}G0X{xmin}Y{ymin}"]
    first = f"S{_num(power_s)}F{_num(feed)}" if lit else f"F{_num(feed)}"
    corners = [f"X{xmax}Y{ymin}", f"X{xmax}Y{ymax}", f"X{xmin}Y{ymax}", f"X{xmin}Y{ymin}"]
    for loop in range(loops):
        for k, corner in enumerate(corners):
            lines.append(f"{g53}G1" + corner + (first if loop == 0 and k == 0 else ""))
    lines.append("M5")
    if return_to is not None:
        lines.append(f"{g53}G0X{_num(return_to[0])}Y{_num(return_to[1])}")
    return lines

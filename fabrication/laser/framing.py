"""Framing program: trace the job's bounding box so the user can check the placement.

By default the beam stays off (`M5`, moves at the framing feed so the eye can follow);
with a power above zero the box is traced in `M4` at that low power, which leaves a faint
mark on most materials: ask for it only when a visible frame is wanted.
"""

from __future__ import annotations

from fabrication.laser.gcode_write import fmt
from machines.laser_profile import LaserProfile
from onestroke.errors import InputError


def framing_lines(bounds: tuple[float, float, float, float], profile: LaserProfile, *,
                  feed: float = 3000.0, power: float = 0.0, loops: int = 1) -> list[str]:
    """G-code lines tracing the box (xmin, ymin, xmax, ymax) in mm, machine frame.

    feed: mm/min; power: fraction of $30 (0 keeps the laser off); loops: times around.
    """
    if not feed > 0:
        raise InputError(f"framing feed {feed!r} mm/min must be greater than 0")
    if not 0.0 <= power <= 1.0:
        raise InputError(f"framing power {power * 100:g}% must lie between 0% and 100%")
    if isinstance(loops, bool) or not isinstance(loops, int) or loops < 1:
        raise InputError(f"framing loops {loops!r} must be a whole number >= 1")
    xmin, ymin, xmax, ymax = (fmt(v) for v in bounds)
    lit = power > 0
    state = "laser at %g%%" % (power * 100) if lit else "laser off"
    lines = [f"; onestroke framing: {bounds[2] - bounds[0]:.1f} x {bounds[3] - bounds[1]:.1f} mm, {state}",
             "G21", "G90", "M4S0" if lit else "M5", f"G0X{xmin}Y{ymin}"]
    first = f"S{fmt(power * profile.max_power)}F{fmt(feed)}" if lit else f"F{fmt(feed)}"
    corners = [f"X{xmax}", f"Y{ymax}", f"X{xmin}", f"Y{ymin}"]
    for loop in range(loops):
        for k, corner in enumerate(corners):
            lines.append("G1" + corner + (first if loop == 0 and k == 0 else ""))
    lines.append("M5")
    return lines

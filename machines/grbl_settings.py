"""The one mapping between GRBL's `$` settings and onestroke's laser profiles.

`settings_from_profile` gives the `$$` dump of the machine a profile describes (GRBL 1.1h
defaults for what a profile does not say); `profile_from_settings` reads a connected
machine's `$$` back into a profile; `kinematics_from_profile` is what the planner core
needs of either.
"""

from __future__ import annotations

from collections.abc import Mapping

from machines.laser_profile import LaserProfile
from machines.planner_model import Kinematics

# GRBL 1.1h defaults (defaults.h, DEFAULTS_GENERIC) for what a laser profile does not describe.
FIRMWARE_DEFAULTS: dict[int, float] = {
    0: 10, 1: 25, 2: 0, 3: 0, 4: 0, 5: 0, 6: 0, 10: 1, 11: 0.010, 12: 0.002, 13: 0,
    20: 0, 21: 0, 22: 0, 23: 0, 24: 25.0, 25: 500.0, 26: 250, 27: 1.0,
    30: 1000, 31: 0, 32: 1,
    100: 80.0, 101: 80.0, 102: 250.0, 110: 6000.0, 111: 6000.0, 112: 500.0,
    120: 500.0, 121: 500.0, 122: 10.0, 130: 400.0, 131: 400.0, 132: 0.0,
}
INTEGER_SETTINGS = frozenset({0, 1, 2, 3, 4, 5, 6, 10, 13, 20, 21, 22, 23, 26, 30, 31, 32})

# $N -> LaserProfile field
_PROFILE_FIELDS = {11: "junction_deviation", 12: "arc_tolerance", 30: "max_power", 100: "steps_per_mm_x",
                   101: "steps_per_mm_y", 110: "max_rate_x", 111: "max_rate_y", 120: "acceleration_x",
                   121: "acceleration_y", 130: "bed_width", 131: "bed_height"}


def settings_from_profile(profile: LaserProfile) -> dict[int, float]:
    """`$$` settings ({N: value}) of the machine `profile` describes."""
    settings = dict(FIRMWARE_DEFAULTS)
    for number, name in _PROFILE_FIELDS.items():
        settings[number] = float(getattr(profile, name))
    settings[32] = float(profile.laser_mode)
    return settings


def profile_from_settings(settings: Mapping[int, float], *, base: LaserProfile | None = None,
                          rx_buffer: int | None = None, planner_blocks: int | None = None,
                          name: str = "connected machine") -> LaserProfile:
    """A profile from a `$$` dump; settings missing or not positive keep `base`'s values."""
    base = base or LaserProfile()
    values = {}
    for number, field in _PROFILE_FIELDS.items():
        got = settings.get(number)
        values[field] = float(got) if got is not None and got > 0 else getattr(base, field)
    return LaserProfile(
        name=name, laser_mode=bool(settings.get(32, base.laser_mode)), air_assist=base.air_assist,
        rx_buffer=max(16, rx_buffer) if rx_buffer else base.rx_buffer,
        planner_blocks=max(2, planner_blocks) if planner_blocks else base.planner_blocks,
        baud=base.baud, parse_time=base.parse_time, **values)


def kinematics_from_profile(profile: LaserProfile) -> Kinematics:
    """The planner limits of `profile` (Z from GRBL's defaults)."""
    return Kinematics.from_settings(settings_from_profile(profile), planner_blocks=profile.planner_blocks)

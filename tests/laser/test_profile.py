"""Laser profiles: TOML with unit strings, the default, and one-line errors for bad files."""

from __future__ import annotations

import pytest

from machines.laser_profile import (DEFAULT_PROFILE_PATH, LaserProfile, bundled_laser_profiles, laser_profile_from_text,
                                    load_laser_profile, parse_acceleration)
from onestroke.errors import InputError


def test_default_profile_values():
    p = load_laser_profile()
    assert (p.bed_width, p.bed_height, p.max_power) == (400.0, 400.0, 1000.0)
    assert (p.max_rate_x, p.max_rate_y, p.acceleration_x, p.acceleration_y) == (6000.0, 6000.0, 500.0, 500.0)
    assert (p.junction_deviation, p.rx_buffer, p.planner_blocks) == (0.01, 128, 15)
    assert p.laser_mode and not p.air_assist
    assert p == LaserProfile(name=p.name)  # the TOML and the dataclass defaults agree


def test_profile_from_text_is_the_file_loader():
    """The studio parses a profile the page sends as text with the loader the CLI reads files with."""
    assert bundled_laser_profiles()[0] == DEFAULT_PROFILE_PATH
    assert laser_profile_from_text(DEFAULT_PROFILE_PATH.read_text()) == load_laser_profile()
    with pytest.raises(InputError, match="^k40.toml is not valid TOML: .*line 1"):
        laser_profile_from_text("name = \n[bed]", source="k40.toml")


def test_units_are_converted(tmp_path):
    path = tmp_path / "p.toml"
    path.write_text("""
name = "imperial"
[bed]
width = "10in"
height = "30cm"
[laser]
max_power = 255
air_assist = true
[motion]
max_rate_x = "100mm/s"
max_rate_y = "200in/min"
acceleration_x = "1800000mm/min^2"
acceleration_y = "1 m/s²"
junction_deviation = "0.02mm"
[controller]
rx_buffer = 256
planner_blocks = 31
""")
    p = load_laser_profile(path)
    assert p.bed_width == pytest.approx(254.0) and p.bed_height == pytest.approx(300.0)
    assert p.max_rate_x == pytest.approx(6000.0) and p.max_rate_y == pytest.approx(5080.0)
    assert p.acceleration_x == pytest.approx(500.0) and p.acceleration_y == pytest.approx(1000.0)
    assert p.air_assist and p.max_power == 255 and p.rx_buffer == 256 and p.planner_blocks == 31


@pytest.mark.parametrize("text,message", [
    ("[bed]\nsize = 'big'\n", "bed.size"),
    ("[motion]\nacceleration_x = '-5mm/s^2'\n", "acceleration_x"),
    ("[motion]\nmax_rate_x = 0\n", "max_rate_x"),
    ("[motion]\nspeed = 3\n", "motion.speed"),
    ("[laser]\nair_assist = 'yes'\n", "true or false"),
    ("[controller]\nrx_buffer = 12.5\n", "whole number"),
    ("[lasers]\n", "unknown key"),
    ("this is = = not toml", "not valid TOML"),
])
def test_bad_profiles_raise_input_error(tmp_path, text, message):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(InputError, match=message):
        load_laser_profile(path)


def test_missing_profile(tmp_path):
    with pytest.raises(InputError, match="does not exist"):
        load_laser_profile(tmp_path / "nope.toml")
    with pytest.raises(InputError, match="directory"):
        load_laser_profile(tmp_path)


def test_parse_acceleration():
    assert parse_acceleration("500mm/s^2") == 500.0
    assert parse_acceleration(250) == 250.0
    assert parse_acceleration("3600 mm/min^2") == pytest.approx(1.0)
    with pytest.raises(InputError):
        parse_acceleration("500 mm/s")


def test_machines_does_not_import_fabrication():
    import ast
    import pathlib

    source = pathlib.Path(__file__).resolve().parents[2] / "machines" / "laser_profile.py"
    tree = ast.parse(source.read_text())
    modules = {n.module for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)}
    modules |= {a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
    assert not any(m.split(".")[0] in ("fabrication", "vectorize") for m in modules if m)


@pytest.mark.parametrize("text,message", [
    ("[bed]\nsize = '3000x400mm'\n", "bed width 3000 must be above 0 mm to 2500 mm"),
    ("[bed]\nheight = '2.6m'\n", "bed height 2600 must be above 0 mm to 2500 mm"),
    ("[motion]\narc_tolerance = '0.0001mm'\n", "arc_tolerance ($12) 0.0001 must be from 0.001 mm to 1 mm"),
    ("[controller]\nrx_buffer = 100000\n", "rx_buffer 100000 must be from 16 bytes to 4096 bytes"),
    ("[controller]\nplanner_blocks = 1000\n", "planner_blocks 1000 must be from 2 to 256"),
])
def test_profile_values_beyond_any_machine_are_refused(text, message):
    """The declared ranges (machines.laser_profile): a bed, an arc tolerance, a buffer or a
    look-ahead beyond any GRBL machine's would make one job's estimate and preview grow
    without bound (an uploaded profile in the studio)."""
    with pytest.raises(InputError) as refused:
        laser_profile_from_text("name = 'big'\n" + text, source="big.toml")
    assert str(refused.value) == f"laser profile 'big': {message}"
    assert "\n" not in str(refused.value)
    LaserProfile(bed_width=2500.0, bed_height=1220.0, arc_tolerance=0.001, rx_buffer=4096, planner_blocks=256)

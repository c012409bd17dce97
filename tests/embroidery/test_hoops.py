"""Hoops, format limits and machine speed are data (machines/profiles/embroidery.toml)."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import machines.hoops as hoops_module
from machines.hoops import format_for_path, hoop_named, load_embroidery_profile
from onestroke.errors import InputError


def test_profile_holds_the_standard_hoops_and_formats():
    profile = load_embroidery_profile()
    sizes = {h.name: (h.width, h.height) for h in profile.hoops}
    assert sizes == {"100x100": (100, 100), "130x180": (130, 180), "150x250": (150, 250),
                     "160x260": (160, 260), "200x200": (200, 200)}
    limits = {f.extension: f.max_stitch for f in profile.formats}
    assert limits == {"pes": 12.1, "dst": 12.1, "jef": 12.7, "exp": 12.7, "vp3": 25.5}
    assert profile.stitches_per_minute == 600 and profile.trim_seconds == 10 and profile.max_stitch == 12.1
    assert format_for_path("x.JEF").settings == {"trims": True}
    assert format_for_path("x.pes").settings == {"pes version": 6}


def test_hoops_by_name_alias_or_custom_size():
    assert hoop_named("4x4").name == "100x100"
    assert hoop_named("5x7").name == "130x180"
    assert hoop_named("6x10").name == "160x260"
    custom = hoop_named("120x90")
    assert (custom.width, custom.height) == (120, 90)
    inches = hoop_named("4inx4in")
    assert inches.width == pytest.approx(101.6)
    assert custom.contains((-60, -45, 60, 45)) and not custom.contains((-60, -45, 60.1, 45))
    for bad in ("potato", "0x100", "100x-5", "10x10x10"):
        with pytest.raises(InputError):
            hoop_named(bad)


def test_unknown_extensions_are_refused_with_the_accepted_list():
    with pytest.raises(InputError, match=r"'\.svg'.*\.pes, \.dst, \.jef, \.exp, \.vp3"):
        format_for_path("drawing.svg")


def test_custom_profile_file(tmp_path):
    path = tmp_path / "p.toml"
    path.write_text('[machine]\nstitches_per_minute = 900\n[hoops.50x50]\nwidth = "2in"\nheight = "50mm"\n'
                    'aliases = ["2x2"]\n')
    profile = load_embroidery_profile(path)
    assert profile.stitches_per_minute == 900 and profile.hoop("2x2").width == pytest.approx(50.8)
    (tmp_path / "bad.toml").write_text("[machine\n")
    with pytest.raises(InputError):
        load_embroidery_profile(tmp_path / "bad.toml")


def test_machines_imports_neither_fabrication_nor_vectorize():
    tree = ast.parse(Path(hoops_module.__file__).read_text())
    names = [n.module for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)]
    names += [a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names]
    assert not [n for n in names if n and n.split(".")[0] in ("fabrication", "vectorize")]


def test_library_never_prints_exits_or_imports_click():
    folder = Path(__file__).parents[2] / "fabrication" / "embroidery"
    for path in folder.glob("*.py"):
        text = path.read_text()
        assert "import click" not in text and "print(" not in text and "sys.exit" not in text, path.name

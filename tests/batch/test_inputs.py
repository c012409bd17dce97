"""Batch inputs, manifest and options without running the vectorizer: which files a batch
picks up, where their outputs go, what it refuses before any work."""

from __future__ import annotations

import json

import pytest
from click.testing import CliRunner

from fabrication.batch.inputs import find_inputs
from fabrication.batch.manifest import MANIFEST_NAME, Manifest
from fabrication.batch.work import INPUT_EXTENSIONS
from fabrication.cli import main
from onestroke.errors import InputError


def touch(path, data: bytes = b"x"):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(data)
    return path


def test_folders_are_searched_recursively_and_mirrored(tmp_path):
    touch(tmp_path / "in" / "a.png")
    touch(tmp_path / "in" / "deep" / "er" / "b.JPG")
    touch(tmp_path / "in" / "notes.txt")
    touch(tmp_path / "in" / ".hidden.png")
    touch(tmp_path / "in" / ".a.png.x1.part")
    single = touch(tmp_path / "elsewhere" / "c.svg")
    items = find_inputs([tmp_path / "in", single], tmp_path / "out", ("svg", "pes"), INPUT_EXTENSIONS)
    assert [i.name for i in items] == ["a.png", "deep/er/b.JPG", "c.svg"]
    assert items[1].output("pes") == (tmp_path / "out" / "deep" / "er" / "b.pes").resolve()
    assert items[2].output("svg") == (tmp_path / "out" / "c.svg").resolve()


def test_the_output_folder_inside_the_input_folder_is_not_read_back(tmp_path):
    touch(tmp_path / "a.png")
    touch(tmp_path / "out" / "a.svg")
    items = find_inputs([tmp_path], tmp_path / "out", ("svg",), INPUT_EXTENSIONS)
    assert [i.name for i in items] == ["a.png"]


def test_two_inputs_writing_one_output_or_an_output_over_an_input_are_refused(tmp_path):
    touch(tmp_path / "in" / "cat.png")
    touch(tmp_path / "in" / "cat.jpg")
    with pytest.raises(InputError, match="would both write"):
        find_inputs([tmp_path / "in"], tmp_path / "out", ("pes",), INPUT_EXTENSIONS)
    touch(tmp_path / "svgs" / "wave.svg")
    with pytest.raises(InputError, match="would overwrite an input"):
        find_inputs([tmp_path / "svgs"], tmp_path / "svgs", ("svg",), INPUT_EXTENSIONS)


def test_a_damaged_manifest_means_everything_is_made_again(tmp_path):
    source = touch(tmp_path / "a.png")
    output = touch(tmp_path / "a.svg")
    manifest = Manifest(tmp_path)
    manifest.made("a.png", output, "k1")
    manifest.save()
    assert Manifest(tmp_path).is_current(source, "a.png", output, "k1")
    assert not Manifest(tmp_path).is_current(source, "a.png", output, "k2")
    (tmp_path / MANIFEST_NAME).write_text("{not json")
    assert not Manifest(tmp_path).is_current(source, "a.png", output, "k1")
    (tmp_path / MANIFEST_NAME).write_text(json.dumps([1, 2]))
    assert not Manifest(tmp_path).is_current(source, "a.png", output, "k1")


@pytest.mark.parametrize(("args", "message"), [
    (["--to", "png"], "is not an output this batch makes"),
    (["--to", ","], "--to names no output"),
    (["--to", "svg", "--pes-version", "1"], "--pes-version applies to --to pes only"),
    (["--to", "gcode", "--laser-tolerance", "5mm"], "--laser-tolerance"),
    (["--jobs", "0"], "--jobs 0"),
    (["--scheduler", "localhost"], "is not an address"),
])
def test_bad_options_are_refused_before_any_work(tmp_path, args, message):
    touch(tmp_path / "in" / "a.png", b"not a png")
    result = CliRunner().invoke(main, ["batch", str(tmp_path / "in"), "-o", str(tmp_path / "out"), *args])
    assert result.exit_code == 2
    assert message in result.output
    assert not (tmp_path / "out").exists()


def test_no_drawings_found_is_bad_input(tmp_path):
    touch(tmp_path / "in" / "readme.txt")
    result = CliRunner().invoke(main, ["batch", str(tmp_path / "in"), "-o", str(tmp_path / "out")])
    assert result.exit_code == 2 and "no drawings" in result.output

"""`onestroke inkscape install`: put the Inkscape extension where Inkscape finds it.

The extension (inkscape/onestroke_vectorize.inx and .py) runs under Inkscape's own Python,
which does not see onestroke's environment; the installer therefore records the interpreter
that has onestroke (onestroke_vectorize.json beside the script), and the script runs
`python -m fabrication.cli vectorize ...` with it.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from onestroke.atomic import atomic_write_bytes, atomic_write_text
from onestroke.errors import InputError, OutputError

EXTENSION_FILES = ("onestroke_vectorize.inx", "onestroke_vectorize.py")
SETTINGS = "onestroke_vectorize.json"


@dataclass(frozen=True, kw_only=True)
class InstalledExtension:
    """folder: where the files went; files: their paths (.inx, script, settings); python:
    the interpreter the extension runs onestroke with."""

    folder: Path
    files: tuple[Path, ...]
    python: str


def user_extensions_folder() -> Path:
    """Inkscape's user extensions folder: what `inkscape --user-data-directory` names (it
    follows INKSCAPE_PROFILE_DIR), else the XDG default ~/.config/inkscape."""
    inkscape = shutil.which("inkscape")
    if inkscape:
        try:
            done = subprocess.run([inkscape, "--user-data-directory"], capture_output=True, text=True,
                                  timeout=60)
            folder = done.stdout.strip().splitlines()[-1] if done.returncode == 0 and done.stdout.strip() else ""
            if folder:
                return Path(folder) / "extensions"
        except (OSError, subprocess.TimeoutExpired):
            pass
    if os.environ.get("INKSCAPE_PROFILE_DIR"):
        return Path(os.environ["INKSCAPE_PROFILE_DIR"]) / "extensions"
    config = os.environ.get("XDG_CONFIG_HOME") or os.path.join(os.path.expanduser("~"), ".config")
    return Path(config) / "inkscape" / "extensions"


def install_extension(folder: str | os.PathLike, *, python: str) -> InstalledExtension:
    """Copy the extension's files into `folder` (made if missing) and record `python`, an
    interpreter that can run `-m fabrication.cli`."""
    folder = Path(folder)
    if folder.exists() and not folder.is_dir():
        raise InputError(f"{folder} is a file; give a folder for the Inkscape extension")
    if not os.path.isfile(python):
        raise InputError(f"python {python!r} does not exist")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise OutputError(f"cannot make the folder {folder}: {error.strerror}") from None
    written = []
    source = resources.files("fabrication.bridges") / "inkscape"
    for name in EXTENSION_FILES:
        atomic_write_bytes(folder / name, (source / name).read_bytes())
        written.append(folder / name)
    atomic_write_text(folder / SETTINGS, json.dumps({"python": python}, indent=1) + "\n")
    written.append(folder / SETTINGS)
    return InstalledExtension(folder=folder, files=tuple(written), python=python)

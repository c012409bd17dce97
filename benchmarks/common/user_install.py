"""The project as a user has it after `pip install .`, for timing whole processes.

An editable install (`pip install -e`, the developers' and the tests' setup) is not what a
user runs: Python starts through the editable install's path finder, and where Python may
not write bytecode (PYTHONDONTWRITEBYTECODE, as on this machine) every process compiles the
project's modules from source. A regular install has them compiled by pip. So the start-up
benchmarks install this working tree the regular way into a new virtual environment in a
temporary folder. Its dependencies are not installed again: a `.pth` file puts the running
interpreter's site-packages (where they are installed, compiled by pip too) after the new
environment's own. Python does not read `.pth` files on such a path, so the editable
install's finder there is not loaded.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
# What the wheel is built from; copied to a clean folder first, so that no stale `build/`
# folder of an earlier build in the working tree puts removed modules into the install.
PACKAGE_FILES = ("pyproject.toml", "README.md", "onestroke", "vectorize", "fabrication", "machines")


def regular_install(folder: Path, source: Path = ROOT) -> Path:
    """Install `source` with `pip install --no-deps .` into a new virtual environment in
    `folder` (dependencies from this interpreter's site-packages); returns its `bin` folder
    (`python`, `onestroke`)."""
    folder = Path(folder)
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(folder)], check=True)
    python = folder / "bin" / "python"
    site = subprocess.run([str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                          capture_output=True, text=True, check=True).stdout.strip()
    ours = sorted({sysconfig.get_paths()["purelib"], sysconfig.get_paths()["platlib"]})
    (Path(site) / "onestroke-dependencies.pth").write_text("".join(f"{path}\n" for path in ours))
    tree = folder / "source"
    for name in PACKAGE_FILES:
        if (source / name).is_dir():
            shutil.copytree(source / name, tree / name, ignore=shutil.ignore_patterns("__pycache__"))
        else:
            tree.mkdir(exist_ok=True)
            shutil.copy2(source / name, tree / name)
    subprocess.run([sys.executable, "-m", "pip", "--python", str(python), "install", "--quiet", "--no-deps",
                    "--no-build-isolation", "--no-index", str(tree)],
                   capture_output=True, text=True, check=True, cwd=folder)
    return folder / "bin"


def bytecode_note(env, installed: bool = False) -> str:
    """Whether processes with environment `env` keep the project's compiled modules."""
    if installed:
        return "the project's modules compiled at install (a regular `pip install .`, what a user runs)"
    if env.get("PYTHONDONTWRITEBYTECODE"):
        return ("not written (PYTHONDONTWRITEBYTECODE is set: each process compiles the project's own modules "
                "from source; an installed package has them compiled)")
    return f"cached in {env.get('PYTHONPYCACHEPREFIX') or 'the __pycache__ folders'}"

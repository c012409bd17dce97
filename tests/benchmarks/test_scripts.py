"""The scripts of `benchmarks/` run as files (`python benchmarks/NAME.py`) from any folder, as
well as modules from the repository root (`python -m benchmarks.NAME`)."""

from __future__ import annotations

import ast
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SCRIPTS = sorted(p for p in (ROOT / "benchmarks").glob("*.py") if p.name != "__init__.py")


def _as_file(script: str, *args: str, cwd: Path) -> subprocess.CompletedProcess:
    """Run benchmarks/`script` as a file in `cwd`, with no PYTHONPATH: the project comes from
    this interpreter's install, `benchmarks` (no installed package) only from the script's own
    doing."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    return subprocess.run([sys.executable, str(ROOT / "benchmarks" / script), *args], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=300)


def test_the_benchmark_and_its_comparison_run_as_files_from_another_folder(tmp_path):
    """The drawing benchmark writes its CSV (the ground truth as output: no vectorizer, two
    drawings) and the no-regression check reads it back, each run as a file from tmp_path."""
    bench = _as_file("vectorize_bench.py", "--ground-truth-as-output", "--set", "plain", "--count", "2",
                     "--classifier", "geometric", "--csv", "base.csv", cwd=tmp_path)
    assert bench.returncode == 0, bench.stderr
    assert len((tmp_path / "base.csv").read_text().splitlines()) == 3  # the header and two drawings
    compared = _as_file("compare_runs.py", "base.csv", "base.csv", cwd=tmp_path)
    assert compared.returncode == 0, compared.stderr
    assert "plain/geometric" in compared.stdout and "2 -> 2" in compared.stdout


def _puts_the_root_first(tree: ast.Module) -> bool:
    """Whether the script, run as `__main__`, assigns `sys.path[0]` (the repository root in
    place of its own folder)."""
    for node in ast.walk(tree):
        if (isinstance(node, ast.If) and "__main__" in ast.unparse(node.test)
                and any(isinstance(n, ast.Assign) and ast.unparse(n.targets[0]) == "sys.path[0]"
                        for n in ast.walk(node))):
            return True
    return False


@pytest.mark.parametrize("script", SCRIPTS, ids=lambda p: p.name)
def test_every_script_puts_the_root_in_its_folder_s_place_when_run_as_a_file(script):
    assert _puts_the_root_first(ast.parse(script.read_text())), \
        f"{script.name} does not run as a file: see benchmarks/__init__.py"

"""Time another checkout's code (a worktree of an older commit, say) with this checkout's
benchmark: the script runs again in a child interpreter that imports `vectorize`,
`fabrication` and `machines` from that tree."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
# Set in the child: the tree it imports from (so the script runs there instead of again).
CHECKOUT_ENV = "ONESTROKE_BENCH_CHECKOUT"


def needs_rerun(tree: str | Path) -> bool:
    """Whether the code of `tree` is not what this process imports: another checkout, and
    this is not already the child started for it."""
    tree = Path(tree).resolve()
    return tree != ROOT and os.environ.get(CHECKOUT_ENV) != str(tree)


def rerun_on(tree: str | Path, script: str | Path, argv: list[str]) -> int:
    """Run `script` with `argv` in a child interpreter whose project packages come from
    `tree` (the benchmarks' own helpers from it too if it has them, else from this
    checkout); its exit code."""
    tree = Path(tree).resolve()
    env = {**os.environ, CHECKOUT_ENV: str(tree), "PYTHONPATH": os.pathsep.join([str(tree), str(ROOT)])}
    # -P: neither the working folder nor the script's own folder goes first on the path
    return subprocess.run([sys.executable, "-P", str(script), *argv], env=env).returncode

"""Child interpreters of the tests import this checkout: its root first on PYTHONPATH (then
whatever the environment had), whatever their working folder."""

from __future__ import annotations

import os
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def child_env(**extra: str) -> dict:
    """This process's environment for a child interpreter, with `extra` variables set."""
    path = os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))
    return {**os.environ, "PYTHONPATH": path, **extra}

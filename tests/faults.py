"""Real faults for tests: full disks, read-only and immutable folders, killed processes.

A full disk is a tiny tmpfs and a read-only folder a read-only tmpfs, both mounted in a
private mount namespace (`unshare -Urm`: a user namespace, so no root is needed, and the
mounts vanish with the process). Commands run there in one child interpreter through the
real click group. A folder a test process can neither write nor be let write as root is one
with `chattr +i` (root ignores permission bits, not the immutable flag); other users get
`chmod 0o500`.
"""

from __future__ import annotations

import contextlib
import json
import os
import shlex
import shutil
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from tests.children import child_env


# Run in the namespace: each (argv, folder) -> exit code, stderr and the files left in folder.
_DRIVER = """
import json, os, sys
from click.testing import CliRunner
from fabrication.cli import main
results = []
for argv, folder in json.loads(sys.argv[1]):
    if isinstance(argv, str):  # a shell command between two runs (a remount)
        results.append({"code": os.system(argv), "stderr": "", "left": []})
        continue
    result = CliRunner().invoke(main, argv)
    left = sorted(os.path.relpath(os.path.join(d, f), folder) for d, _, fs in os.walk(folder) for f in fs) \\
        if folder else []
    results.append({"code": result.exit_code, "stderr": result.stderr, "left": left})
print(json.dumps(results))
"""


def unshare_available() -> bool:
    if shutil.which("unshare") is None:
        return False
    probe = subprocess.run(["unshare", "-Urm", "true"], capture_output=True)
    return probe.returncode == 0


def run_with_mounts(mounts: list[str], rows: list[tuple[list[str], str | None]], *,
                    timeout: float = 300) -> list[dict]:
    """Run CLI `rows` ((argv, folder to list afterwards)) in a private mount namespace after
    the shell commands `mounts`; returns per row {"code", "stderr", "left"}. A row whose argv
    is a string is a shell command run there (e.g. a remount) between two runs."""
    if not unshare_available():
        pytest.skip("unshare -Urm is not allowed here (user namespaces disabled): no private tmpfs to fill")
    script = " && ".join(mounts) + " && exec " + shlex.join([sys.executable, "-c", _DRIVER, json.dumps(rows)])
    done = subprocess.run(["unshare", "-Urm", "sh", "-c", script], capture_output=True, text=True,
                          timeout=timeout, env=child_env())
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.strip().splitlines()[-1])


def tmpfs(folder: Path, size: str, *, read_only: bool = False) -> str:
    """The shell command mounting a tmpfs of `size` (e.g. "16k") on `folder`."""
    return f"mount -t tmpfs -o {'ro,' if read_only else ''}size={size} tmpfs {shlex.quote(str(folder))}"


@contextlib.contextmanager
def locked_folder(folder: Path) -> Iterator[Path]:
    """`folder` (made) that takes no new files for this process, root included."""
    folder.mkdir(exist_ok=True)
    if os.geteuid() == 0:
        if subprocess.run(["chattr", "+i", str(folder)], capture_output=True).returncode != 0:
            pytest.skip(f"chattr +i is not supported on {folder}'s file system")
        try:
            yield folder
        finally:
            subprocess.run(["chattr", "-i", str(folder)], check=True)
    else:
        folder.chmod(0o500)
        try:
            yield folder
        finally:
            folder.chmod(0o700)

"""No import circles in the benchmarks or the tests: every module's imports (at the top or
inside a function: a lazy import still closes a circle) read with ast, the modules of a
folder as a graph, and no strongly connected component larger than one module."""

from __future__ import annotations

import ast
from pathlib import Path

import networkx as nx
import pytest

ROOT = Path(__file__).resolve().parents[1]


def imported(path: Path, name: str) -> set[str]:
    """Every module `path` (module `name`) imports, as absolute names; `from a import b`
    counts as a and as a.b (b may be a submodule)."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")
                base = ".".join([*parts[:len(parts) - node.level + 1], *filter(None, [node.module])])
            found.add(base)
            found.update(f"{base}.{alias.name}" for alias in node.names)
    return found


def circles(root: Path, folder: str) -> list[list[str]]:
    """The import circles among the modules of `root / folder` (module names from `root`)."""
    paths = {}
    for path in (root / folder).rglob("*.py"):
        parts = list(path.relative_to(root).with_suffix("").parts)
        paths[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    graph = nx.DiGraph()
    graph.add_nodes_from(paths)
    for name, path in paths.items():
        graph.add_edges_from((name, target) for target in imported(path, name) if target in paths and target != name)
    return sorted(sorted(c) for c in nx.strongly_connected_components(graph) if len(c) > 1)


@pytest.mark.parametrize("folder", ["benchmarks", "tests"])
def test_no_import_circles(folder):
    assert len(list((ROOT / folder).rglob("*.py"))) > 10
    assert circles(ROOT, folder) == []


def test_a_lazy_import_closes_a_circle(tmp_path):
    """The check sees the circle conditions.py and photo.py had: a top-level import one way,
    an import inside a function (relative here) the other."""
    (tmp_path / "sets").mkdir()
    (tmp_path / "sets" / "__init__.py").write_text("")
    (tmp_path / "sets" / "photo.py").write_text("from sets.conditions import through_jpeg\n")
    (tmp_path / "sets" / "conditions.py").write_text("def f():\n    from .photo import photo_image\n")
    (tmp_path / "sets" / "render.py").write_text("import sets.photo\n")
    assert circles(tmp_path, "sets") == [["sets.conditions", "sets.photo"]]

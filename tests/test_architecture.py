"""The packages import each other as docs/architecture.md draws them, and never in a circle;
nor do the modules of the benchmarks and of the tests.

The imports are read from the source with `ast` (every `import` and `from ... import`, at the
top of a module or inside a function or `if TYPE_CHECKING:`, and module names given as
strings to `importlib`), module by module, then grouped into the packages of the
picture. The picture in docs/architecture.md is this module's output:

    python -m tests.test_architecture        # prints the mermaid block the doc holds
"""

from __future__ import annotations

import ast
import re
import sys
from functools import cache
from pathlib import Path

import networkx as nx
import pytest

ROOT = Path(__file__).resolve().parents[1]
LIBRARY = ("onestroke", "vectorize", "machines", "fabrication")
DOC = ROOT / "docs" / "architecture.md"

# The packages of the picture, in the pipeline's order (a module belongs to the package with
# the longest prefix of its name). The top of vectorize/ is two boxes: the types every stage shares
# and the entry points that run the stages.
PACKAGES = {
    "onestroke": ("onestroke",),
    "machines": ("machines",),
    "vectorize types": ("vectorize.stroke", "vectorize.drawing", "vectorize.options",
                        "vectorize.svg_write"),
    "vectorize.raster": ("vectorize.raster",),
    "vectorize.svg": ("vectorize.svg",),
    "vectorize.axis": ("vectorize.axis",),
    "vectorize.junctions": ("vectorize.junctions",),
    "vectorize.route": ("vectorize.route",),
    "vectorize.fit": ("vectorize.fit",),
    "vectorize.refine": ("vectorize.refine",),
    "vectorize entry": ("vectorize.pipeline", "vectorize.vectorizer", "vectorize.front_stages",
                        "vectorize.stage_clock", "vectorize.debug_overlay", "vectorize"),
    "vectorize.training": ("vectorize.training",),
    "fabrication.placement": ("fabrication.placement", "fabrication"),
    "fabrication.embroidery": ("fabrication.embroidery",),
    "fabrication.laser": ("fabrication.laser",),
    "fabrication.job_options": ("fabrication.job_options",),
    "fabrication.player": ("fabrication.player",),
    "fabrication.batch": ("fabrication.batch",),
    "fabrication.bridges": ("fabrication.bridges",),
    "fabrication.studio": ("fabrication.studio",),
    "fabrication.cli": ("fabrication.cli",),
}


def library_modules(packages: tuple[str, ...] = LIBRARY, root: Path = ROOT) -> dict[str, Path]:
    """Dotted name -> path of every module of `packages` (by default the four library
    packages) under `root` (a script in a folder that is no package, like the Inkscape
    extension run by Inkscape's own Python, is none)."""
    modules = {}
    for package in packages:
        for path in sorted((root / package).rglob("*.py")):
            parts = path.relative_to(root).with_suffix("").parts
            folders = [root.joinpath(*parts[:i]) for i in range(1, len(parts))]
            if not all(p.isidentifier() for p in parts) or not all((f / "__init__.py").exists() for f in folders):
                continue
            name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
            modules[name] = path
    return modules


def _resolve(name: str, modules: dict[str, Path]) -> str | None:
    """The library module `name` names (a module, or an attribute of one), else None."""
    while name and name not in modules:
        name = name.rpartition(".")[0]
    return name or None


@cache
def module_imports(packages: tuple[str, ...] = LIBRARY, root: Path = ROOT) -> nx.DiGraph:
    """Module -> module among the modules of `packages`, one edge per import found in the
    source (read once per run)."""
    modules = library_modules(packages, root)
    graph = nx.DiGraph()
    graph.add_nodes_from(modules)
    for name, path in modules.items():
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            targets = []
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    base = ".".join([*package.split(".")[:len(package.split(".")) - node.level + 1], base]).strip(".")
                targets = [f"{base}.{a.name}" for a in node.names]
            elif isinstance(node, ast.Constant) and isinstance(node.value, str):
                # A module named to importlib ("a.b" or "a.b:attribute": the lazy commands);
                # a string naming the module's own package is a resource look-up, not an import.
                text = node.value.partition(":")[0]
                if (re.fullmatch(r"[a-z_][a-z0-9_]*(\.[a-z_][a-z0-9_]*)+", text) and text in modules
                        and not name.startswith(text + ".")):
                    targets = [text]
            for target in targets:
                found = _resolve(target, modules)
                if found and found != name:
                    graph.add_edge(name, found)
    return graph


def package_of(module: str) -> str:
    """The box of `module`: the package with the longest prefix of its name."""
    found = [(len(p), package) for package, prefixes in PACKAGES.items() for p in prefixes
             if module == p or module.startswith(p + ".")]
    if not found:
        raise KeyError(f"{module} is in no package of docs/architecture.md")
    return max(found)[1]


def package_imports(graph: nx.DiGraph | None = None) -> nx.DiGraph:
    """Package -> package: the module imports grouped into the picture's boxes."""
    graph = module_imports() if graph is None else graph
    packages = nx.DiGraph()
    packages.add_nodes_from(PACKAGES)
    for a, b in graph.edges:
        pa, pb = package_of(a), package_of(b)
        if pa != pb:
            packages.add_edge(pa, pb)
    return packages


def _node_id(package: str) -> str:
    return package.replace(".", "_").replace(" ", "_")


def drawn_edges(packages: nx.DiGraph) -> list[tuple[str, str]]:
    """The arrows of the picture: every import between packages except those of the shared
    base `onestroke`, which every package may import (and which imports none of them)."""
    order = list(PACKAGES)
    return sorted(((a, b) for a, b in packages.edges if b != "onestroke"),
                  key=lambda e: (order.index(e[0]), order.index(e[1])))


def mermaid(packages: nx.DiGraph) -> str:
    """The picture: a box per package, grouped by top-level package, an arrow per import
    (importer --> imported)."""
    lines = ["```mermaid", "flowchart TD"]
    groups: dict[str, list[str]] = {}
    for package in PACKAGES:
        groups.setdefault(package.split(".")[0].split(" ")[0], []).append(package)
    for group, members in groups.items():
        if len(members) == 1:
            lines.append(f'    {_node_id(members[0])}["{members[0]}"]')
            continue
        lines.append(f"    subgraph {group}_packages[{group}]")
        lines.extend(f'        {_node_id(m)}["{m}"]' for m in members)
        lines.append("    end")
    lines.extend(f"    {_node_id(a)} --> {_node_id(b)}" for a, b in drawn_edges(packages))
    lines.append("```")
    return "\n".join(lines)


def drawn_block() -> str:
    match = re.search(r"```mermaid\n.*?```", DOC.read_text(), re.S)
    assert match, "docs/architecture.md has no mermaid picture"
    return match.group(0)


def test_no_import_circle_between_modules():
    cycles = list(nx.simple_cycles(module_imports()))
    assert cycles == [], f"import circles: {cycles}"


@pytest.mark.parametrize("folder", ["benchmarks", "tests"])
def test_no_import_circle_in_the_benchmarks_or_the_tests(folder):
    graph = module_imports((folder,))
    assert graph.number_of_nodes() > 10
    cycles = list(nx.simple_cycles(graph))
    assert cycles == [], f"import circles: {cycles}"


def test_a_lazy_import_closes_a_circle(tmp_path):
    """The reading sees the circle benchmarks/conditions.py and photo.py had: a top-level
    import one way, an import inside a function (relative here) the other."""
    (tmp_path / "sets").mkdir()
    (tmp_path / "sets" / "__init__.py").write_text("")
    (tmp_path / "sets" / "photo.py").write_text("from sets.conditions import through_jpeg\n")
    (tmp_path / "sets" / "conditions.py").write_text("def f():\n    from .photo import photo_image\n")
    (tmp_path / "sets" / "render.py").write_text("import sets.photo\n")
    graph = module_imports(("sets",), tmp_path)
    assert sorted(map(sorted, nx.simple_cycles(graph))) == [["sets.conditions", "sets.photo"]]


def test_no_import_circle_between_packages():
    packages = package_imports()
    assert nx.is_directed_acyclic_graph(packages), f"package circles: {list(nx.simple_cycles(packages))}"


def test_every_module_is_in_a_drawn_package():
    for module in library_modules():
        package_of(module)


def test_vectorize_top_holds_only_entry_points_and_types():
    top = {p.stem for p in (ROOT / "vectorize").glob("*.py")}
    named = {prefix.split(".")[1] for key in ("vectorize types", "vectorize entry")
             for prefix in PACKAGES[key] if "." in prefix}
    assert top - {"__init__"} == named


def test_packages_import_only_earlier_packages():
    """The boxes come in the pipeline's order: a package imports only those before it
    (downstream -> upstream), so the stages form a chain a newcomer can follow."""
    order = list(PACKAGES)
    backwards = [(a, b) for a, b in package_imports().edges if order.index(b) > order.index(a)]
    assert backwards == []


def test_the_doc_draws_the_real_imports():
    """An import between packages that the picture does not draw (or a drawn one that is gone)
    fails here: run `python -m tests.test_architecture` and update docs/architecture.md."""
    real, drawn = package_imports(), drawn_block()
    arrows = set(re.findall(r"^\s*(\w+) --> (\w+)$", drawn, re.M))
    ids = {_node_id(p): p for p in PACKAGES}
    assert {(ids[a], ids[b]) for a, b in arrows} == set(drawn_edges(real))
    assert drawn == mermaid(real)


def test_the_base_imports_no_other_package():
    assert list(package_imports().successors("onestroke")) == []


if __name__ == "__main__":
    sys.stdout.write(mermaid(package_imports()) + "\n")

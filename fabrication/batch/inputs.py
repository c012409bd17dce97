"""The files of a batch: drawings found in files and folders, and where their outputs go.

Outputs mirror the input tree under the output folder: `drawings/sub/cat.png` given as
`drawings` becomes `OUT/sub/cat.svg`, `OUT/sub/cat.pes`...; a file given by itself goes to
the top of OUT. Anything ambiguous (two inputs that would write the same output, an output
that is an input) is refused before any work.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from onestroke.errors import InputError
from onestroke.paths import check_input_file


@dataclass(frozen=True, kw_only=True)
class BatchItem:
    """One input: source (absolute path), name (relative posix path, as reported) and its
    output file per target extension."""

    source: Path
    name: str
    outputs: tuple[tuple[str, Path], ...]

    def output(self, extension: str) -> Path:
        return dict(self.outputs)[extension]


# The drawings a run still has to make, each with the extensions of its outputs not current.
Todo = list[tuple[BatchItem, tuple[str, ...]]]


def _walk(folder: Path, skip: Path) -> list[Path]:
    found = []
    for root, dirs, files in os.walk(folder, followlinks=False):
        here = Path(root)
        # never read our own outputs back as inputs; hidden entries are other tools' (and
        # half-written .part files)
        dirs[:] = sorted(d for d in dirs if not d.startswith(".") and (here / d).resolve() != skip)
        found += [here / f for f in sorted(files) if not f.startswith(".")]
    return found


def find_inputs(inputs, out_dir: str | os.PathLike, extensions: tuple[str, ...],
                input_extensions: tuple[str, ...]) -> list[BatchItem]:
    """The drawings among `inputs` (files, and folders searched recursively for files ending
    in one of `input_extensions`), each with an output path per target extension."""
    out = Path(out_dir).resolve()
    pairs: list[tuple[Path, str]] = []
    for given in inputs:
        path = Path(given)
        if path.is_dir():
            for file in _walk(path, out):
                if file.suffix.lower().lstrip(".") in input_extensions:
                    pairs.append((file.resolve(), file.relative_to(path).as_posix()))
        else:
            check_input_file(path, what="input")
            pairs.append((path.resolve(), path.name))
    items, seen_sources, writers = [], set(), {}
    for source, name in pairs:
        if source in seen_sources:  # the same file reached twice (a file inside a given folder)
            continue
        seen_sources.add(source)
        stem = name[: -len(source.suffix)] if source.suffix else name
        outputs = tuple((ext, out / f"{stem}.{ext}") for ext in extensions)
        for _, target in outputs:
            if target in writers:
                raise InputError(f"{writers[target]!r} and {name!r} would both write {str(target)!r}; "
                                 "rename one or run them as separate batches")
            writers[target] = name
        items.append(BatchItem(source=source, name=name, outputs=outputs))
    clash = seen_sources.intersection(writers)
    if clash:
        raise InputError(f"output {str(sorted(clash)[0])!r} would overwrite an input; choose another -o folder")
    return items

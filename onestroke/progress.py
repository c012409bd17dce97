"""Progress of long library work, as data: the library reports, the CLI shows.

A loop that can take more than a second on a large input (thousands of strokes, hundreds of
thousands of moves) accepts `progress`, a callable taking one `Progress`. The library never
prints; the caller decides what to show (a bar on a terminal, a line every few seconds in a
log, nothing). Reports within one stage never go back, and each stage ends with done == total.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from typing import TypeVar

T = TypeVar("T")

# Reports per stage at most (plus the last): enough for a smooth bar, few enough to cost nothing.
REPORTS_PER_STAGE = 100


@dataclass(frozen=True, kw_only=True)
class Progress:
    """`done` of `total` units (`unit`: "strokes", "moves", "bytes" ...) of the step `stage`."""

    stage: str
    done: int
    total: int
    unit: str = ""

    @property
    def fraction(self) -> float:
        """done / total in [0, 1] (1 for an empty stage)."""
        return min(1.0, self.done / self.total) if self.total > 0 else 1.0


ProgressCallback = Callable[[Progress], None]


class Stage:
    """Reports of one stage to `callback` (None: no reports, nothing to pay).

    `advance(n)` counts work done; a report goes out when the count has moved by a
    hundredth of `total` (`REPORTS_PER_STAGE`), and `finish()` sends done == total.
    """

    def __init__(self, callback: ProgressCallback | None, stage: str, total: int, unit: str = "") -> None:
        self.callback, self.stage, self.total, self.unit = callback, stage, max(0, int(total)), unit
        self.done = 0
        self._step = max(1, self.total // REPORTS_PER_STAGE)
        self._next = 0
        if callback is not None:
            self._send()

    def _send(self) -> None:
        self.callback(Progress(stage=self.stage, done=self.done, total=self.total, unit=self.unit))
        self._next = self.done + self._step

    def advance(self, count: int = 1) -> None:
        """`count` more units done."""
        self.done = min(self.total, self.done + count)
        if self.callback is not None and self.done >= self._next and self.done < self.total:
            self._send()

    def set(self, done: int) -> None:
        """`done` units done in all (never moves back)."""
        self.advance(max(0, int(done) - self.done))

    def finish(self) -> None:
        """The stage is complete: one last report with done == total."""
        self.done = self.total
        if self.callback is not None:
            self._send()


def counted(items: Iterable[T], callback: ProgressCallback | None, stage: str, total: int,
            unit: str = "") -> Iterator[T]:
    """`items`, reporting one unit of `stage` per item and the end of the stage."""
    if callback is None:
        yield from items
        return
    report = Stage(callback, stage, total, unit)
    for item in items:
        yield item
        report.advance()
    report.finish()

"""Wall and CPU seconds of each stage of one vectorizer run (`VectorizeReport.seconds` and
`cpu_seconds`), and the stage boundaries where the studio may stop a run."""

from __future__ import annotations

import time


class StageClock:
    """Wall and CPU seconds per stage (CPU: on a shared machine the wall time includes
    waiting for a core); `checkpoint` (optional) is called at every stage boundary and may
    raise to stop the run there (`StageCache.checkpoint`)."""

    def __init__(self, checkpoint=None) -> None:
        self.checkpoint = checkpoint
        self.seconds: dict[str, float] = {}
        self.cpu_seconds: dict[str, float] = {}
        self._last = time.perf_counter()
        self._last_cpu = time.process_time()

    def lap(self, stage: str) -> None:
        now, cpu = time.perf_counter(), time.process_time()
        self.seconds[stage] = self.seconds.get(stage, 0.0) + now - self._last
        self.cpu_seconds[stage] = self.cpu_seconds.get(stage, 0.0) + cpu - self._last_cpu
        self._last, self._last_cpu = now, cpu
        if self.checkpoint is not None:
            self.checkpoint()

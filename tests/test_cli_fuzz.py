"""Fuzzed inputs through every command: PNG bytes, SVG text and SVG structure (nested and
looping <use>, symbols, comments, huge numbers, transforms), G-code text, JSON drawings and
edits files, and option values of every command (Hypothesis, derandomized, bounded to about
two minutes). Each command line must exit 0, 1 or 2, show no traceback or internal error,
leave no partial or half-written file (all its outputs or none), finish within the time
bound and not push the process's memory peak over 1 GB. The longer run of 2,000+ inputs is
`python -m benchmarks.fuzz`.
"""

from __future__ import annotations


import pytest
from hypothesis import HealthCheck, given, settings

from benchmarks.sets.fuzz_cases import fuzz_case, run_case


TIME_BOUND = 60.0  # s per command line: generous for a loaded CI machine; a hang is minutes


@pytest.mark.parametrize("kind,examples", [("png", 12), ("svg", 25), ("svg-structure", 25), ("gcode", 15),
                                           ("json", 20), ("edits", 6), ("options", 30)])
def test_fuzzed_command_lines(kind, examples, tmp_path_factory):
    folder = tmp_path_factory.mktemp(f"fuzz-{kind}")

    @settings(max_examples=examples, derandomize=True, deadline=None, database=None,
              suppress_health_check=list(HealthCheck))
    @given(fuzz_case(kind))
    def check(case):
        outcome = run_case(case, folder, time_bound=TIME_BOUND)
        assert not outcome.hung, (case, "ran past the time bound")
        assert outcome.traceback is None, (case, outcome.traceback)
        assert outcome.exit_code in (0, 1, 2), (case, outcome.exit_code)
        assert outcome.leftovers == (), (case, outcome.leftovers)
        assert not outcome.over_memory, (case, f"{outcome.peak_mb:.0f} MB")

    check()

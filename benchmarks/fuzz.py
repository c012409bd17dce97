"""The long fuzz run: 2,000 fuzzed `onestroke` command lines (PNG bytes, SVG text, G-code
text, option values), in-process through the real click group, each under a time bound.
Prints how many exited 0/1/2, tracebacks, hangs and leftover files, and the slowest case.

    python benchmarks/fuzz.py                 # 2,000 inputs (500 per kind), seed 0
    python benchmarks/fuzz.py --per-kind 50 --seed 3 --time-bound 30
"""

from __future__ import annotations

import argparse
import collections
import sys
import tempfile
import time
from pathlib import Path

from hypothesis import HealthCheck, Phase, given, seed, settings

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from benchmarks.fuzz_cases import fuzz_case, run_case  # noqa: E402

KINDS = ("png", "svg", "gcode", "options")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--per-kind", type=int, default=500)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--time-bound", type=float, default=60.0, help="seconds per command line")
    args = ap.parse_args()
    codes, problems, slowest, total = collections.Counter(), [], (0.0, None), 0
    started = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for kind in KINDS:
            @seed(args.seed)
            @settings(max_examples=args.per_kind, deadline=None, database=None, phases=[Phase.generate],
                      suppress_health_check=list(HealthCheck))
            @given(fuzz_case(kind))
            def one(case):
                nonlocal slowest, total
                outcome = run_case(case, folder, time_bound=args.time_bound)
                total += 1
                codes[outcome.exit_code] += 1
                if outcome.seconds > slowest[0]:
                    slowest = (outcome.seconds, case[2:])
                if outcome.hung or outcome.traceback or outcome.leftovers or outcome.exit_code not in (0, 1, 2):
                    problems.append((kind, case, outcome))

            one()
            print(f"{kind}: done ({total} so far, {time.perf_counter() - started:.0f} s)", flush=True)
    tracebacks = [p for p in problems if p[2].traceback]
    hangs = [p for p in problems if p[2].hung]
    leftovers = [p for p in problems if p[2].leftovers]
    print(f"{total} inputs in {time.perf_counter() - started:.0f} s; exit codes "
          f"{dict(sorted(codes.items(), key=lambda kv: str(kv[0])))}; tracebacks {len(tracebacks)}, "
          f"hangs {len(hangs)} (> {args.time_bound:g} s), leftovers {len(leftovers)}; slowest "
          f"{slowest[0]:.1f} s ({slowest[1]})")
    for kind, case, outcome in problems[:20]:
        data = case[1][:200] if case[1] is not None else None
        print(f"  {kind} {case[2]} {case[3]}: {outcome} input {data!r}")


if __name__ == "__main__":
    main()

"""The long fuzz run: fuzzed `onestroke` command lines over every command (PNG bytes, SVG
text and structure, G-code text, JSON drawings and edits files, option values), in-process
through the real click group, each under a time bound (10 s) and a memory bound (1 GB:
the process's peak, a high-water mark, so no case went over when the final peak is under
it). Prints how many exited 0/1/2, tracebacks and internal errors, runs over the bounds,
incomplete output sets, the slowest case and the peak memory.

    python -m benchmarks.fuzz                 # 2,100 inputs (300 per kind), seed 0
    python -m benchmarks.fuzz --per-kind 50 --seed 3 --time-bound 30
"""

from __future__ import annotations

import argparse
import collections
import sys
import tempfile
import time
from pathlib import Path

if __name__ == "__main__" and Path(sys.path[0]).resolve() == Path(__file__).resolve().parent:
    sys.path[0] = str(Path(__file__).resolve().parents[1])  # run as a file: see benchmarks/__init__.py

from hypothesis import HealthCheck, Phase, given, seed, settings

from benchmarks.sets.fuzz_cases import KINDS, MEMORY_BOUND_MB, fuzz_case, run_case


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--per-kind", type=int, default=300)
    ap.add_argument("--kinds", default=",".join(KINDS), help="comma-separated subset of " + ",".join(KINDS))
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--time-bound", type=float, default=10.0, help="seconds per command line")
    ap.add_argument("--keep", default=None, help="folder to save the input of every problem case in")
    args = ap.parse_args()
    codes, problems, slowest, total, outcomes = collections.Counter(), [], (0.0, None), 0, []
    started = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for kind in args.kinds.split(","):
            @seed(args.seed)
            @settings(max_examples=args.per_kind, deadline=None, database=None, phases=[Phase.generate],
                      suppress_health_check=list(HealthCheck))
            @given(fuzz_case(kind))
            def one(case):
                nonlocal slowest, total
                outcome = run_case(case, folder, time_bound=args.time_bound)
                total += 1
                outcomes.append(outcome)
                codes[outcome.exit_code] += 1
                if outcome.seconds > slowest[0]:
                    slowest = (outcome.seconds, case[2:])
                if outcome.hung or outcome.traceback or outcome.leftovers or outcome.over_memory or \
                        outcome.exit_code not in (0, 1, 2):
                    problems.append((kind, case, outcome))
                    if args.keep and case[1] is not None:
                        Path(args.keep).mkdir(parents=True, exist_ok=True)
                        (Path(args.keep) / f"{kind}-{len(problems)}-{case[2]}.input").write_bytes(case[1])

            one()
            print(f"{kind}: done ({total} so far, {time.perf_counter() - started:.0f} s)", flush=True)
    tracebacks = [p for p in problems if p[2].traceback]
    hangs = [p for p in problems if p[2].hung]
    leftovers = [p for p in problems if p[2].leftovers]
    memory = [p for p in problems if p[2].over_memory]
    print(f"{total} inputs in {time.perf_counter() - started:.0f} s; exit codes "
          f"{dict(sorted(codes.items(), key=lambda kv: str(kv[0])))}; tracebacks or internal errors {len(tracebacks)}, "
          f"over {args.time_bound:g} s {len(hangs)}, over {MEMORY_BOUND_MB:g} MB {len(memory)}, partial output "
          f"sets {len(leftovers)}; slowest {slowest[0]:.1f} s ({slowest[1]}); peak memory "
          f"{max(o.peak_mb for o in outcomes):.0f} MB")
    # exit 1 is a failure of the work (a port that cannot open, a job GRBL would refuse): which
    failures = collections.Counter(" ".join(o.message.split()[:6]) for o in outcomes if o.exit_code == 1)
    print("exit 1, most common messages: " + "; ".join(f"{n} x {m}" for m, n in failures.most_common(6)))
    # tracebacks first, then partial outputs, memory, time: the rarer problems are not hidden
    problems.sort(key=lambda p: (not p[2].traceback, not p[2].leftovers, not p[2].over_memory))
    for kind, case, outcome in problems[:20]:
        data = case[1][:200] if case[1] is not None else None
        print(f"  {kind} {case[2]} {case[3]}: {outcome} input {data!r}")


if __name__ == "__main__":
    main()

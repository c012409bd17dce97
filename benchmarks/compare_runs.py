"""Did a change lower any set? Compares two `vectorize_bench --csv` files of the same drawings.

    python -m benchmarks.vectorize_bench --set all --seed 0 --csv /tmp/base-0.csv   # before
    python -m benchmarks.vectorize_bench --set all --seed 0 --csv /tmp/new-0.csv    # after
    python -m benchmarks.compare_runs /tmp/base-0.csv /tmp/new-0.csv

Prints, per set and classifier, the drawings that are correct, within half the local width
+ 1 px, and within 2 % of the route-inspection optimum, before -> after; then every drawing
whose verdict changed, and how many outputs changed length. This is the no-regression check
an output-changing step runs at two seeds before it lands. Exit code 1 when some set has
fewer correct drawings after than before.
"""

from __future__ import annotations

import argparse
import csv
import sys
from collections import defaultdict
from dataclasses import dataclass
from pathlib import Path

if __name__ == "__main__" and Path(sys.path[0]).resolve() == Path(__file__).resolve().parent:
    sys.path[0] = str(Path(__file__).resolve().parents[1])  # run as a file: see benchmarks/__init__.py

from benchmarks.metrics.route_figures import ROUTE_SLACK


@dataclass
class Tally:
    """Counts of one set's drawings in one run."""

    drawings: int = 0
    correct: int = 0
    within: int = 0
    route_within: int = 0
    route_measured: int = 0


def read_rows(path: Path) -> dict[tuple[str, str, str], dict]:
    """The rows of a `vectorize_bench --csv` file by (set, classifier, name)."""
    with open(path, newline="") as handle:
        return {(row["set"], row["classifier"], row["name"]): row for row in csv.DictReader(handle)}


def _yes(value: str) -> bool:
    return value == "True"


def tallies(rows: dict, keys: list) -> dict[tuple[str, str], Tally]:
    """Per (set, classifier): the counts over `keys`."""
    result: dict[tuple[str, str], Tally] = defaultdict(Tally)
    for key in keys:
        row, tally = rows[key], result[key[:2]]
        tally.drawings += 1
        tally.correct += _yes(row["correct"])
        tally.within += _yes(row["within"])
        if row.get("route_ratio"):
            tally.route_measured += 1
            tally.route_within += float(row["route_ratio"]) <= 1.0 + ROUTE_SLACK
    return result


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("base", type=Path, help="--csv of vectorize_bench before the change")
    ap.add_argument("new", type=Path, help="--csv of the same sets and seed after it")
    args = ap.parse_args(argv)
    try:
        base, new = read_rows(args.base), read_rows(args.new)
    except (OSError, KeyError, csv.Error) as exc:
        print(f"error: cannot read a vectorize_bench --csv file: {exc}", file=sys.stderr)
        return 2
    keys = sorted(set(base) & set(new))
    if not keys:
        print("error: the two files have no drawing in common (other sets or seeds?)", file=sys.stderr)
        return 2
    before, after = tallies(base, keys), tallies(new, keys)
    print(f"{'set':24s} {'n':>4s}  {'correct':>12s}  {'within w/2+1':>14s}  {'route <= 2 %':>16s}")
    lowered = []
    for group in sorted(before):
        b, a = before[group], after[group]
        print(f"{'/'.join(group):24s} {b.drawings:4d}  {b.correct:5d} -> {a.correct:<4d}  "
              f"{b.within:6d} -> {a.within:<5d}  {b.route_within:5d}/{b.route_measured} -> "
              f"{a.route_within}/{a.route_measured}")
        if a.correct < b.correct:
            lowered.append("/".join(group))
    print("\nchanged verdicts:")
    for key in keys:
        b, a = base[key], new[key]
        if _yes(b["correct"]) != _yes(a["correct"]):
            print(f"  {'/'.join(key)}: correct {b['correct']} -> {a['correct']}, order "
                  f"{float(b['order'] or 0):.3f} -> {float(a['order'] or 0):.3f}, strokes {b['strokes']} -> "
                  f"{a['strokes']}, route {b.get('route_ratio', '')[:6]} -> {a.get('route_ratio', '')[:6]}")
    changed = sum(base[key]["out_length"] != new[key]["out_length"] for key in keys)
    print(f"\noutputs whose length changed: {changed} of {len(keys)}")
    if len(keys) < max(len(base), len(new)):
        print(f"(compared the {len(keys)} drawings both files hold; {len(base)} before, {len(new)} after)")
    if lowered:
        print(f"lower than before: {', '.join(lowered)}")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Every drawing set of the vectorizer benchmark by name, and how many drawings each takes.

`SETS` are the sets `--set all` runs (the ones the team tunes on); "heldout", "kinds" and
"cursive" run only when named. `build_set` imports a set's module only when it is asked for.
"""

from __future__ import annotations

DEFAULT_COUNTS = {"plain": 42, "touch": 40, "hershey": 40, "hershey-retrace": 40, "relief": 40, "triple": 40,
                  "handwriting": 40}
SETS = tuple(DEFAULT_COUNTS)
HELDOUT_COUNT = 93  # --set heldout (benchmarks/sets/heldout.py): not part of "all", which are the sets tuned on
KINDS_COUNT = 40  # --set kinds (benchmarks/sets/kinds.py): not part of "all" either
CURSIVE_COUNT = 40  # --set cursive (benchmarks/sets/cursive.py): long lines, not part of "all"


def build_set(name: str, count: int, seed: int) -> list:
    """The ground truths (`GroundTruth`) of one benchmark set."""
    if name in ("hershey", "hershey-retrace"):
        from benchmarks.sets.hershey import hershey_set

        return hershey_set(count, seed, ambiguous=name == "hershey-retrace")
    if name == "relief":
        from benchmarks.sets.relief import relief_set

        return relief_set(count, seed)
    if name == "handwriting":
        from benchmarks.sets.handwriting import handwriting_set

        return handwriting_set(count, seed)
    if name == "heldout":
        from benchmarks.sets.heldout import heldout_set

        return heldout_set(count, seed)
    if name == "kinds":
        from benchmarks.sets.kinds import kinds_set

        return kinds_set(count, seed)
    if name == "cursive":
        from benchmarks.sets.cursive import cursive_set

        return cursive_set(count, seed)
    from benchmarks.sets.drawings import generate_set

    return generate_set(name, count, seed)

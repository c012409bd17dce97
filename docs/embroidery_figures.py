"""The stitch counts and densities quoted in docs/embroidery.md, computed from the code.

    python -m docs.embroidery_figures           # list each figure: in the docs / from the code
    python -m docs.embroidery_figures --write   # put the code's figures into the docs

In the docs a figure is written `<!-- figure NAME -->VALUE<!-- /figure -->` (the markers
do not show on the rendered page). Every figure is deterministic (the same code gives the
same value), so `tests/embroidery/test_docs.py` checks that the docs say what the code
does: a figure cannot drift again (the ampersand's 487 stitches were 477 for a while).
Jobs are built by `fabrication.job_options.embroidery_settings`, the same call as
`onestroke embroider` with the flags shown in the docs.
"""

from __future__ import annotations

import argparse
import re
from functools import lru_cache
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

DOC = ROOT / "docs" / "embroidery.md"
MARK = re.compile(r"<!-- figure (?P<name>[\w.-]+) -->(?P<value>.*?)<!-- /figure -->")
STYLES = ("running", "triple", "zigzag", "arrows")


@lru_cache(maxsize=None)
def _drawing(name: str):
    from vectorize import VectorizeOptions, vectorize_file

    return vectorize_file(str(ROOT / "examples" / name), VectorizeOptions()).drawing


@lru_cache(maxsize=None)
def _embroider(name: str, style: str):
    """What `onestroke embroider examples/NAME -o x.pes --style STYLE` makes."""
    from fabrication.embroidery.pipeline import embroider
    from fabrication.job_options import embroidery_settings

    job = embroidery_settings(output="x.pes", style=style, source=name).job
    return embroider(_drawing(name), job)


def _short_stroke_density(style: str) -> int:
    """Worst density (every needle point) of a 1.2 mm stroke, just above --min-stroke."""
    import numpy as np

    from fabrication.embroidery.plan import PlanOptions, plan_embroidery, style_options
    from fabrication.embroidery.stats import embroidery_stats
    from vectorize.drawing import Drawing
    from vectorize.stroke import Stroke

    stroke = Stroke.from_polyline(np.array([[0.0, 0.0], [1.2, 0.0]]))
    plan = plan_embroidery(Drawing((stroke,), 2, 1, "mm"), PlanOptions(style=style_options(style)))
    return embroidery_stats(plan).max_density


def figures() -> dict[str, str]:
    """Every figure the docs quote, by name, as the docs write it."""
    out = {}
    arrows = _embroider("hershey-HersheySans1-ampersand.png", "arrows").stats
    out["ampersand-arrows-stitches"] = f"{arrows.stitches:,}"
    out["ampersand-arrows-trims"] = f"{arrows.trims}"
    wave = _embroider("embroidery/wave.svg", "zigzag").stats
    out["wave-zigzag-stitches"] = f"{wave.stitches:,}"
    out["wave-zigzag-trims"] = f"{wave.trims}"
    for style in STYLES:
        out[f"short-stroke-density-{style}"] = f"{_short_stroke_density(style)}"
    return out


def quoted(text: str) -> dict[str, str]:
    """The figures `text` quotes, by name."""
    return {m["name"]: m["value"] for m in MARK.finditer(text)}


def rewrite(text: str, values: dict[str, str]) -> str:
    """`text` with each marked figure set to its value in `values`."""
    return MARK.sub(lambda m: f"<!-- figure {m['name']} -->{values.get(m['name'], m['value'])}<!-- /figure -->",
                    text)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write", action="store_true", help="put the code's figures into the docs")
    args = parser.parse_args(argv)
    text = DOC.read_text(encoding="utf-8")
    have, want = quoted(text), figures()
    for name in sorted(set(have) | set(want)):
        flag = "" if have.get(name) == want.get(name) else "   <- differs"
        print(f"{name:32} docs {have.get(name, '-'):>8}   code {want.get(name, '-'):>8}{flag}")
    if args.write:
        from onestroke.atomic import atomic_write_bytes

        atomic_write_bytes(DOC, rewrite(text, want).encode("utf-8"))
        print(f"wrote {DOC.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

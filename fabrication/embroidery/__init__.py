"""Embroidery along the curve: stitch generators, whole-design planning, export and preview.

One call: `embroider(drawing, EmbroideryJob(...))`. Step by step: `Drawing` (mm, centred)
-> `plan_embroidery` (a generator per stroke, tacks,
locks, trims, min/max stitch) -> `StitchPlan` -> `write_embroidery` (.pes/.dst/.jef/.exp/
.vp3 via pyembroidery), `embroidery_stats`, `render_stitch_preview`.
"""

from fabrication.embroidery.arrows import ArrowOptions, arrow_stitch
from fabrication.embroidery.export import write_embroidery
from fabrication.embroidery.locks import LockOptions
from fabrication.embroidery.pipeline import EmbroideryJob, EmbroideryResult, embroider
from fabrication.embroidery.plan import (STYLES, PlanOptions, StitchPlan, plan_embroidery,
                                         style_options)
from fabrication.embroidery.read import read_embroidery
from fabrication.embroidery.running import RunningOptions, running_stitch
from fabrication.embroidery.triple import TripleOptions, triple_stitch
from fabrication.embroidery.zigzag import ZigzagOptions, zigzag_stitch

__all__ = [
    "EmbroideryJob", "EmbroideryResult", "embroider",
    "ArrowOptions", "LockOptions", "PlanOptions", "RunningOptions", "STYLES", "StitchPlan",
    "TripleOptions", "ZigzagOptions", "arrow_stitch", "plan_embroidery", "read_embroidery",
    "running_stitch", "style_options", "triple_stitch", "write_embroidery", "zigzag_stitch",
]

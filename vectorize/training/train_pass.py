"""Train the pass scorer of triple points on synthetic scenes and export it to ONNX.

    onestroke train-pass-scorer --seed 0 --out vectorize/models/pass_cnn.onnx

Reproducible from the seed on CPU, like the crossing CNN (`vectorize.training.train`):
scenes, initialisation, batch order and mirroring all derive from it. After training:
the weights that combine the image's log-odds with continuation are fitted on scenes of
seed + 500 (a conditional-logit model over the 15 pairings of each node), and the pairing
accuracy of continuation alone, the image alone and both is measured on scenes of seed +
1000 (`vectorize.training.pass_eval`). Writes the model, its metadata (.json) and model
card (.md), all three together or none (`vectorize.training.train.staged_model`). Needs the `train` extra (PyTorch); the vectorizer only loads the ONNX file.
"""

from __future__ import annotations

import json
import os
import time
from collections.abc import Callable
from pathlib import Path

import torch
from torch import nn

from onestroke.atomic import atomic_write_text
from vectorize.junctions.pass_crop import PassCropSpec
from vectorize.training.model import pass_net
from vectorize.training.pass_eval import evaluate_pairing, fit_combination
from vectorize.training.train import base_meta, crop_tensors, export_onnx, fit, seeded_start, staged_model
from vectorize.training.triple_synth import generate_passes

CALIBRATION_SEED_OFFSET, VALIDATION_SEED_OFFSET = 500, 1000
DEFAULT_OUT = Path(__file__).parents[1] / "models" / "pass_cnn.onnx"


def _mirror(x: torch.Tensor, code: torch.Tensor) -> torch.Tensor:
    """Per sample, code in 0..3: bit 0 mirrors across the pass (rows), bit 1 swaps its feet
    (columns); both are exact symmetries of a pass crop."""
    out = x.clone()
    rows, cols = (code & 1).bool(), (code & 2).bool()
    out[rows] = out[rows].flip(-2)
    out[cols] = out[cols].flip(-1)
    return out


def train_pass(*, seed: int, scenes: int, epochs: int, batch: int, lr: float, workers: int,
               log: Callable[[str], None] = lambda line: None) -> tuple[nn.Module, dict]:
    """Generate `scenes` scenes (15 candidate passes each) and train; returns the network
    (eval mode) and training facts."""
    started = seeded_start(seed)
    data = generate_passes(scenes, seed=seed, workers=workers)
    log(f"generated {len(data.x)} training crops ({scenes} scenes) in {time.perf_counter() - started:.0f} s")
    x, y = crop_tensors(data.x, data.label)
    net = pass_net()
    # 3 true passes of 15: weigh them up so that p = 0.5 means "as likely as not".
    loss_fn = nn.BCEWithLogitsLoss(pos_weight=torch.tensor(4.0))
    fit(net, x, y, seed=seed, epochs=epochs, batch=batch, lr=lr, augment=_mirror, codes=4, loss_fn=loss_fn,
        started=started, log=log)
    return net, {"train_scenes": scenes, "train_crops": len(data.x), "epochs": epochs, "batch": batch, "lr": lr,
                 "train_seconds": round(time.perf_counter() - started, 1)}


def model_card(meta: dict) -> str:
    """The Markdown model card from the metadata."""
    v, t, c = meta["validation"], meta["training"], meta["combine"]
    rows = "\n".join(f"| {name} | {v[key]['synthetic']:.4f} | {v[key]['pipeline']:.4f} |"
                     for name, key in (("continuation alone", "continuation"), ("image alone", "image"),
                                       ("both (shipped)", "combined")))
    return f"""# Pass scorer of triple points (`pass_cnn.onnx`)

A small CNN that tells, at a node where three passes of a single-line drawing cross (six
branch feet, `vectorize.axis.clusters`), whether a candidate pass (two feet) is one the pen
drew straight through. The vectorizer pairs the six feet by the pairing whose three passes
score best, adding the image's log-odds and the continuation cost (`vectorize.junctions.pass_scorer`).

- Input `crops`: (N, 4, {meta['crop']['size']}, {meta['crop']['size']}) float32 from
  `vectorize.junctions.pass_crop.crop_passes`: ink and the candidate's two rays, {meta['crop']['near_span']} and
  {meta['crop']['far_span']} stroke widths wide, rotated so the candidate runs along +x.
- Output `p_pass`: (N,) probability that the candidate is a true pass.
- Parameters: {meta['parameters']:,}; file size {meta['bytes']:,} bytes; sha256 `{meta['sha256']}`.
- Training data: {t['train_scenes']:,} synthetic scenes ({t['train_crops']:,} candidate passes,
  `vectorize.training.triple_synth`, seed {meta['seed']}), {t['epochs']} epochs, batch {t['batch']},
  AdamW with a one-cycle learning rate up to {t['lr']}, random mirroring; {t['train_seconds']:.0f} s on {t['cpu']}{
  ' (' + t['note'] + ')' if t.get('note') else ''}.
- Combination (fitted on {c['scenes']} scenes of seed {c['seed']}): score of a pass =
  {c['image']:.3f} x image log-odds {c['continuation']:+.3f} x (1 + cos between its feet) (signs
  fixed: image >= 0, continuation <= 0). Where the best pairing's posterior is under one
  half, continuation alone decides.
- Command: `{meta['command']}`

## Validation

Pairing accuracy (all three passes right) on fresh scenes of seed {v['seed']}: "synthetic" with
the feet measured from the true curves as the vectorizer measures them ({v['synthetic_scenes']}
scenes); "pipeline" on the nodes the vectorizer's own stages (binarize, medial axis, pruning,
cluster merge) find in {v['pipeline_scenes']} scenes ({v['pipeline_nodes']} nodes found):

| pairing by | synthetic | pipeline |
|---|---|---|
{rows}
"""


def train_and_export_pass(*, seed: int = 0, scenes: int = 1000, epochs: int = 4, batch: int = 128,
                          lr: float = 4e-3, calibration: int = 200, validation: int = 200, workers: int = 1,
                          out: Path = DEFAULT_OUT, log: Callable[[str], None] = lambda line: None) -> dict:
    """Train, export `out` (.onnx), fit the combination weights on `calibration` scenes,
    measure pairing accuracy on `validation` scenes; writes .json and .md beside `out` and
    returns the metadata."""
    spec = PassCropSpec()
    net, facts = train_pass(seed=seed, scenes=scenes, epochs=epochs, batch=batch, lr=lr, workers=workers, log=log)
    facts["cpu"] = f"{os.cpu_count()} CPU cores"
    with staged_model(Path(out)) as staged:
        data = export_onnx(net, staged, spec, channels=4, output="p_pass")
        meta = base_meta("train-pass-scorer", {"seed": seed, "scenes": scenes, "epochs": epochs, "batch": batch,
                                               "lr": lr, "calibration": calibration, "validation": validation},
                         spec, net, data, facts)
        return calibrate_and_validate(staged, meta, calibration=calibration, validation=validation,
                                      workers=workers, log=log)


def calibrate_and_validate(out: Path, meta: dict, *, calibration: int, validation: int, workers: int,
                           log: Callable[[str], None] = lambda line: None) -> dict:
    """For an exported model `out` and its metadata so far: fit the combination weights,
    measure the pairing accuracy, write the .json and .md; returns the full metadata."""
    seed = meta["seed"]
    meta = dict(meta, combine=fit_combination(out, scenes=calibration, seed=seed + CALIBRATION_SEED_OFFSET,
                                              workers=workers))
    log(f"combination fitted: {meta['combine']}")
    # The metadata must exist before validation loads the model the way the vectorizer does.
    atomic_write_text(out.with_suffix(".json"), json.dumps(meta, indent=2) + "\n")
    meta["validation"] = evaluate_pairing(out, scenes=validation, seed=seed + VALIDATION_SEED_OFFSET,
                                          workers=workers)
    atomic_write_text(out.with_suffix(".json"), json.dumps(meta, indent=2) + "\n")
    atomic_write_text(out.with_suffix(".md"), model_card(meta))
    return meta

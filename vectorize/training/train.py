"""Train the crossing-vs-touching CNN on synthetic crops and export it to ONNX.

    onestroke train-classifier --seed 0 --out vectorize/models/crossing_cnn.onnx

Reproducible from the seed on CPU (data, initialisation, batch order and augmentation all
derive from it). Writes the ONNX model, its metadata JSON and the model card (Markdown)
with the validation figures measured on freshly generated crops of another seed. The three
files appear together when the command succeeds; until then the model is exported and
validated in a hidden folder beside `--out`, so an interrupted run leaves the old trio as it was.
Needs the `train` extra (PyTorch); the vectorizer itself only ever loads the ONNX file.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import tempfile
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
import torch
from torch import nn

from onestroke.atomic import all_or_nothing, atomic_write_bytes, atomic_write_text
from vectorize.junctions.junction_crop import CropSpec
from vectorize.training.model import CrossingNet, Probability
from vectorize.training.synth import SUBTYPES, generate
from vectorize.training.validate import evaluate_onnx

VALIDATION_SEED_OFFSET = 1000


def _dihedral(x: torch.Tensor, code: torch.Tensor) -> torch.Tensor:
    """Apply one of the 8 rotations/flips per sample (code in 0..7)."""
    out = torch.empty_like(x)
    for c in range(8):
        idx = (code == c).nonzero(as_tuple=True)[0]
        if idx.numel() == 0:
            continue
        part = x[idx]
        if c >= 4:
            part = part.flip(-1)
        out[idx] = torch.rot90(part, c % 4, dims=(-2, -1))
    return out


def fit(net: nn.Module, x: torch.Tensor, y: torch.Tensor, *, seed: int, epochs: int, batch: int, lr: float,
        augment: Callable[[torch.Tensor, torch.Tensor], torch.Tensor], codes: int,
        loss_fn: nn.Module, started: float, log: Callable[[str], None] = lambda line: None) -> None:
    """Train `net` in place on crops x (N, C, S, S) and labels y (N,) in {0, 1}: AdamW with a
    one-cycle learning rate; each sample of a batch gets `augment(crops, code)` with a code
    drawn in 0..codes-1 (an exact symmetry). Batch order and codes derive from `seed`."""
    samples = len(x)
    optimizer = torch.optim.AdamW(net.parameters(), lr=lr, weight_decay=1e-4)
    steps = epochs * ((samples + batch - 1) // batch)
    schedule = torch.optim.lr_scheduler.OneCycleLR(optimizer, max_lr=lr, total_steps=steps)
    generator = torch.Generator().manual_seed(seed)
    for epoch in range(epochs):
        net.train()
        order = torch.randperm(samples, generator=generator)
        total, correct, loss_sum = 0, 0, 0.0
        for start in range(0, samples, batch):
            idx = order[start:start + batch]
            code = torch.randint(0, codes, (len(idx),), generator=generator)
            xb, yb = augment(x[idx], code), y[idx]
            optimizer.zero_grad()
            logits = net(xb)
            loss = loss_fn(logits, yb)
            loss.backward()
            optimizer.step()
            schedule.step()
            loss_sum += float(loss.detach()) * len(idx)
            correct += int(((logits > 0).float() == yb).sum())
            total += len(idx)
        log(f"epoch {epoch + 1}/{epochs}: loss {loss_sum / total:.4f}, train accuracy {correct / total:.4f}, "
            f"{time.perf_counter() - started:.0f} s")
    net.eval()


def seeded_start(seed: int) -> float:
    """Seed torch (initialisation, batch order) and use every core; returns the start time
    (time.perf_counter) for the training log."""
    torch.manual_seed(seed)
    torch.set_num_threads(max(1, os.cpu_count() or 1))
    return time.perf_counter()


def crop_tensors(crops: np.ndarray, labels: np.ndarray) -> tuple[torch.Tensor, torch.Tensor]:
    """uint8 crops (N, C, S, S) and 0/1 labels (N,) -> float32 tensors, ink scaled to 0..1."""
    return torch.from_numpy(crops.astype(np.float32) / 255.0), torch.from_numpy(labels.astype(np.float32))


def train(*, seed: int, samples: int, epochs: int, batch: int, lr: float, workers: int,
          log: Callable[[str], None] = lambda line: None) -> tuple[CrossingNet, dict]:
    """Generate data and train; returns the network (eval mode) and training facts.
    `log` receives one progress line per stage and epoch."""
    started = seeded_start(seed)
    data = generate(samples, seed=seed, workers=workers)
    log(f"generated {samples} training crops in {time.perf_counter() - started:.0f} s")
    x, y = crop_tensors(data.x, data.label)
    net = CrossingNet()
    fit(net, x, y, seed=seed, epochs=epochs, batch=batch, lr=lr, augment=_dihedral, codes=8,
        loss_fn=nn.BCEWithLogitsLoss(), started=started, log=log)
    return net, {"train_samples": samples, "epochs": epochs, "batch": batch, "lr": lr,
                 "train_seconds": round(time.perf_counter() - started, 1)}


def export_onnx(net: CrossingNet, path: Path, spec: CropSpec, *, channels: int = 2,
                output: str = "p_crossing") -> bytes:
    """Export (crops (N, channels, S, S) float32 -> `output` (N,)) and return the file's bytes."""
    import io

    model = Probability(net).eval()
    example = torch.zeros(1, channels, spec.size, spec.size)
    buffer = io.BytesIO()
    torch.onnx.export(model, (example,), buffer, input_names=["crops"], output_names=[output],
                      dynamic_axes={"crops": {0: "n"}, output: {0: "n"}}, opset_version=17,
                      dynamo=False)
    data = buffer.getvalue()
    atomic_write_bytes(path, data)
    return data


def base_meta(command: str, options: dict, spec, net: nn.Module, data: bytes, facts: dict) -> dict:
    """Metadata of an exported model: the command and options that made it (seed first),
    its crop geometry, size, hash and training facts."""
    return {
        "seed": options["seed"],
        "command": f"onestroke {command} " + " ".join(f"--{k} {v}" for k, v in options.items()),
        "crop": spec.to_dict(),
        "parameters": sum(p.numel() for p in net.parameters()),
        "bytes": len(data),
        "sha256": hashlib.sha256(data).hexdigest(),
        "training": facts,
    }


def model_card(meta: dict) -> str:
    """The Markdown model card from the metadata."""
    v = meta["validation"]
    rows = "\n".join(f"| {name.replace('_', ' ')} | {v['per_subtype'][name]['n']} | "
                     f"{v['per_subtype'][name]['accuracy']:.4f} |" for name in SUBTYPES)
    return f"""# Crossing-vs-touching classifier (`crossing_cnn.onnx`)

A small CNN that tells, at a degree-4 node of a single-line drawing's medial axis,
whether the two strokes cross (go straight over) or touch and turn back.

- Input `crops`: (N, 2, {meta['crop']['size']}, {meta['crop']['size']}) float32, the near ({meta['crop']['near_span']} w)
  and far ({meta['crop']['far_span']} w) crops of `vectorize.junctions.junction_crop.crop_junctions`, ink = 1, paper = 0.
- Output `p_crossing`: (N,) probability of a crossing.
- Parameters: {meta['parameters']:,}; file size {meta['bytes']:,} bytes; sha256 `{meta['sha256']}`.
- Training data: {meta['training']['train_samples']:,} synthetic crops (`vectorize.training.synth`, seed
  {meta['seed']}), {meta['training']['epochs']} epochs, batch {meta['training']['batch']}, AdamW with a
  one-cycle learning rate up to {meta['training']['lr']}, random 90-degree turns and flips;
  {meta['training']['train_seconds']:.0f} s on {meta['training']['cpu']}.
- Command: `{meta['command']}`

## Validation

{v['n']:,} fresh crops (seed {v['seed']}), 8-fold dihedral test-time augmentation, onnxruntime:

| | crops | accuracy |
|---|---|---|
| overall | {v['n']} | {v['accuracy']:.4f} |
| crossings | {v['per_class']['crossing']['n']} | {v['per_class']['crossing']['accuracy']:.4f} |
| touchings | {v['per_class']['touching']['n']} | {v['per_class']['touching']['accuracy']:.4f} |
{rows}

Shallow crossings are those under 15 degrees; near touches leave a gap of 0.15-0.9
stroke widths that the ink still bridges.
"""


DEFAULT_OUT = Path(__file__).parents[1] / "models" / "crossing_cnn.onnx"
MODEL_FILES = (".json", ".md")  # written beside the model, with its own suffix replaced


@contextlib.contextmanager
def staged_model(out: Path) -> Iterator[Path]:
    """A path, in a hidden folder beside `out`, to export, validate and describe a model at.

    When the block ends, the model and its .json and .md replace `out`'s together; if it
    fails (Ctrl-C during hours of training or the validation after it), none of them does,
    so a model and metadata that disagree (the vectorizer refuses such a model) never appear.
    """
    out.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix=f".{out.name}.", dir=out.parent) as folder:
        staged = Path(folder) / out.name
        yield staged
        with all_or_nothing():
            atomic_write_bytes(out, staged.read_bytes())
            for suffix in MODEL_FILES:
                atomic_write_bytes(out.with_suffix(suffix), staged.with_suffix(suffix).read_bytes())


def train_and_export(*, seed: int = 0, samples: int = 36_000, epochs: int = 8, batch: int = 128,
                     lr: float = 4e-3, validation: int = 5_000, workers: int = 1,
                     out: Path = DEFAULT_OUT,
                     log: Callable[[str], None] = lambda line: None) -> dict:
    """Train, export `out` (.onnx) with its metadata (.json) and model card (.md), validate
    on `validation` fresh crops of another seed; returns the metadata (validation included).
    `log` receives the training's progress lines."""
    spec = CropSpec()
    net, facts = train(seed=seed, samples=samples, epochs=epochs, batch=batch, lr=lr, workers=workers,
                       log=log)
    facts["cpu"] = f"{os.cpu_count()} CPU cores"
    with staged_model(Path(out)) as staged:
        data = export_onnx(net, staged, spec)
        measured = evaluate_onnx(staged, count=validation, seed=seed + VALIDATION_SEED_OFFSET, workers=workers)
        meta = base_meta("train-classifier", {"seed": seed, "samples": samples, "epochs": epochs, "batch": batch,
                                              "lr": lr, "validation": validation}, spec, net, data, facts)
        meta["validation"] = measured
        atomic_write_text(staged.with_suffix(".json"), json.dumps(meta, indent=2) + "\n")
        atomic_write_text(staged.with_suffix(".md"), model_card(meta))
    return meta

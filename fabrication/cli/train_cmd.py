"""`onestroke train-classifier` and `onestroke validate-classifier`: the crossing CNN.

Training needs the `train` extra (PyTorch); validation runs the exported model with
onnxruntime only. Both print their figures as JSON on stdout.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import click

from onestroke.errors import InputError

WORKERS = os.cpu_count() or 1


@click.command("train-classifier")
@click.option("--seed", type=int, default=0, show_default=True, help="Seed of data, initialisation and batch order.")
@click.option("--samples", type=int, default=36_000, show_default=True, help="Synthetic training crops.")
@click.option("--epochs", type=int, default=8, show_default=True)
@click.option("--batch", type=int, default=128, show_default=True)
@click.option("--lr", type=float, default=4e-3, show_default=True, help="Learning rate.")
@click.option("--validation", type=int, default=5_000, show_default=True,
              help="Fresh crops (another seed) measured after export.")
@click.option("--workers", type=int, default=WORKERS, show_default=True, help="Processes making crops.")
@click.option("--out", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="ONNX file to write (its .json and .md beside it); default: the shipped model.")
def train_classifier(seed: int, samples: int, epochs: int, batch: int, lr: float, validation: int,
                     workers: int, out: Path | None) -> None:
    """Train the crossing-vs-touching CNN on CPU, reproducibly from --seed, and export it."""
    try:
        from vectorize.training.train import DEFAULT_OUT, train_and_export
    except ImportError as error:
        raise InputError(f"training needs PyTorch ({error.name} is missing): pip install -e '.[train]'") from None
    meta = train_and_export(seed=seed, samples=samples, epochs=epochs, batch=batch, lr=lr,
                            validation=validation, workers=workers, out=out or DEFAULT_OUT,
                            log=lambda line: click.echo(line, err=True))
    click.echo(json.dumps(meta["validation"], indent=2))


@click.command("validate-classifier")
@click.option("--seed", type=int, default=1000, show_default=True, help="Seed of the fresh crops.")
@click.option("--count", type=int, default=5000, show_default=True, help="Crops to measure.")
@click.option("--workers", type=int, default=WORKERS, show_default=True, help="Processes making crops.")
@click.option("--model", type=click.Path(exists=True, dir_okay=False, path_type=Path), default=None,
              help="ONNX model; default: the shipped one.")
def validate_classifier(seed: int, count: int, workers: int, model: Path | None) -> None:
    """Accuracy of the CNN on freshly generated crops (onnxruntime, 8-fold augmentation)."""
    from vectorize.cnn_classifier import DEFAULT_MODEL
    from vectorize.training.validate import evaluate_onnx

    click.echo(json.dumps(evaluate_onnx(model or DEFAULT_MODEL, count=count, seed=seed, workers=workers),
                          indent=2))

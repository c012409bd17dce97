"""`onestroke train-classifier`, `validate-classifier` and `train-pass-scorer`: the CNNs.

Training needs the `train` extra (PyTorch); validation runs the exported model with
onnxruntime only. Both print their figures as JSON on stdout.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import click

from fabrication.cli.options import InputFile, Integer, Number, output_option
from onestroke.errors import InputError
from onestroke.ranges import Range

WORKERS = os.cpu_count() or 1
# Ranges of the training commands' options (the training code takes what they allow).
SEED = Range(0, 2**32 - 1, name="--seed", integer=True)
EPOCHS = Range(1, 1000, name="--epochs", integer=True)
BATCH = Range(1, 65536, name="--batch", integer=True)
LEARNING_RATE = Range(0.0, 10.0, name="--lr", low_open=True)
PROCESSES = Range(1, 256, name="--workers", integer=True)
CROPS = Range(1, 10_000_000, name="--count", integer=True)
SAMPLES = Range(100, 10_000_000, name="--samples", integer=True)
SCENES = Range(8, 1_000_000, name="--scenes", integer=True)
SCENE_CHECKS = Range(1, 1_000_000, name="--validation", integer=True)
DEFAULT_NAME = "crossing_cnn.onnx"  # in the current folder: never the shipped model by default


def _training_options(*, epochs: int, what: str, default_name: str):
    """--seed, --epochs, --batch, --lr, --workers and --out, shared by both training commands."""
    options = [
        click.option("--seed", type=Integer(SEED), default=0, show_default=True,
                     help=f"Seed of {what}, initialisation and batch order."),
        click.option("--epochs", type=Integer(EPOCHS), default=epochs, show_default=True, help=f"Epochs, {EPOCHS.span()}."),
        click.option("--batch", type=Integer(BATCH), default=128, show_default=True,
                     help=f"Batch size, {BATCH.span()}."),
        click.option("--lr", type=Number(LEARNING_RATE), default=4e-3, show_default=True,
                     help=f"Learning rate, {LEARNING_RATE.span()}."),
        click.option("--workers", type=Integer(PROCESSES), default=WORKERS, show_default=True,
                     help="Processes making crops."),
        output_option(".onnx", flags=("--out",), required=False,
                      help=f"ONNX file to write (its .json and .md beside it) [default: {default_name} in the "
                           "current folder; the shipped model is replaced only when named explicitly]."),
    ]

    def apply(command):
        for option in reversed(options):
            command = option(command)
        return command
    return apply


@click.command("train-classifier")
@_training_options(epochs=8, what="data", default_name=DEFAULT_NAME)
@click.option("--samples", type=Integer(SAMPLES), default=36_000, show_default=True,
              help="Synthetic training crops, 100-10,000,000.")
@click.option("--validation", type=Integer(CROPS), default=5_000, show_default=True,
              help="Fresh crops (another seed) measured after export.")
def train_classifier(seed: int, samples: int, epochs: int, batch: int, lr: float, validation: int,
                     workers: int, out: str | None) -> None:
    """Train the crossing-vs-touching CNN on CPU, reproducibly from --seed, and export it."""
    from onestroke.atomic import check_writable

    out_path = Path(out or DEFAULT_NAME)
    check_writable(out_path)
    try:
        from vectorize.training.train import train_and_export
    except ImportError as error:
        raise InputError(f"training needs PyTorch ({error.name} is missing): pip install -e '.[train]'") from None
    meta = train_and_export(seed=seed, samples=samples, epochs=epochs, batch=batch, lr=lr,
                            validation=validation, workers=workers, out=out_path,
                            log=lambda line: click.echo(line, err=True))
    click.echo(json.dumps(meta["validation"], indent=2))


@click.command("validate-classifier")
@click.option("--seed", type=Integer(SEED), default=1000, show_default=True, help="Seed of the fresh crops.")
@click.option("--count", type=Integer(CROPS), default=5000, show_default=True, help="Crops to measure.")
@click.option("--workers", type=Integer(PROCESSES), default=WORKERS, show_default=True, help="Processes making crops.")
@click.option("--model", type=InputFile(), default=None, help="ONNX model; default: the shipped one.")
def validate_classifier(seed: int, count: int, workers: int, model: Path | None) -> None:
    """Accuracy of the CNN on freshly generated crops (onnxruntime, 8-fold augmentation)."""
    from vectorize.junctions.cnn_classifier import DEFAULT_MODEL
    from vectorize.training.validate import evaluate_onnx

    click.echo(json.dumps(evaluate_onnx(model or DEFAULT_MODEL, count=count, seed=seed, workers=workers),
                          indent=2))


@click.command("train-pass-scorer")
@_training_options(epochs=4, what="scenes", default_name="pass_cnn.onnx")
@click.option("--scenes", type=Integer(SCENES), default=1000, show_default=True,
              help="Synthetic triple points to train on (15 candidate passes each), 8-1,000,000.")
@click.option("--calibration", type=Integer(SCENES), default=200, show_default=True,
              help="Fresh scenes (seed + 500) that fit the image/continuation weights.")
@click.option("--validation", type=Integer(SCENE_CHECKS), default=200, show_default=True,
              help="Fresh scenes (seed + 1000) whose pairing accuracy is measured after export.")
def train_pass_scorer(seed: int, scenes: int, epochs: int, batch: int, lr: float, calibration: int,
                      validation: int, workers: int, out: str | None) -> None:
    """Train the pass scorer of triple points on CPU, reproducibly from --seed, and export it."""
    from onestroke.atomic import check_writable

    out_path = Path(out or "pass_cnn.onnx")
    check_writable(out_path)
    try:
        from vectorize.training.train_pass import train_and_export_pass
    except ImportError as error:
        raise InputError(f"training needs PyTorch ({error.name} is missing): pip install -e '.[train]'") from None
    meta = train_and_export_pass(seed=seed, scenes=scenes, epochs=epochs, batch=batch, lr=lr,
                                 calibration=calibration, validation=validation, workers=workers, out=out_path,
                                 log=lambda line: click.echo(line, err=True))
    click.echo(json.dumps({"combine": meta["combine"], "validation": meta["validation"]}, indent=2))

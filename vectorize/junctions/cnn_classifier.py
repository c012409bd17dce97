"""The shipped CNN that tells crossings from touchings, run with onnxruntime only.

All junctions of a drawing go through the network in ONE batched call, each as its 8
dihedral copies (rotations by 90 degrees and flips are exact symmetries of the question):
p_crossing is the mean probability over the copies, confidence the share of copies that
vote with the majority. No randomness is involved, so results are reproducible.
"""

from __future__ import annotations

import hashlib
import json
import os
import threading
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from onestroke.errors import VectorizeError
from vectorize.junctions.intersections import Junction, JunctionVerdict
from vectorize.junctions.junction_crop import CropSpec, crop_junctions, crop_own_ink, dihedral_copies

DEFAULT_MODEL = Path(__file__).parents[1] / "models" / "crossing_cnn.onnx"

# One onnxruntime session per model file and process: the pipeline makes a classifier per
# vectorize call, and building a session costs more than classifying a whole drawing.
_SESSIONS: dict[tuple[str, str], object] = {}
_SESSIONS_LOCK = threading.Lock()


def model_meta(model_path: Path, *, check_hash: bool = True) -> dict:
    """The metadata (``<model>.json``) of a shipped ONNX model; with `check_hash`, the
    file's sha256 must match it. Raises `VectorizeError` when the model is missing or damaged."""
    if not model_path.is_file():
        raise VectorizeError(f"classifier model {str(model_path)!r} is missing; "
                             "reinstall onestroke or use --classifier geometric")
    meta_path = model_path.with_suffix(".json")
    meta = json.loads(meta_path.read_text()) if meta_path.is_file() else {}
    if check_hash and meta.get("sha256"):
        if hashlib.sha256(model_path.read_bytes()).hexdigest() != meta["sha256"]:
            raise VectorizeError(f"classifier model {str(model_path)!r} does not match its "
                                 "metadata (sha256 differs): the file is damaged")
    return meta


def onnx_session(model_path: Path, sha256: str):
    """The process's onnxruntime session for a model file (CPU, one thread), made once."""
    key = (str(Path(model_path).resolve()), sha256)
    with _SESSIONS_LOCK:
        if key not in _SESSIONS:
            from onestroke.lasting import import_later

            onnxruntime = import_later("onnxruntime")  # for good in a command (onestroke/lasting.py)

            options = onnxruntime.SessionOptions()
            # One thread: the same float sums in the same order on every run, and a batch
            # of a few dozen crops gains little from more.
            options.intra_op_num_threads = 1
            options.inter_op_num_threads = 1
            _SESSIONS[key] = onnxruntime.InferenceSession(str(model_path), options,
                                                          providers=["CPUExecutionProvider"])
        return _SESSIONS[key]


class CnnClassifier:
    """Crossing-vs-touching classifier backed by an ONNX model (default: the shipped one).

    The model's metadata (``<model>.json``: crop geometry, sha256) is read on creation and,
    unless `check_hash` is False, the file's hash must match it.
    """

    name = "cnn"

    def __init__(self, model_path: str | os.PathLike | None = None, *, check_hash: bool = True) -> None:
        self.model_path = Path(model_path) if model_path is not None else DEFAULT_MODEL
        self.meta = model_meta(self.model_path, check_hash=check_hash)
        self.spec = CropSpec(**self.meta["crop"]) if "crop" in self.meta else CropSpec()
        self._session = None

    @property
    def session(self):
        """The onnxruntime session, created on first use (CPU, deterministic threads)."""
        if self._session is None:
            self._session = onnx_session(self.model_path, self.meta.get("sha256", ""))
        return self._session

    def predict_crops(self, crops: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """crops (N, 2, S, S) float32 -> (mean p_crossing (N,), vote share (N,)) over 8 copies."""
        crops = np.asarray(crops, dtype=np.float32)
        n = len(crops)
        if n == 0:
            return np.zeros(0), np.zeros(0)
        copies = dihedral_copies(crops).reshape(8 * n, *crops.shape[1:])
        p = self.session.run(["p_crossing"], {"crops": copies})[0].reshape(8, n).astype(np.float64)
        mean = p.mean(axis=0)
        votes = (p >= 0.5).mean(axis=0)
        share = np.where(mean >= 0.5, votes, 1.0 - votes)
        return mean, np.maximum(share, 0.5)

    def classify(self, gray: np.ndarray, junctions: Sequence[Junction], stroke_width: float, *,
                 whole_image: bool = True) -> list[JunctionVerdict]:
        """One verdict per junction; gray (H, W) float32 in [0, 1], 1 = paper.

        A junction with `ink` is read from an image holding that ink alone
        (`junction_crop.crop_own_ink`): in crowded context (cursive letters beside a
        crossing) the whole image misleads the model. With `whole_image` it is read whole as
        well, for the confidence only: cut to a few widths, a clean crossing's branches get
        fewer votes (5-7 of 8 on examples/loops.png, where the whole image gets 8), so where
        the two readings agree the confidence is the larger vote share. Without it the
        confidence is the own ink's vote share, and the network reads half as many crops;
        p_crossing is the same either way. A junction without `ink` is read whole.
        """
        if not junctions:
            return []
        centers = np.array([j.crop_center for j in junctions], dtype=float)
        own = [i for i, j in enumerate(junctions) if j.ink is not None]
        whole = list(range(len(junctions))) if whole_image else [i for i, j in enumerate(junctions) if j.ink is None]
        parts = [crop_junctions(gray, centers[whole], stroke_width, self.spec)] if whole else []
        if own:
            parts.append(crop_own_ink(gray, centers[own], [junctions[i].ink for i in own], stroke_width, self.spec))
        mean, share = self.predict_crops(np.concatenate(parts))
        p, confidence = np.zeros(len(junctions)), np.zeros(len(junctions))
        p[whole], confidence[whole] = mean[:len(whole)], share[:len(whole)]
        for k, i in enumerate(own):
            m, s = mean[len(whole) + k], share[len(whole) + k]
            agree = whole_image and (m >= 0.5) == (p[i] >= 0.5)
            p[i], confidence[i] = m, max(s, confidence[i]) if agree else s
        return [JunctionVerdict(p_crossing=float(m), confidence=float(s)) for m, s in zip(p, confidence)]

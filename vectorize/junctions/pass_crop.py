"""Image crops of a candidate pass through a triple point, the input of the pass scorer.

At a node where three passes cross (`vectorize.axis.clusters`) six branch feet leave one spot,
and the pairing of the feet decides where the pen goes. The pass scorer
(`vectorize.junctions.pass_scorer`) judges one candidate pass, feet a and b, from a crop centred on
the node and rotated so that the candidate runs along +x (foot a leaving to the left, foot
b to the right). The same function cuts the crops at run time and in the synthetic
training data (`vectorize.training.triple_synth`).

Four channels of `PassCropSpec.size` px, all scaled to the stroke width w:

- 0, 2: the ink, `near_span` w and `far_span` w wide (normalised as the crossing crops:
  0 = paper, 1 = the darkest ink near the node);
- 1, 3: the candidate pass at the same two scales: two rays from the centre along the two
  feet's measured directions (what continuation sees), so the network is told which ink
  to follow and judges whether the pen went on along it.

Mirroring across the x axis and swapping the two feet (mirroring across y) are exact
symmetries of the question: test-time augmentation uses the 4 copies.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from vectorize.junctions.junction_crop import _sample_filtered, _unit_grid, checked_crop_input


@dataclass(frozen=True, kw_only=True)
class PassCropSpec:
    """Geometry of the pass crops; stored in the model's metadata and checked on load.

    size: side of each crop in px; near_span, far_span: crop sides in stroke widths;
    ray_sigma: half-width of a drawn ray, in crop px.
    """

    size: int = 32
    near_span: float = 10.0
    far_span: float = 24.0
    ray_sigma: float = 0.7

    def to_dict(self) -> dict:
        return asdict(self)


def _ray_image(grid: np.ndarray, direction: np.ndarray, sigma: float) -> np.ndarray:
    """Soft image of the ray from the crop centre along `direction`: grid (S, S, 2) crop px."""
    along = np.maximum(grid @ direction, 0.0)
    off = grid - along[..., None] * direction
    return np.exp(-0.5 * (np.linalg.norm(off, axis=-1) / sigma) ** 2)


def crop_passes(gray: np.ndarray, centers: np.ndarray, foot_a: np.ndarray, foot_b: np.ndarray,
                stroke_width: float, spec: PassCropSpec = PassCropSpec()) -> np.ndarray:
    """Crops of candidate passes.

    Parameters
    ----------
    gray : (H, W) float in [0, 1], 1 = paper (not thresholded).
    centers : (N, 2) node positions, x right, y down, px of `gray` (pixel centres at integers).
    foot_a, foot_b : (N, 2) unit tangents of the two feet, pointing away from the node.
    stroke_width : the drawing's stroke width in px (> 0).

    Returns
    -------
    (N, 4, size, size) float32: near ink, near pass, far ink, far pass.
    """
    gray, centers = checked_crop_input(gray, centers, stroke_width)
    foot_a = np.asarray(foot_a, dtype=float).reshape(-1, 2)
    foot_b = np.asarray(foot_b, dtype=float).reshape(-1, 2)
    n, s = len(centers), spec.size
    out = np.zeros((n, 4, s, s), dtype=np.float32)
    if n == 0:
        return out
    # The candidate's through direction, from foot a's side to foot b's, is the crop's +x.
    axis = foot_b - foot_a
    norm = np.linalg.norm(axis, axis=1, keepdims=True)
    fallback = np.stack([-foot_a[:, 1], foot_a[:, 0]], axis=1)  # feet along one line
    axis = np.where(norm > 1e-6, axis / np.maximum(norm, 1e-12), fallback)
    c, si = axis[:, 0, None, None], axis[:, 1, None, None]
    gx, gy = _unit_grid(s)
    grid = np.stack([gx, gy], axis=-1) * s  # crop px from the centre
    for ch, span in ((0, spec.near_span), (2, spec.far_span)):
        side = span * stroke_width
        ox, oy = gx * side, gy * side
        xs = centers[:, 0, None, None] + c * ox - si * oy
        ys = centers[:, 1, None, None] + si * ox + c * oy
        out[:, ch] = _sample_filtered(gray, xs.reshape(n, -1), ys.reshape(n, -1), side / s).reshape(n, s, s)
        for i in range(n):
            # The feet in the rotated frame (rotation by -angle of the axis).
            rot = np.array([[axis[i, 0], axis[i, 1]], [-axis[i, 1], axis[i, 0]]])
            out[i, ch + 1] = np.maximum(_ray_image(grid, rot @ foot_a[i], spec.ray_sigma),
                                        _ray_image(grid, rot @ foot_b[i], spec.ray_sigma))
    paper = np.percentile(out[:, 2], 75, axis=(1, 2))
    ink = np.percentile(out[:, 0], 2, axis=(1, 2))
    contrast = np.maximum(paper - ink, 0.05)
    for ch in (0, 2):
        out[:, ch] = np.clip((paper[:, None, None] - out[:, ch]) / contrast[:, None, None], 0.0, 1.0)
    return out


def mirror_copies(crops: np.ndarray) -> np.ndarray:
    """The 4 exact symmetries of each pass crop (mirror across x, swap the feet):
    (N, C, S, S) -> (4, N, C, S, S)."""
    return np.ascontiguousarray(np.stack([crops, crops[..., ::-1, :], crops[..., ::-1], crops[..., ::-1, ::-1]]))

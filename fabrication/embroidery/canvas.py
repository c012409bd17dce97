"""A small 2-D canvas in millimetres that saves as PNG (Pillow) or SVG, for previews.

Items are collected in mm (x right, y down) and drawn in order. PNG is drawn at twice the
size and downsampled for smooth lines. Files are written atomically.
"""

from __future__ import annotations

import io
import os
from dataclasses import dataclass, field

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from onestroke.atomic import atomic_write_bytes, atomic_write_text
from onestroke.errors import InputError

PREVIEW_SUFFIXES = (".png", ".svg")

# Anchors of the start-to-end gradient (blue, cyan, green, yellow, red, like the paper's
# figures): order along the curve reads as colour.
_ANCHORS = np.array([[48, 18, 160], [30, 120, 230], [20, 185, 140], [120, 205, 40],
                     [245, 190, 20], [235, 95, 20], [190, 20, 40]], dtype=float)
_SUPERSAMPLE = 2


def gradient(u: np.ndarray) -> np.ndarray:
    """Colours (N, 3) uint8 for positions u (N,) in [0, 1] along the start-to-end gradient."""
    u = np.clip(np.nan_to_num(np.asarray(u, dtype=float)), 0.0, 1.0) * (len(_ANCHORS) - 1)
    i = np.minimum(u.astype(int), len(_ANCHORS) - 2)
    f = (u - i)[:, None]
    return np.rint(_ANCHORS[i] * (1 - f) + _ANCHORS[i + 1] * f).astype(np.uint8)


def check_preview_path(path: str | os.PathLike) -> str:
    """The lower-case suffix of a preview path, or `InputError` if it is not .png / .svg."""
    suffix = os.path.splitext(str(path))[1].lower()
    if suffix not in PREVIEW_SUFFIXES:
        shown = f"'{suffix}'" if suffix else "no extension"
        raise InputError(f"cannot write a preview as {shown} ({str(path)!r}); use .png or .svg")
    return suffix


def _hex(rgb) -> str:
    return "#{:02x}{:02x}{:02x}".format(*(int(c) for c in rgb))


MAX_ASPECT = 8.0  # a preview at most 8 times as tall as it is wide (or as wide as tall)


@dataclass
class Canvas:
    """A `width` x `height` px picture of the mm box `view` = (xmin, ymin, xmax, ymax)."""

    width: int
    height: int
    view: tuple[float, float, float, float]
    background: tuple[int, int, int] = (250, 248, 243)
    items: list = field(default_factory=list)

    @classmethod
    def fitting(cls, view: tuple[float, float, float, float], width: int, **kw) -> "Canvas":
        """A canvas `width` px wide whose height keeps the aspect ratio of `view`, the short
        side of a view longer than MAX_ASPECT times its width widened about its centre (a
        0.01 mm line drawn 1000 px wide would otherwise be a picture 100 million px tall)."""
        x0, y0, x1, y1 = view
        w, h = max(x1 - x0, 1e-9), max(y1 - y0, 1e-9)
        if h > MAX_ASPECT * w:
            x0, x1, w = (x0 + x1 - h / MAX_ASPECT) / 2, (x0 + x1 + h / MAX_ASPECT) / 2, h / MAX_ASPECT
        elif w > MAX_ASPECT * h:
            y0, y1, h = (y0 + y1 - w / MAX_ASPECT) / 2, (y0 + y1 + w / MAX_ASPECT) / 2, w / MAX_ASPECT
        return cls(width=int(width), height=max(1, int(round(width * h / w))), view=(x0, y0, x1, y1), **kw)

    @property
    def scale(self) -> float:
        """Pixels per mm."""
        return self.width / max(self.view[2] - self.view[0], 1e-9)

    def px(self, points: np.ndarray) -> np.ndarray:
        """mm (..., 2) to px (..., 2)."""
        return (np.asarray(points, dtype=float) - np.array(self.view[:2])) * self.scale

    # -- items (all coordinates in mm, widths in mm unless said) --------------------
    def segments(self, a: np.ndarray, b: np.ndarray, colors: np.ndarray, width: float,
                 *, min_px: float = 1.0, opacity: float = 1.0, round_caps: bool = False) -> None:
        """Line segments a[i] -> b[i] (S, 2) with colours (S, 3). Below full `opacity`,
        segments sewn over each other darken, as layers of thread do. `round_caps`: round
        ends in PNG too (SVG lines always have them), so wide strokes join without notches."""
        self.items.append(("segments", self.px(a), self.px(b), np.asarray(colors, np.uint8),
                           max(width * self.scale, min_px), None, float(opacity), bool(round_caps)))

    def dashed(self, a: np.ndarray, b: np.ndarray, color, width: float, dash: float) -> None:
        """Dashed segments with dashes and gaps `dash` mm long."""
        self.items.append(("segments", self.px(a), self.px(b),
                           np.tile(np.asarray(color, np.uint8), (len(a), 1)),
                           max(width * self.scale, 1.0), max(dash * self.scale, 2.0), 1.0, False))

    def dots(self, points: np.ndarray, color, radius: float, *, min_px: float = 0.8) -> None:
        self.items.append(("dots", self.px(points), tuple(color), max(radius * self.scale, min_px)))

    def crosses(self, points: np.ndarray, color, size_px: float) -> None:
        self.items.append(("crosses", self.px(points), tuple(color), size_px))

    def rectangle(self, box: tuple[float, float, float, float], color, width_px: float) -> None:
        lo, hi = self.px(np.array(box[:2])), self.px(np.array(box[2:]))
        self.items.append(("rect", lo, hi, tuple(color), width_px))

    def text_box(self, lines: list[str], *, swatch=None, avoid: np.ndarray | None = None) -> None:
        """Lines of text in a light box in a corner; `swatch` an RGB shown beside it. The
        corner covering fewest of the points `avoid` (mm, (N, 2)) is used (top-left first)."""
        lines = list(lines)
        w, h = self._text_size(lines, swatch)
        corners = [(6.0, 6.0), (self.width - w - 6.0, 6.0), (6.0, self.height - h - 6.0),
                   (self.width - w - 6.0, self.height - h - 6.0)]
        origin = corners[0]
        if avoid is not None and len(avoid):
            p = self.px(avoid)
            covered = [int(np.count_nonzero((p[:, 0] >= x - 4) & (p[:, 0] <= x + w + 4)
                                            & (p[:, 1] >= y - 4) & (p[:, 1] <= y + h + 4)))
                       for x, y in corners]
            origin = corners[int(np.argmin(covered))]
        self.items.append(("text", lines, swatch, origin))

    def _text_size(self, lines: list[str], swatch) -> tuple[float, float]:
        """(width, height) px of the text box drawn by `text_box`."""
        font = ImageFont.load_default(size=self._font_size())
        boxes = [font.getbbox(line) for line in lines]
        line_h = max(b[3] - b[1] for b in boxes) + 4
        text_w = max(b[2] - b[0] for b in boxes)
        return text_w + 12 + (line_h if swatch is not None else 0), line_h * len(lines) + 12

    # -- output ---------------------------------------------------------------------
    def save(self, path: str | os.PathLike) -> None:
        """Write PNG or SVG by the extension of `path`, atomically."""
        suffix = check_preview_path(path)
        if suffix == ".png":
            buffer = io.BytesIO()
            self.to_image().save(buffer, format="PNG", optimize=False)
            atomic_write_bytes(path, buffer.getvalue())
        else:
            atomic_write_text(path, self.to_svg())

    def _font_size(self) -> int:
        return max(11, min(22, int(self.width / 60)))

    def to_image(self) -> Image.Image:
        k = _SUPERSAMPLE
        image = Image.new("RGB", (self.width * k, self.height * k), self.background)
        draw = ImageDraw.Draw(image)
        blend = ImageDraw.Draw(image, "RGBA")  # draws with alpha blending
        for item in self.items:
            kind = item[0]
            if kind == "segments":
                _, a, b, colors, width, dash, opacity, caps = item
                w = max(1, int(round(width * k)))
                if dash is not None:
                    a, b, colors = _dash_pieces(a, b, colors, dash)
                pen, alpha = (draw, ()) if opacity >= 1.0 else (blend, (int(round(opacity * 255)),))
                r = w / 2.0
                if not alpha or (w >= 2 and not (caps and w > 2)):
                    # translucent lines 1 px wide are the exception (PIL's polyline skips the
                    # shared end pixels that separate calls blend twice), and translucent caps
                    # (blends of rounded values depend on their order)
                    _draw_chains(pen, a * k, b * k, colors, w, r if caps and w > 2 else None, alpha)
                    continue
                for (x0, y0), (x1, y1), c in zip((a * k).tolist(), (b * k).tolist(), colors.tolist()):
                    fill = tuple(c) + alpha
                    pen.line((x0, y0, x1, y1), fill=fill, width=w)
                    if caps and w > 2:
                        pen.ellipse((x1 - r, y1 - r, x1 + r, y1 + r), fill=fill)
            elif kind == "dots":
                _, p, color, r = item
                r *= k
                for x, y in (p * k).tolist():
                    draw.ellipse((x - r, y - r, x + r, y + r), fill=color)
            elif kind == "crosses":
                _, p, color, size = item
                s = size * k / 2
                for x, y in (p * k).tolist():
                    draw.line((x - s, y - s, x + s, y + s), fill=color, width=2 * k)
                    draw.line((x - s, y + s, x + s, y - s), fill=color, width=2 * k)
            elif kind == "rect":
                _, lo, hi, color, width = item
                draw.rectangle((*(lo * k), *(hi * k)), outline=color, width=max(1, int(width * k)))
            elif kind == "text":
                _, lines, swatch, (ox, oy) = item
                w, h = self._text_size(lines, swatch)
                font = ImageFont.load_default(size=self._font_size() * k)
                line_h = (h - 12) / len(lines) * k
                x0, y0 = ox * k, oy * k
                draw.rectangle((x0, y0, x0 + w * k, y0 + h * k), fill=(255, 255, 255),
                               outline=(150, 150, 150), width=k)
                for j, line in enumerate(lines):
                    draw.text((x0 + 6 * k, y0 + 6 * k + j * line_h), line, fill=(20, 20, 20), font=font)
                if swatch is not None:
                    x = x0 + (w - 6) * k - line_h
                    draw.rectangle((x, y0 + 6 * k, x + line_h - 6 * k, y0 + line_h), fill=tuple(swatch),
                                   outline=(60, 60, 60), width=k)
        return image.resize((self.width, self.height), Image.LANCZOS)

    def to_svg(self) -> str:
        out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{self.width}" height="{self.height}" '
               f'viewBox="0 0 {self.width} {self.height}">',
               f'<rect width="100%" height="100%" fill="{_hex(self.background)}"/>']
        for item in self.items:
            kind = item[0]
            if kind == "segments":
                _, a, b, colors, width, dash, opacity, _caps = item
                dash_attr = f' stroke-dasharray="{dash:.1f} {dash:.1f}"' if dash is not None else ""
                # One path per distinct colour keeps the file small.
                keys = colors[:, 0].astype(np.int64) << 16 | colors[:, 1].astype(np.int64) << 8 | colors[:, 2]
                for key in np.unique(keys):
                    sel = keys == key
                    d = " ".join(f"M{x0:.2f} {y0:.2f}L{x1:.2f} {y1:.2f}"
                                 for (x0, y0), (x1, y1) in zip(a[sel].tolist(), b[sel].tolist()))
                    alpha = f' stroke-opacity="{opacity:.2f}"' if opacity < 1.0 else ""
                    out.append(f'<path d="{d}" fill="none" stroke="#{int(key):06x}" '
                               f'stroke-width="{width:.2f}" stroke-linecap="round"{dash_attr}{alpha}/>')
            elif kind == "dots":
                _, p, color, r = item
                d = " ".join(f"M{x:.2f} {y:.2f}h0" for x, y in p.tolist())
                out.append(f'<path d="{d}" stroke="{_hex(color)}" stroke-width="{2 * r:.2f}" '
                           'stroke-linecap="round"/>')
            elif kind == "crosses":
                _, p, color, size = item
                s = size / 2
                d = " ".join(f"M{x - s:.1f} {y - s:.1f}L{x + s:.1f} {y + s:.1f}M{x - s:.1f} {y + s:.1f}"
                             f"L{x + s:.1f} {y - s:.1f}" for x, y in p.tolist())
                out.append(f'<path d="{d}" stroke="{_hex(color)}" stroke-width="2"/>')
            elif kind == "rect":
                _, lo, hi, color, width = item
                out.append(f'<rect x="{lo[0]:.2f}" y="{lo[1]:.2f}" width="{hi[0] - lo[0]:.2f}" '
                           f'height="{hi[1] - lo[1]:.2f}" fill="none" stroke="{_hex(color)}" '
                           f'stroke-width="{width:.1f}"/>')
            elif kind == "text":
                _, lines, swatch, (ox, oy) = item
                w, h = self._text_size(lines, swatch)
                size = self._font_size()
                line_h = (h - 12) / len(lines)
                out.append(f'<rect x="{ox:.0f}" y="{oy:.0f}" width="{w:.0f}" height="{h:.0f}" '
                           'fill="white" stroke="#969696"/>')
                for j, line in enumerate(lines):
                    text = line.replace("&", "&amp;").replace("<", "&lt;")
                    out.append(f'<text x="{ox + 6:.0f}" y="{oy + 6 + size + j * line_h:.0f}" '
                               f'font-family="sans-serif" font-size="{size}" xml:space="preserve">{text}</text>')
                if swatch is not None:
                    out.append(f'<rect x="{ox + w - 6 - line_h:.0f}" y="{oy + 6:.0f}" width="{line_h - 6:.0f}" '
                               f'height="{line_h - 6:.0f}" fill="{_hex(swatch)}" stroke="#3c3c3c"/>')
        out.append("</svg>")
        return "\n".join(out) + "\n"


def _draw_chains(pen, a: np.ndarray, b: np.ndarray, colors: np.ndarray, width: int, cap: float | None,
                 alpha: tuple = ()) -> None:
    """Segments a[i] -> b[i] (px) as few polylines as possible: a chain of segments that
    meet end to start in one colour is one call. PIL draws a polyline of width 2 or more
    segment by segment (and opaque paint twice is paint once), so the pixels are those of
    one call per segment (a design of 300,000 stitches would otherwise make 300,000
    calls). `cap`: radius of a round dot at each segment's end, or None; `alpha`: () or
    (opacity 0-255,) for a translucent pen."""
    if not len(a):
        return
    joined = np.all(a[1:] == b[:-1], axis=1) & np.all(colors[1:] == colors[:-1], axis=1)
    starts = np.flatnonzero(np.r_[True, ~joined]).tolist() + [len(a)]
    a_list, b_list, c_list = a.tolist(), b.tolist(), colors.tolist()
    for s, e in zip(starts[:-1], starts[1:]):
        fill = tuple(c_list[s]) + alpha
        pen.line([tuple(a_list[s])] + [tuple(p) for p in b_list[s:e]], fill=fill, width=width)
        if cap is not None:
            for x1, y1 in b_list[s:e]:
                pen.ellipse((x1 - cap, y1 - cap, x1 + cap, y1 + cap), fill=fill)


def _dash_pieces(a: np.ndarray, b: np.ndarray, colors: np.ndarray, dash: float):
    """Cut each segment into dashes `dash` px long separated by equal gaps."""
    pieces_a, pieces_b, pieces_c = [], [], []
    for p, q, c in zip(a, b, colors):
        length = float(np.hypot(*(q - p)))
        n = max(1, int(length // (2 * dash)) + 1)
        starts = np.arange(n) * 2 * dash
        ends = np.minimum(starts + dash, length)
        u0, u1 = starts / max(length, 1e-9), ends / max(length, 1e-9)
        pieces_a.append(p + (q - p) * u0[:, None])
        pieces_b.append(p + (q - p) * u1[:, None])
        pieces_c.append(np.tile(c, (n, 1)))
    if not pieces_a:
        return a, b, colors
    return np.concatenate(pieces_a), np.concatenate(pieces_b), np.concatenate(pieces_c)

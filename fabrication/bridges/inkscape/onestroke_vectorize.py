#!/usr/bin/env python3
"""Inkscape extension "Single-line vectorize": the selected bitmap (embedded or linked) or filled
outline path becomes onestroke's ordered curve, at the same place and size.

This script runs under Inkscape's own Python with inkex, not in onestroke's environment: it
hands the bitmap (or the outline, as a small SVG) to the installed `onestroke vectorize`, reads
the SVG that writes, and puts its paths into the document with inkex, moved from the input's
pixels onto the image (x, y, width, height, preserveAspectRatio and transform). The command is
the Python recorded by `onestroke inkscape install` next to this file (onestroke_vectorize.json),
the ONESTROKE_PYTHON environment variable, or an `onestroke` on PATH. Every failure reaches
Inkscape's message box as one line (the CLI's own message), never a traceback.
"""

import base64
import io
import json
import math
import os
import shutil
import subprocess
import tempfile
import urllib.parse

import inkex
from inkex.transforms import Transform
from lxml import etree

SETTINGS = "onestroke_vectorize.json"  # {"python": ...}, written by `onestroke inkscape install`
INKSTITCH = "http://inkstitch.org/namespace"
SUFFIXES = {"image/png": ".png", "image/jpeg": ".jpg", "image/jpg": ".jpg", "image/gif": ".gif",
            "image/bmp": ".bmp", "image/tiff": ".tif", "image/webp": ".webp"}
ALIGN = {"min": 0.0, "mid": 0.5, "max": 1.0}


def onestroke_command(folder):
    """The command line that runs onestroke, or AbortExtension saying what is missing."""
    python = os.environ.get("ONESTROKE_PYTHON")
    settings = os.path.join(folder, SETTINGS)
    if not python and os.path.isfile(settings):
        try:
            with open(settings, encoding="utf-8") as handle:
                python = json.load(handle)["python"]
        except (OSError, ValueError, KeyError, TypeError):
            raise inkex.AbortExtension(f"onestroke: {settings} is damaged; run 'onestroke inkscape install' "
                                       "again") from None
    if python:
        if os.path.isfile(python) and os.access(python, os.X_OK):
            return [python, "-m", "fabrication.cli"]
        raise inkex.AbortExtension(f"onestroke: the Python it was installed with ({python}) is gone; run "
                                   "'onestroke inkscape install' again from the environment that has onestroke")
    found = shutil.which("onestroke")
    if found:
        return [found]
    raise inkex.AbortExtension("onestroke: cannot find onestroke (no onestroke_vectorize.json beside this "
                               "extension, no ONESTROKE_PYTHON, no 'onestroke' on PATH); run "
                               "'onestroke inkscape install' from the environment where onestroke is installed")


def run_onestroke(command, arguments):
    """Run onestroke; its one-line error message becomes the extension's."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    try:
        done = subprocess.run(command + arguments, capture_output=True, text=True, env=env)
    except OSError as error:
        raise inkex.AbortExtension(f"onestroke: cannot run {command[0]}: {error.strerror}") from None
    if done.returncode != 0:
        lines = [line for line in done.stderr.splitlines() if line.strip()]
        message = next((line for line in reversed(lines) if line.startswith("error:")), lines[-1] if lines else
                       f"onestroke stopped with exit code {done.returncode}")
        raise inkex.AbortExtension(f"onestroke {message}")


def own_transform(element):
    """The element's own transform attribute, read without inkex's `transform` property
    (which writes the attribute back as a rounded matrix)."""
    return Transform(element.get("transform"))


def aspect_box(ratio, box, size):
    """(scale x, scale y, offset x, offset y) mapping an image of `size` (w, h) px onto
    `box` (x, y, w, h) under a preserveAspectRatio value."""
    x, y, w, h = box
    sx, sy = w / size[0], h / size[1]
    words = (ratio or "xMidYMid meet").split()
    if words and words[0] == "defer":
        words = words[1:]
    align = words[0] if words else "xMidYMid"
    if align == "none":
        return sx, sy, x, y
    scale = max(sx, sy) if len(words) > 1 and words[1] == "slice" else min(sx, sy)
    ax, ay = ALIGN.get(align[1:4].lower(), 0.5), ALIGN.get(align[5:8].lower(), 0.5)
    return scale, scale, x + (w - size[0] * scale) * ax, y + (h - size[1] * scale) * ay


class SingleLineVectorize(inkex.EffectExtension):
    """Extensions > onestroke > Single-line vectorize."""

    def add_arguments(self, pars):
        pars.add_argument("--tab", default="options")
        pars.add_argument("--threshold", type=float, default=0.0)
        pars.add_argument("--blur", type=float, default=0.0)
        pars.add_argument("--multi", type=inkex.Boolean, default=False)
        pars.add_argument("--classifier", default="cnn")
        pars.add_argument("--keep", type=inkex.Boolean, default=True)
        pars.add_argument("--inkstitch", default="none")

    def effect(self):
        chosen = [e for e in self.svg.selection.values() if isinstance(e, (inkex.Image, inkex.ShapeElement))
                  and not isinstance(e, (inkex.Group, inkex.TextElement))]
        if not chosen:
            raise inkex.AbortExtension("onestroke: select a bitmap or a filled outline path first")
        command = onestroke_command(self.ext_path())
        with tempfile.TemporaryDirectory(prefix="onestroke-") as folder:
            for element in chosen:
                try:
                    self.vectorize(element, command, folder)
                except inkex.AbortExtension:
                    raise
                except Exception as error:  # noqa: BLE001 - one line in the message box, never a traceback
                    raise inkex.AbortExtension(f"onestroke: internal error ({type(error).__name__}: {error}); "
                                               "please report it with the drawing") from None

    # -- inputs ----------------------------------------------------------------------------
    def image_source(self, image, folder):
        """A file holding the image's pixels: the embedded data decoded, or the linked file."""
        href = image.get("xlink:href") or image.get("href") or ""
        if href.startswith("data:"):
            header, _, data = href.partition(",")
            mime = header[5:].split(";")[0].strip().lower()
            if ";base64" not in header:
                raise inkex.AbortExtension("onestroke: the embedded image is not base64 data")
            path = os.path.join(folder, f"{image.get_id()}{SUFFIXES.get(mime, '.png')}")
            with open(path, "wb") as handle:
                handle.write(base64.b64decode(data))
            return path
        if href.startswith("file:"):
            path = urllib.parse.unquote(urllib.parse.urlparse(href).path)
        else:
            path = self.absolute_href(urllib.parse.unquote(href))
        if not os.path.isfile(path):
            raise inkex.AbortExtension(f"onestroke: the linked image {path} does not exist")
        return path

    def outline_source(self, shape, folder):
        """A small SVG holding the outline alone, in its parent's units: the element's own
        path data and transform as they are, so onestroke reads the rings it would read in
        the document itself."""
        if shape.specified_style().get("fill", "#000000") == "none":  # SVG fills black by default
            raise inkex.AbortExtension(f"onestroke: {shape.get_id()} is not filled; select a bitmap or a "
                                       "filled outline path")
        box = shape.path.transform(own_transform(shape)).bounding_box()
        if box is None or not (box.width > 0 and box.height > 0):
            raise inkex.AbortExtension(f"onestroke: {shape.get_id()} has no area to vectorize")
        page = inkex.load_svg(io.BytesIO(b'<svg xmlns="http://www.w3.org/2000/svg"/>')).getroot()
        # The page only has to be positive: onestroke fills the rings wherever they lie.
        width, height = max(box.right, box.width), max(box.bottom, box.height)
        page.set("width", f"{width:.6f}")
        page.set("height", f"{height:.6f}")
        page.set("viewBox", f"0 0 {width:.6f} {height:.6f}")
        outline = page.add(inkex.PathElement())
        outline.set("d", shape.get("d") if isinstance(shape, inkex.PathElement) else str(shape.path))
        if shape.get("transform"):
            outline.set("transform", shape.get("transform"))
        outline.set("style", "fill:#000000;stroke:none")
        file = os.path.join(folder, f"{shape.get_id()}.svg")
        with open(file, "wb") as handle:
            handle.write(page.tostring())
        return file

    # -- the work ----------------------------------------------------------------------------
    def vectorize(self, element, command, folder):
        is_image = isinstance(element, inkex.Image)
        source = self.image_source(element, folder) if is_image else self.outline_source(element, folder)
        output = os.path.join(folder, f"{element.get_id()}.onestroke.svg")
        arguments = ["vectorize", source, "-o", output, "--blur", f"{self.options.blur:g}",
                     "--classifier", self.options.classifier]
        if self.options.threshold > 0:
            arguments += ["--threshold", f"{self.options.threshold:g}"]
        if self.options.multi:
            arguments.append("--multi")
        if self.options.inkstitch != "none":
            arguments += ["--inkstitch", self.options.inkstitch]
        run_onestroke(command, arguments)
        result = inkex.load_svg(output).getroot()
        # onestroke writes the input's page: px, or mm at 96 dpi with --inkstitch.
        units = [float(v) for v in result.get("viewBox").split()]
        to_px = inkex.units.convert_unit(result.get("width"), "px") / units[2]
        if is_image:
            size = (units[2] * to_px, units[3] * to_px)
            box = (element.left, element.top, element.width or size[0], element.height or size[1])
            sx, sy, ox, oy = aspect_box(element.get("preserveAspectRatio"), box, size)
            place = own_transform(element) @ Transform(translate=(ox, oy)) @ Transform(scale=(sx * to_px, sy * to_px))
        else:
            place = Transform(scale=to_px)
        self.insert(element, result, place)
        if not self.options.keep:
            element.delete()

    def insert(self, element, result, place):
        """onestroke's paths, moved by `place`, next to `element` in drawing order."""
        (a, c, _), (b, d, _) = place.matrix[0], place.matrix[1]
        widen = math.sqrt(abs(a * d - b * c))  # how much a line's width grows under `place`
        group = next(result.iterchildren("{http://www.w3.org/2000/svg}g"))
        ink = float(group.get("stroke-width"))
        paint = "#000000" if isinstance(element, inkex.Image) else element.specified_style().get("fill", "#000000")
        made = []
        for index, source in enumerate(group.iterchildren("{http://www.w3.org/2000/svg}path")):
            path = inkex.PathElement.new(inkex.Path(source.get("d")).transform(place))
            width = float(source.get("stroke-width", ink)) * widen
            path.style = inkex.Style({"fill": "none", "stroke": source.get("stroke", paint),
                                      "stroke-width": f"{width:.6g}", "stroke-linecap": "round",
                                      "stroke-linejoin": "round"})
            for name, value in source.attrib.items():
                if name.startswith("{" + INKSTITCH + "}"):
                    path.set(name, value)
            path.label = f"onestroke {index + 1}"
            made.append(path)
        if len(made) == 1:
            element.addnext(made[0])
            made[0].set_random_id("onestroke")
        else:
            holder = inkex.Group()
            holder.label = f"onestroke ({len(made)} in drawing order)"
            element.addnext(holder)
            holder.set_random_id("onestroke")
            for path in made:
                holder.append(path)
                path.set_random_id("onestroke")
        # Declare the prefixes once on the root (lxml would invent ns0, ns1 on each path).
        prefixes = {"inkscape": inkex.NSS["inkscape"]}
        if any(name.startswith("{" + INKSTITCH + "}") for path in made for name in path.attrib):
            prefixes["inkstitch"] = INKSTITCH
        etree.cleanup_namespaces(self.document, top_nsmap=prefixes)


if __name__ == "__main__":
    SingleLineVectorize().run()

"""The SVG way in (not in the paper): an SVG file to strokes, or to ink for the raster stages.

In: an SVG file. Out: a `Drawing` of its stroked paths as they are (`svg_read`), and its
filled outlines as a gray image (`outline_svg`) that then goes through preprocessing and the
stages after it like a scan. `svg_source` reads the XML once, with bounds, for svgelements.
"""

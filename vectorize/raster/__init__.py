"""Stage 1, preprocessing (paper 3.1): a raster file to a gray working image and its ink outline.

In: an image file or array. Out: the gray working image (paper = 1), the ink threshold and
mask (`binarize`), and the outline rings (`outline`: (N, 2) px sub-pixel contours) that the
medial axis is built from. `image_io` loads files with clear errors; `scan_bands` shrinks a
huge scan a band of rows at a time.
"""

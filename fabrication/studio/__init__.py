"""The studio: the paper's interactive refinement (Section 4.4) and the make-it panels as a
local web page. A thin layer over the library, beside the CLI: `onestroke studio DRAWING`."""

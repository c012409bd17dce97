"""Laser engraving: toolpath planning, GRBL 1.1 G-code, job-time estimate, preview.

Modules, one job each: `toolpath` (placement to the machine frame, flattening, order),
`travel_order` (greedy + 2-opt stroke order), `arcs` (G2/G3 fitting), `gcode_write`,
`gcode_read` (parser and strict validator), `job_time` (GRBL planner model),
`raster_time` (raster-engraving comparison), `framing`, `preview`.
"""

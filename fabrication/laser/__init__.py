"""Laser engraving: toolpath planning, GRBL 1.1 G-code, job-time estimate, preview.

Modules, one job each: `toolpath` (placement to the machine frame, flattening, order),
`travel_order` (greedy + 2-opt stroke order), `arcs` (G2/G3 fitting), `gcode_write`,
`raster_time` (raster-engraving comparison), `preview`. What GRBL does with the G-code
(validation, arcs, planner, job time, framing) is asked of `machines/`.
"""

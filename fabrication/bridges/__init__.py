"""Bridges to the tools people already use: thin layers that translate and call the library.

- `inkstitch`: Ink/Stitch's stitch parameters on our SVG (`onestroke vectorize --inkstitch`);
- `inkscape/`: the Inkscape extension (its .inx and script run under Inkscape's own Python and
  call the installed `onestroke`), installed by `inkscape_install`;
- `vpype_plugin`: the `vpype onestroke` command (the `vpype` extra).
"""

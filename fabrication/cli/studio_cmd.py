"""`onestroke studio DRAWING`: refine the vectorization, preview and export on a local page."""

from __future__ import annotations

import threading
import time

import click

from fabrication.cli.common import console, done
from fabrication.cli.options import Integer
from onestroke.atomic import check_writable
from onestroke.errors import InputError
from onestroke.paths import check_distinct
from onestroke.ranges import Range

PORT = Range(0, 65535, name="--port", integer=True)


@click.command()
@click.argument("source", type=click.Path(path_type=str))
@click.option("--port", type=Integer(PORT), default=0, show_default=True,
              help=f"Port on 127.0.0.1, {PORT.span()} (0: any free port).")
@click.option("--no-browser", is_flag=True, help="Print the page's address instead of opening a browser.")
@click.option("--edits", "edits_path", default=None, type=click.Path(dir_okay=False, path_type=str),
              help="The edits file the page loads and saves [default: DRAWING.edits.json beside the drawing].")
@click.option("--profile", "profile_path", default=None, type=click.Path(dir_okay=False, path_type=str),
              help="Laser profile TOML: the laser panel's default machine profile (others can be "
                   "loaded in the page); default: built-in 400x400 mm.")
@click.option("--classifier", type=click.Choice(["cnn", "geometric"]), default="cnn", show_default=True,
              help="How crossings are told from touchings.")
def studio(source: str, port: int, no_browser: bool, edits_path: str | None, profile_path: str | None,
           classifier: str) -> None:
    """Open SOURCE in the studio: fix crossings, splits, merges, start and threshold; see the
    stitches and the laser toolpath; export and send. Ctrl-C stops it."""
    from fabrication.studio.server import StudioServer
    from fabrication.studio.session import StudioSession

    check_distinct(inputs=[("input", source), ("--profile", profile_path)], outputs=[("--edits file", edits_path)])
    session = StudioSession(source, edits_path=edits_path, profile=profile_path, classifier=classifier,
                            precompute=True)
    try:  # the page saves every edit there: a folder that cannot take it is refused now
        check_writable(session.edits_path)
    except InputError as error:
        raise InputError(f"{error}; the studio saves its edits there (give --edits FILE elsewhere)") from None
    if profile_path is not None:
        from machines.laser_profile import load_laser_profile

        load_laser_profile(profile_path)  # a bad profile is refused now, not on the page
    session.saved_edits()  # a malformed edits file is refused now too
    server = StudioServer(session, port=port)  # a port in use is refused now, before the work
    with console.status(f"vectorizing {session.drawing_path.name}"):
        session.vectorize(session.saved_edits())
    server.start()
    threading.Thread(target=session.warm, name="studio-warm", daemon=True).start()
    done(f"studio for {session.drawing_path.name} at {server.url}")
    console.print(f"edits are saved to {session.edits_path}; Ctrl-C stops the studio")
    if not no_browser and _graphical():
        import webbrowser

        webbrowser.open(server.url)
    try:
        while server.thread.is_alive():
            time.sleep(0.5)
    except KeyboardInterrupt:
        console.print("studio stopped")
    finally:
        if session.sender is not None and session.sender.running:
            # Never leave a laser running unattended: stop the job before the server goes.
            session.sender.abort()
            session.sender.wait(10.0)
        server.stop()
        session.stop_background()


def _graphical() -> bool:
    """Whether a browser window can open: on Linux without a display, webbrowser would
    start a text browser in this terminal instead; the printed address is enough there."""
    import os
    import sys

    if sys.platform.startswith("linux"):
        return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))
    return True

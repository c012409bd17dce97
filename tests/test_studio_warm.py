"""The studio session's background work: the neighbouring slider values computed while
idle give the answers of a fresh session, and a request stops that work."""

from __future__ import annotations

import os
import threading
from pathlib import Path

from fabrication.studio.session import StudioSession, Superseded
from tests.test_studio_edits import loop_png as drawing  # noqa: F401 (the same small drawing)
from vectorize.refine.edits import Edits


def test_neighbours_are_one_slider_step_away_in_the_direction_of_the_move(drawing):
    session = StudioSession(drawing, edits_path=Path(os.devnull), classifier="geometric")
    found = session.neighbours(Edits(threshold=0.45, blur=0.5), previous=Edits(threshold=0.46, blur=0.5))
    assert [(e.threshold, e.blur) for e in found] == [(0.44, 0.5), (0.46, 0.5), (0.45, 0.75), (0.45, 0.25)]
    # The automatic threshold has no slider position to step from; blur stays in 0..4.
    assert [(e.threshold, e.blur) for e in session.neighbours(Edits())] == [(None, 0.25)]
    # With the automatic threshold the slider sits at the threshold in use, on its 0.01 grid:
    # the first drag goes one step either way, unticking "automatic" sends the position.
    found = session.neighbours(Edits(), automatic=0.2255)
    assert [(e.threshold, e.blur) for e in found] == [(0.24, None), (0.22, None), (None, 0.25), (0.23, None)]


def test_the_first_slider_step_from_the_automatic_threshold_is_warmed(drawing):
    session = StudioSession(drawing, edits_path=Path(os.devnull), classifier="geometric", precompute=True)
    automatic = session.state(Edits())["report"]["threshold"]
    assert session.idle(120)
    fronts = len(session.cache.front)
    for value in (round(automatic, 2) + 0.01, round(automatic, 2) - 0.01, round(automatic, 2)):
        session.precompute = False  # (what this answer would warm is not the question)
        warmed = session.state(Edits(threshold=round(value, 2)))
        assert len(session.cache.front) == fronts, value  # answered from the cache
        fresh = StudioSession(drawing, edits_path=Path(os.devnull), classifier="geometric").state(
            Edits(threshold=round(value, 2)))
        for state in (warmed, fresh):
            state["report"].pop("seconds")
        assert warmed == fresh


def test_warmed_neighbours_answer_from_the_cache_with_a_fresh_sessions_state(drawing):
    session = StudioSession(drawing, edits_path=Path(os.devnull), classifier="geometric", precompute=True)
    edits = Edits(threshold=0.45)
    session.state(edits)
    assert session.idle(120)
    fronts = len(session.cache.front)
    for neighbour in session.neighbours(edits):
        warmed = session.state(neighbour)
        fresh = StudioSession(drawing, edits_path=Path(os.devnull), classifier="geometric").state(neighbour)
        for state in (warmed, fresh):
            state["report"].pop("seconds")  # how long this answer took: ~0 from the cache
        assert warmed == fresh, neighbour
        assert session.idle(120)
    # Each neighbour was computed once, in the background (then theirs were warmed too).
    assert fronts == 1 + len(session.neighbours(edits))


def test_a_request_stops_background_work_between_stages(drawing):
    session = StudioSession(drawing, edits_path=Path(os.devnull), classifier="geometric")
    started, release = threading.Event(), threading.Event()
    checks = []

    def slow_check():
        checks.append(1)
        if len(checks) == 2:  # the first stage boundary (after binarization) comes late
            started.set()
            release.wait(30)
        return False

    generation = session._generation
    errors = []

    def background():
        try:
            session.vectorize(Edits(threshold=0.41), generation=generation, superseded=slow_check)
        except Superseded as error:
            errors.append(error)

    worker = threading.Thread(target=background)
    worker.start()
    assert started.wait(60)
    answer = {}
    request = threading.Thread(target=lambda: answer.update(state=session.state(Edits(threshold=0.47))))
    request.start()
    while session._generation == generation:
        threading.Event().wait(0.01)
    release.set()
    worker.join(60)
    request.join(120)
    assert errors and len(checks) == 2  # stopped at the first stage boundary after the request
    assert answer["state"]["settings"]["threshold"] == 0.47
    assert not any(key[0] == 0.41 for key in session.cache.front)


def test_stopping_the_studio_stops_and_waits_for_background_work(drawing):
    """On Ctrl-C the command stops the background work and waits for it: a process that
    exits while a thread is inside native code aborts ("terminate called without an active
    exception", exit -6: it happened to `onestroke studio` about one run in four)."""
    session = StudioSession(drawing, edits_path=Path(os.devnull), classifier="geometric", precompute=True)
    session.state(Edits(threshold=0.45))  # starts the neighbours in the background
    warmer = session._warmer
    assert warmer is not None
    assert session.stop_background(60) and not warmer.is_alive()
    fronts = len(session.cache.front)
    session.state(Edits(threshold=0.46))  # no background work is started any more
    assert session.idle(0) and session._warmer is warmer and len(session.cache.front) <= fronts + 1

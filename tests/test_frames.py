"""When a viewer draws: once a change has settled, at most FRAME_RATE times a second, never for nothing."""

import math
import time

import pytest

import tutorial.app as app_module
from conftest import MODEL
from tutorial.app import App, FRAME_RATE
from tutorial.project import load_project


@pytest.fixture
def viewer(tmp_path, node):
    """A project without a simulator (a viewer's), headless, its frames' times in a list."""
    path = tmp_path / "viewer.yaml"
    path.write_text(f"name: frames\nmodels:\n  - name: Tank\n    file: {MODEL / 'tank.xml'}\n")
    app = App(load_project(path), node=node, headless=True, output=lambda r: None)
    app.open()
    frames = []
    app._draw = lambda: frames.append(time.monotonic())
    try:
        yield app, frames
    finally:
        app.close()


def move(app) -> None:
    app.bodies["Tank"].notify_kinematic_state_change()


def step_for(app, seconds: float, post=None) -> None:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if post is not None:
            app.loop.call_later(post, app, key=object())
        app.step(timeout=0.001)


def test_nothing_changed_nothing_drawn(viewer):
    app, frames = viewer
    step_for(app, 0.3)
    assert frames == []
    assert app.next_frame_due() == math.inf


def test_a_burst_of_changes_is_drawn_once_after_it_settles(viewer, monkeypatch):
    app, frames = viewer
    monkeypatch.setattr(app_module, "SETTLE", 0.3)  # long, so a slow machine cannot split the burst
    monkeypatch.setattr(app_module, "SETTLE_MAX", 2.0)
    for _ in range(3):  # three states of one step (three robots), one after another
        app.loop.call_later(move, app, key=object())
        app.step(timeout=0)
    last_change = time.monotonic()
    assert frames == []  # not yet: more of the burst may come
    deadline = time.monotonic() + 10
    while not frames and time.monotonic() < deadline:
        app.step(timeout=0.05)
    assert len(frames) == 1 and frames[0] - last_change >= 0.3 * 0.9
    step_for(app, 0.3)
    assert len(frames) == 1  # nothing new since


def test_a_steady_stream_is_still_drawn_and_at_most_frame_rate_times_a_second(viewer, monkeypatch):
    app, frames = viewer
    monkeypatch.setattr(app_module, "SETTLE", 0.2)  # every change would put the frame off again ...
    monkeypatch.setattr(app_module, "SETTLE_MAX", 0.25)  # ... but not past this
    step_for(app, 1.0, post=move)
    assert 2 <= len(frames) <= 1.0 / 0.25 + 1, frames
    monkeypatch.setattr(app_module, "SETTLE", 0.002)
    monkeypatch.setattr(app_module, "SETTLE_MAX", 0.005)
    frames.clear()
    step_for(app, 1.0, post=move)
    assert 10 <= len(frames) <= FRAME_RATE + 2, len(frames)

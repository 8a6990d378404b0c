"""When a viewer draws: once a burst is complete or has settled, at most FRAME_RATE times a second, never for
nothing."""

import math
import time

import pytest

import tutorial.app.frame_clock as frames_module
from tutorial.app.app import App
from tutorial.app.frame_clock import FRAME_RATE
from tutorial.core.project import load_project

from conftest import MODEL


@pytest.fixture
def viewer(tmp_path, node):
    """A project without a simulator (a viewer's) of three tanks, headless, its frames' times in a list."""
    path = tmp_path / "viewer.yaml"
    path.write_text(
        "name: frames\nmodels:\n"
        + "".join(f"  - name: Tank{i}\n    file: {MODEL / 'tank.xml'}\n    position: [{i}, 0, 0]\n" for i in (1, 2, 3))
    )
    app = App(load_project(path), node=node, headless=True, output=lambda r: None)
    app.open()
    frames = []
    app._draw = lambda: frames.append(time.monotonic())
    try:
        yield app, frames
    finally:
        app.close()


def move(app, name="Tank1") -> None:
    app.bodies[name].notify_kinematic_state_change()


def move_all(app) -> None:
    for name in app.bodies:
        move(app, name)


def wait_for_frames(app, frames, n: int, timeout: float = 10.0) -> None:
    deadline = time.monotonic() + timeout
    while len(frames) < n and time.monotonic() < deadline:
        app.step(timeout=0.01)


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


def test_a_complete_burst_is_drawn_at_once(viewer, monkeypatch):
    app, frames = viewer
    move_all(app)  # every tank has moved once: each is expected in every burst
    wait_for_frames(app, frames, 1)
    frames.clear()
    monkeypatch.setattr(frames_module, "SETTLE", 5.0)  # the settle wait must play no part
    monkeypatch.setattr(frames_module, "SETTLE_MAX", 5.0)
    for name in ("Tank1", "Tank2"):  # the states of one step, one per robot: not all in yet
        app.loop.call_later(move, app, name, key=object())
        app.step(timeout=0)
    step_for(app, 0.2)
    assert frames == [] and not app.burst_complete()
    app.loop.call_later(move, app, "Tank3", key=object())  # the last one
    wait_for_frames(app, frames, 1, timeout=2.0)
    assert len(frames) == 1
    assert not app.burst_complete()  # drawn: nobody has moved since


def test_an_arrow_that_has_ever_changed_is_part_of_the_burst(viewer, monkeypatch):
    app, frames = viewer
    move_all(app)
    arrow = app.overlays.arrow("Tank1/acceleration", (1.0, 0.0, 0.0))  # a Step 5 viewer: the IMU's arrow
    arrow.set((0.0, 0.0, 0.0), (0.1, 0.0, 0.0))
    wait_for_frames(app, frames, 1)
    frames.clear()
    monkeypatch.setattr(frames_module, "SETTLE", 5.0)
    monkeypatch.setattr(frames_module, "SETTLE_MAX", 5.0)
    move_all(app)  # the joint states are in, the IMU's message is not
    step_for(app, 0.2)
    assert frames == [] and not app.burst_complete()
    app.loop.call_later(arrow.set, (0.0, 0.0, 0.0), (0.2, 0.0, 0.0), key=object())  # now the IMU's is
    wait_for_frames(app, frames, 1, timeout=2.0)
    assert len(frames) == 1


def test_an_incomplete_burst_is_drawn_once_after_it_settles(viewer, monkeypatch):
    app, frames = viewer
    move_all(app)  # every tank has moved once: each is expected in every burst
    wait_for_frames(app, frames, 1)
    monkeypatch.setattr(frames_module, "SETTLE", 0.3)  # long, so a slow machine cannot split the burst
    monkeypatch.setattr(frames_module, "SETTLE_MAX", 2.0)
    last_change = time.monotonic()  # before the step that sees the last change: the frame comes >= 0.3 s after
    for name in ("Tank1", "Tank2"):  # Tank3's state does not come
        app.loop.call_later(move, app, name, key=object())
        app.step(timeout=0)
    assert frames[1:] == []  # not yet: more of the burst may come
    wait_for_frames(app, frames, 2)
    assert len(frames) == 2 and frames[1] - last_change >= 0.3
    step_for(app, 0.3)
    assert len(frames) == 2  # nothing new since


def test_a_steady_stream_is_still_drawn_and_at_most_frame_rate_times_a_second(viewer, monkeypatch):
    app, frames = viewer
    move_all(app)
    wait_for_frames(app, frames, 1)
    frames.clear()  # from here on only Tank1 moves: no burst is ever complete
    monkeypatch.setattr(frames_module, "SETTLE", 0.2)  # every change would put the frame off again ...
    monkeypatch.setattr(frames_module, "SETTLE_MAX", 0.25)  # ... but not past this
    step_for(app, 1.0, post=move)
    assert 2 <= len(frames) <= 1.0 / 0.25 + 1, frames
    monkeypatch.setattr(frames_module, "SETTLE", 0.002)
    monkeypatch.setattr(frames_module, "SETTLE_MAX", 0.005)
    frames.clear()
    step_for(app, 1.0, post=move)
    assert 10 <= len(frames) <= FRAME_RATE + 2, len(frames)


def test_complete_bursts_back_to_back_are_drawn_at_most_frame_rate_times_a_second(viewer):
    app, frames = viewer
    step_for(app, 1.0, post=move_all)  # every posted call completes a burst
    assert FRAME_RATE * 0.5 <= len(frames) <= FRAME_RATE + 2, len(frames)


@pytest.mark.unit
def test_the_frame_rate_comes_from_the_environment_or_a_clear_error():
    """A class's server sets RTT_FRAME_RATE (course/jupyterhub_config.py); a learner's machine keeps 60."""
    from tutorial.app.frame_clock import frame_rate

    assert frame_rate(None) == 60.0 and frame_rate(" ") == 60.0
    assert frame_rate("20") == 20.0 and frame_rate("1") == 1.0 and frame_rate("240") == 240.0
    for bad in ("0", "0.5", "241", "-20", "nan", "inf", "twenty"):
        with pytest.raises(ValueError, match=r"RTT_FRAME_RATE must be frames per second from 1 to 240"):
            frame_rate(bad)


@pytest.mark.cross_process
def test_a_class_server_s_frame_rate_paces_the_views(tmp_path):
    """With RTT_FRAME_RATE=20 a simulating view draws 20 frames a second, not 60 (a subprocess: read at import)."""
    import subprocess
    import sys

    code = (
        "from tutorial.app.frame_clock import FRAME_RATE, FramePacer\n"
        "p = FramePacer(); n = 0; now = 0.0\n"  # one second of the frame clock, each frame drawn when due
        "while True:\n"
        "    now = p.next_frame_due(True, [])\n"
        "    if now > 1.0: break\n"
        "    p.drawn(now, []); n += 1\n"
        "print(FRAME_RATE, n)\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], env={**__import__("os").environ, "RTT_FRAME_RATE": "20"},
        capture_output=True, text=True, timeout=60, check=True,
    )  # fmt: skip
    rate, frames = out.stdout.split()
    assert float(rate) == 20.0 and 19 <= int(frames) <= 21, out.stdout

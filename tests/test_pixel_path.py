"""A JointState's way to the 3D view, counted in our files by following the calls.

A Step 3 viewer runs in an :class:`tutorial.app.app.App` that draws: with
meshcat's own ``Visualizer`` on a window that keeps what it is sent (the
scene's default sink), and, as ``rtt-run project/step3.yaml`` runs it, on
the project's meshcat server (the App gives the scene a ``BatchSink``).  One message goes in
through the subscription's callback, on a thread of its own as the spin
thread calls it; the App's owner thread then steps until the scene has sent
the new pose.  A profiler (``sys.setprofile``) notes the stack of calls at
each point where the message, or what came of it, moves toward the view:

* the callback posting it to the main thread (``call_later``);
* any function of ours called with the message, its names or its positions
  (the matcher reads them there);
* a joint's position written into the model, and the model's poses updated;
* the scene handing the frame's transforms to its sink.

The files of ``tutorial/`` on those stacks are the message's path to the
scene: at most six (issue #61).  What runs beside it without being handed the
message is not counted: when to draw (``app/frame_clock.py``), the arrows'
bookkeeping, and a monitor's status line (``view/status.py``, given counts
and the applied positions, never the message).  Past the scene, the sink
(a widget, or a meshcat server's socket) is the transport, not the path.
A last test shows the count catching one more file.
"""

from __future__ import annotations

import sys
import threading
from pathlib import Path

import pytest

pytestmark = pytest.mark.ros

ROOT = Path(__file__).resolve().parents[1]
LIBRARY = ROOT / "tutorial"
HAND_OVERS = {
    ("call_later.py", "call_later"),  # the callback posts: the spin thread's side
    ("body.py", "q"),  # a joint's position written into the model (Joint.q's setter)
    ("body.py", "notify_kinematic_state_change"),  # the model's poses updated from it
    ("a sink", "send_transforms"),  # the frame handed to the scene's sink, whichever it is
}


def stack_files(frame) -> set[str]:
    files = set()
    while frame is not None:
        path = Path(frame.f_code.co_filename)
        if path.is_relative_to(LIBRARY):
            files.add(str(path.relative_to(ROOT)))
        frame = frame.f_back
    return files


def scene_update_above(frame, depth: int = 3):
    """The frame of ``Scene.update`` among the few callers of ``frame`` (the test's noting wrapper between), or None."""
    for _ in range(depth):
        frame = frame.f_back
        if frame is None:
            return None
        if frame.f_code.co_name == "update" and Path(frame.f_code.co_filename).name == "scene.py":
            return frame
    return None


class PathProfiler:
    """A ``sys.setprofile`` hook: the files on the stack at each hand-over, and which hand-overs it saw."""

    def __init__(self, msg):
        self.files: set[str] = set()
        self.seen: set[tuple[str, str]] = set()
        self.carried = (msg, msg.name, msg.position)  # the message and its fields, as received
        self.receivers: set[str] = set()

    def __call__(self, frame, event, arg):
        if event != "call":
            return
        ours = Path(frame.f_code.co_filename).is_relative_to(LIBRARY)
        key = (Path(frame.f_code.co_filename).name, frame.f_code.co_name)
        scene = scene_update_above(frame) if ours and frame.f_code.co_name == "send_transforms" else None
        if scene is not None:
            self.seen.add(("a sink", "send_transforms"))
            self.files |= stack_files(scene)  # the sink is past the scene: the stack from the scene's update up
        elif key in HAND_OVERS:
            self.seen.add(key)
            self.files |= stack_files(frame)
        elif Path(frame.f_code.co_filename).is_relative_to(LIBRARY) and any(
            any(value is c for c in self.carried) for value in frame.f_locals.values()
        ):  # a function of ours called with the message, or its names or positions (the matcher)
            self.receivers.add(frame.f_code.co_qualname)
            self.files |= stack_files(frame)


class KeepingWindow:
    """meshcat's window stand-in: no server, every command kept (meshcat's own Visualizer sends to it)."""

    zmq_url = None
    web_url = "(a test's window)"

    def __init__(self):
        self.commands = []

    def send(self, command):
        self.commands.append(command)

    def url(self):
        return self.web_url


def path_of(viewer_class, node, server: bool = False) -> PathProfiler:
    """One JointState through a drawing App with ``viewer_class`` attached; the profiler that followed it.

    ``server``: draw on the project's meshcat server, as ``rtt-run`` does (the App's own, a ``BatchSink``),
    instead of meshcat's own ``Visualizer`` on a window that keeps what it is sent.
    """
    import meshcat
    from sensor_msgs.msg import JointState

    from tutorial.app.app import App
    from tutorial.core.project import load_project
    from tutorial.tools.standalone.app import StandaloneApp

    project = load_project(ROOT / "project" / "tank_view.yaml").with_controller("Tank", "Viewer", viewer_class)
    vis = None if server else meshcat.Visualizer(window=KeepingWindow())
    app = (StandaloneApp if server else App)(project, node=node, output=lambda record: None, vis=vis)
    errors, sent = [], threading.Event()
    msg = JointState(name=["TURRET_Y"], position=[0.4])
    profiler = PathProfiler(msg)
    try:
        app.open()
        [(_, viewer, _)] = app.controllers
        sink = app.scene.sink
        assert type(sink).__name__ == ("BatchSink" if server else "VisualizerSink")
        send = sink.send_transforms

        def noting_send(transforms):
            send(transforms)
            sent.set()

        sink.send_transforms = noting_send

        def spin_thread_calls():
            sys.setprofile(profiler)
            try:
                viewer.on_joint_state(msg)
            except Exception as exc:  # collected, asserted below
                errors.append(exc)
            finally:
                sys.setprofile(None)

        caller = threading.Thread(target=spin_thread_calls)
        caller.start()
        caller.join(10)
        assert not caller.is_alive()
        sys.setprofile(profiler)
        try:
            for _ in range(200):  # the owner thread steps until the frame went out (each step waits <= 1/60 s)
                app.step()
                if sent.is_set():
                    break
        finally:
            sys.setprofile(None)
        assert sent.is_set(), "no frame was sent"
        assert abs(viewer.body.joint("TURRET_Y").q - 0.4) < 1e-12
    finally:
        app.close()
    assert errors == []
    assert profiler.seen == HAND_OVERS  # each hand-over was seen: the stacks are the message's own
    assert "match_joint_state" in profiler.receivers  # the data followed into the matcher, too
    return profiler


VIEWERS = {
    "the lesson's viewer": ("tutorial.controllers.joint_state_subscriber", "RttJointStateSubscriber", False),
    "the lesson's monitor on the project's server (step3.yaml)": (
        "tutorial.controllers.joint_state_subscriber",
        "RttJointStateMonitor",
        True,
    ),
    "the frozen monitor (step5.yaml)": ("tutorial.app.reference.joint_state_subscriber", "RttJointStateMonitor", False),
}


@pytest.mark.parametrize("viewer", list(VIEWERS))
def test_a_joint_state_reaches_the_scene_through_at_most_six_of_our_files(node, viewer):
    import importlib

    module, name, server = VIEWERS[viewer]
    profiler = path_of(getattr(importlib.import_module(module), name), node, server)
    print(f"\n{viewer}: {len(profiler.files)} files: {sorted(profiler.files)}")
    assert len(profiler.files) <= 6, sorted(profiler.files)


def test_the_count_catches_a_file_the_message_detours_through(node):
    from tutorial.controllers.joint_state_subscriber import RttJointStateSubscriber
    from tutorial.view import status

    class Detour(RttJointStateSubscriber):
        def update_joint_state(self, msg):
            status._shown_name(msg.name)  # the message's names through one more file
            return super().update_joint_state(msg)

    profiler = path_of(Detour, node)
    assert "tutorial/view/status.py" in profiler.files and len(profiler.files) == 7, sorted(profiler.files)

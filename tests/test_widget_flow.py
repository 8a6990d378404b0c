"""The live view's flow (tutorial/view/widget/flow.py) and the widget's kernel side, without a browser.

What is held: commands coalesce by what they change (never a queue of old
states, the pending set bounded by the scene's paths however long no view
answers); at most WINDOW frames are in flight; nothing goes before a view
says hello; the scene a new view gets rebuilds what the run drew, with the
newest value of each; while a cell runs frames go on a timer, and stop after
BUSY_UNANSWERED unanswered ones.  The widget answers its browser's messages,
and a run drawing from its own thread while the kernel's thread answers
views leaves the messages in the flow's order (no exception on either).
The browser's side (widget.js) is tested in tests/test_widget_browser.py.
"""

from __future__ import annotations

import threading

import meshcat
import meshcat.geometry as g
import msgpack
import numpy as np
import pytest
import umsgpack
from meshcat.commands import Delete, SetObject, SetProperty, SetTransform

from tutorial.view.meshcat_batch import SET_TRANSFORMS
from tutorial.view.widget import flow as flow_module
from tutorial.view.widget.flow import BUSY_RATE, BUSY_UNANSWERED, WINDOW, FrameFlow

pytestmark = pytest.mark.unit


def pose(x: float) -> np.ndarray:
    m = np.eye(4)
    m[0, 3] = x
    return m


def transform(path: str, x: float) -> dict:
    return SetTransform(pose(x), meshcat.path.Path(tuple(p for p in path.split("/") if p))).lower()


def box(path: str) -> dict:
    return SetObject(g.Box([0.1, 0.1, 0.1]), None, meshcat.path.Path(tuple(p for p in path.split("/") if p))).lower()


def unpack(buffers: list[bytes]) -> list[dict]:
    """The commands of a frame, set_transforms opened up."""
    out = []
    for b in buffers:
        c = umsgpack.unpackb(b)
        out.extend(c["commands"] if c["type"] == SET_TRANSFORMS else [c])
    return out


def opened(flow: FrameFlow) -> list[dict]:
    """A view says hello: what it is sent."""
    return unpack(flow.scene(0.0))


def test_nothing_goes_before_a_view_says_hello():
    f = FrameFlow()
    f.put(box("/a"))
    f.put(transform("/a", 1.0))
    assert f.take(0.0) is None
    assert f.take(100.0, busy=True) is None, "a busy kernel sent to a page no view has opened"
    assert f.pending == 2


def test_transforms_coalesce_to_the_newest_and_the_pending_set_stays_bounded():
    f = FrameFlow()
    f.put(box("/a"))
    f.put(box("/b"))
    for i in range(10_000):  # a run drawing for minutes with no view answering
        f.put(transform("/a", i))
        f.put(transform("/b", -i))
    assert f.pending == 4, "commands piled up instead of replacing the older ones"
    assert f.commands_replaced == 2 * 9_999
    scene = opened(f)
    matrices = {c["path"]: c["matrix"][12] for c in scene if c["type"] == "set_transform"}
    assert matrices == {"/a": 9_999.0, "/b": -9_999.0}


def test_at_most_window_frames_in_flight_and_each_answer_lets_one_more_go():
    f = FrameFlow()
    f.put(box("/a"))
    opened(f)  # the scene is in flight
    sent = 0
    for i in range(50):
        f.put(transform("/a", i))
        if f.take(float(i)) is not None:
            sent += 1
    assert sent == WINDOW - 1, f"{sent} frames sent with the scene unanswered; the window is {WINDOW}"
    f.put(transform("/a", 99.0))
    f.drawn()
    out = f.take(100.0)
    assert out is not None and unpack(out)[0]["matrix"][12] == 99.0, "the answer did not let the newest state go"
    assert f.take(100.0) is None
    for _ in range(WINDOW + 1):  # answers never add up past the window
        f.drawn()
    burst = 0
    for i in range(10):
        f.put(transform("/a", i))
        burst += f.take(200.0) is not None
    assert burst == WINDOW


def test_an_answer_for_two_frames_lets_two_go_and_a_bad_count_counts_as_one(widget):
    """A view answers several drawn frames at once ({"type": "drawn", "frames": 2}); its count is never trusted."""
    vis = widget.visualizer()
    vis["box"].set_object(g.Box([0.1, 0.2, 0.3]))
    widget._on_message(widget, {"type": "hello", "id": "v1"}, [])
    x = 0.0

    def fill() -> int:  # new poses until the window is full: the frames sent
        nonlocal x
        before = len(widget.sent)
        for _ in range(WINDOW + 2):
            x += 1.0
            vis["box"].set_transform(pose(x))
        return len(widget.sent) - before

    assert fill() == WINDOW - 1  # the scene is the window's first frame
    widget._on_message(widget, {"type": "drawn", "frames": 2}, [])  # the newest pending pose goes at once
    assert fill() == 1, "an answer for two frames let fewer than two go"
    for bad in (0, -5, "2", 2.5, True, None, [2]):
        widget._on_message(widget, {"type": "drawn", "frames": bad}, [])
        assert fill() == 0, f"frames={bad!r} let more than one go"  # it counted one, sent with the answer
    widget._on_message(widget, {"type": "drawn", "frames": 10**9}, [])
    assert fill() == WINDOW - 1, "answers added up past the window"  # one went with the answer itself


def test_a_frame_of_several_transforms_is_one_set_transforms_and_other_commands_keep_their_order():
    f = FrameFlow()
    opened(f)
    f.drawn()
    f.put(box("/a"))
    f.put(transform("/a", 1.0))
    f.put(transform("/b", 2.0))
    f.put(SetProperty("visible", False, meshcat.path.Path(("c",))).lower())
    f.put(transform("/d", 3.0))
    buffers = f.take(0.0)
    kinds = [umsgpack.unpackb(b)["type"] for b in buffers]
    assert kinds == ["set_object", SET_TRANSFORMS, "set_property", "set_transform"], kinds
    batch = msgpack.unpackb(buffers[1])
    assert [c["path"] for c in batch["commands"]] == ["/a", "/b"]


def test_properties_keep_the_newest_value_and_set_object_clears_them():
    f = FrameFlow()
    f.put(box("/a"))
    for i in range(100):
        f.put(SetProperty("opacity", i / 100, meshcat.path.Path(("a",))).lower())
    props = [c for c in opened(f) if c["type"] == "set_property"]
    assert len(props) == 1 and props[0]["value"] == pytest.approx(0.99), "the scene grew a value per set_property"
    f.put(SetProperty("visible", False, meshcat.path.Path(("a",))).lower())
    f.put(box("/a"))
    assert [c for c in opened(f) if c["type"] == "set_property"] == [], "set_object did not clear the properties"


def test_delete_removes_the_subtree_from_the_scene_and_from_what_is_pending():
    f = FrameFlow()
    f.put(box("/robot/a"))
    f.put(box("/robot/b"))
    f.put(box("/other"))
    f.put(transform("/robot/a", 1.0))
    f.put(Delete(meshcat.path.Path(("robot",))).lower())
    assert [c["type"] for c in f._pending.values() if c[0] is not None] == []  # no transform under /robot left
    scene = opened(f)
    assert [c["path"] for c in scene if c["type"] == "set_object"] == ["/other"]
    f.put(Delete(meshcat.path.Path(())).lower())  # the whole scene
    assert opened(f) == []


def test_while_a_cell_runs_frames_go_on_a_timer_and_stop_after_too_many_unanswered():
    f = FrameFlow()
    f.put(box("/a"))
    opened(f)
    f.drawn()
    f.drawn()
    times = [i / (4 * BUSY_RATE) for i in range(4 * (BUSY_UNANSWERED + 200))]
    sent = []
    for t in times:
        f.put(transform("/a", t))
        if f.take(1.0 + t, busy=True) is not None:
            sent.append(1.0 + t)
    gaps = np.diff(sent[WINDOW:])
    assert gaps.min() >= 1.0 / BUSY_RATE - 1e-9, "frames faster than the busy rate"
    assert len(sent) == BUSY_UNANSWERED, f"{len(sent)} frames sent in a row with no answer"
    f.drawn()  # the cell ended, the view answered: back to the window
    f.put(transform("/a", 0.5))
    assert f.take(1e6) is not None


def test_a_command_that_is_not_a_scene_command_is_refused():
    f = FrameFlow()
    with pytest.raises(ValueError, match="not a meshcat scene command"):
        f.put({"type": "capture_image"})
    with pytest.raises(ValueError, match="not a meshcat scene command"):
        f.put({"type": "set_transform", "path": 3, "matrix": [0] * 16})
    assert f.pending == 0


# ---- the widget's kernel side -------------------------------------------------------------------------------
@pytest.fixture
def widget():
    from tutorial.view.widget.widget import MeshcatWidget

    w = MeshcatWidget("test view")
    sent: list = []
    w.send = lambda content, buffers=None: sent.append((content, buffers))  # the comm, as the browser gets it
    w.sent = sent
    yield w
    w.close()


def test_the_widget_answers_its_views(widget):
    vis = widget.visualizer()
    vis["box"].set_object(g.Box([0.1, 0.2, 0.3]))
    assert widget.sent == [], "sent before any view opened"
    widget._on_message(widget, {"type": "viewer_js"}, [])
    (content, [script]) = widget.sent[-1]
    assert content == {"type": "viewer_js"} and script[:2] == b"\x1f\x8b", "meshcat's script, gzip-compressed"
    widget._on_message(widget, {"type": "hello", "id": "v1"}, [])
    content, buffers = widget.sent[-1]
    assert content == {"type": "scene", "to": "v1"} and [c["type"] for c in unpack(buffers)] == ["set_object"]
    vis["box"].set_transform(pose(1.0))  # the scene is in flight: the window has WINDOW - 1 frames left
    assert widget.sent[-1][0] == {"type": "frame", "n": 1}
    for k in range(WINDOW - 2):
        vis["box"].set_transform(pose(1.5 + k))
    assert widget.sent[-1][0] == {"type": "frame", "n": WINDOW - 1}
    n = len(widget.sent)
    vis["box"].set_transform(pose(2.0))
    vis["box"].set_transform(pose(3.0))
    assert len(widget.sent) == n, "sent past the window"
    widget._on_message(widget, {"type": "drawn"}, [])
    assert unpack(widget.sent[-1][1])[0]["matrix"][12] == 3.0, "the answer did not send the newest pose"
    widget._on_message(widget, {"type": "ping"}, [])
    assert widget.sent[-1][0] == {"type": "pong"}
    widget._on_message(widget, {"type": "rejected", "reason": "x" * 1000}, [])
    assert widget.rejected == 1 and len(widget.last_rejection) == 300
    widget._on_message(widget, "not a dict", [])  # ignored
    assert repr(widget) == "MeshcatWidget('test view')"


def test_a_scene_drawn_from_another_thread_while_views_answer_keeps_the_flow_in_order(widget):
    """The run's owner thread draws while the kernel's thread answers: every send sees a consistent flow."""
    from tutorial.view.widget.widget import WidgetWindow

    errors: list[BaseException] = []
    window = WidgetWindow(widget)
    vis = meshcat.Visualizer(window=window)
    vis["a"].set_object(g.Box([0.1, 0.1, 0.1]))
    widget._on_message(widget, {"type": "hello", "id": "v"}, [])
    stop = threading.Event()

    def draw():
        try:
            for i in range(3000):
                window.send_transforms([(meshcat.path.Path(("a",)), pose(float(i)))])
        except BaseException as exc:  # noqa: BLE001 - collected, asserted below
            errors.append(exc)
        finally:
            stop.set()

    def answer():
        try:
            while not stop.is_set():
                widget._on_message(widget, {"type": "drawn"}, [])
        except BaseException as exc:  # noqa: BLE001
            errors.append(exc)

    threads = [threading.Thread(target=draw), threading.Thread(target=answer)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(60)
    assert not errors, errors
    assert not any(t.is_alive() for t in threads)
    xs = [c["matrix"][12] for content, b in widget.sent if content["type"] == "frame" for c in unpack(b)]
    assert xs == sorted(xs) and len(set(xs)) == len(xs), "frames left out of the order they were drawn in"
    assert widget.flow.frames_sent == len(xs)


def test_busy_limits_are_what_the_docs_say():
    assert flow_module.BUSY_RATE * 60 == flow_module.BUSY_UNANSWERED  # "a minute" of frames while busy


def test_the_nodelay_extension_is_enabled_by_the_same_setting_both_ways_and_turns_the_delay_off(tmp_path):
    """pip's data file and ``python -m tutorial.view.widget.nodelay`` write the same setting; loading the
    extension makes every kernel WebSocket set TCP_NODELAY once open (and loading twice wraps once)."""
    import asyncio
    import json

    from jupyter_server.services.kernels.websocket import KernelWebsocketHandler

    from tutorial.view.widget import nodelay

    from conftest import ROOT

    shipped = json.loads((ROOT / "jupyter-config" / "jupyter_server_config.d" / "ros_tank_tutorial.json").read_text())
    assert shipped == nodelay.SETTING
    assert json.loads(nodelay.enable(str(tmp_path)).read_text()) == nodelay.SETTING

    class App:
        class log:  # noqa: N801 - a stand-in for the server's logger
            info = staticmethod(lambda *a: None)

    original = KernelWebsocketHandler.open
    try:
        calls = []

        async def opened(self, *args, **kwargs):
            calls.append("open")

        KernelWebsocketHandler.open = opened
        KernelWebsocketHandler.rtt_nodelay = False
        nodelay._load_jupyter_server_extension(App)
        nodelay._load_jupyter_server_extension(App)  # a second load does not wrap again

        class Handler:
            def set_nodelay(self, value):
                calls.append(("nodelay", value))

        asyncio.run(KernelWebsocketHandler.open(Handler(), "kernel-id"))
        assert calls == ["open", ("nodelay", True)]
    finally:
        KernelWebsocketHandler.open = original
        KernelWebsocketHandler.rtt_nodelay = False

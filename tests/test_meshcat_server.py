"""The project's meshcat server and page: a frame's transforms as one message, the fallback, the renderer.

The scene sends a frame as one ``set_transforms`` command
(:mod:`tutorial.view.meshcat_batch`); the project's server stores each inner
transform as meshcat's own server stores a single one and forwards the
frame as one WebSocket message; meshcat's own server refuses the command
and the scene falls back to one command per transform.
"""

from __future__ import annotations

import base64
import re
import urllib.request

import msgpack
import mujoco
import numpy as np
import pytest
import umsgpack
from hypothesis import given
from hypothesis import strategies as st

from tutorial.core.world import ModelEntry, build_world
from tutorial.view import meshcat_page
from tutorial.view.meshcat_batch import MAX_COMMANDS, MAX_PATH_CHARS, MAX_PATH_PARTS, BadBatch, pack_batch, split_batch

from browser import chromium, messages_after_one
from conftest import MODEL
from fuzzing import examples


def lowered(path: str, matrix: np.ndarray) -> dict:
    from meshcat.commands import SetTransform

    class Path:
        def lower(self):
            return path

    return SetTransform(matrix, Path()).lower()


def pose(x: float, y: float = 0.0, z: float = 0.0) -> np.ndarray:
    t = np.eye(4)
    t[:3, 3] = (x, y, z)
    return t


# ---- the protocol (no process) -------------------------------------------------------------


@pytest.mark.unit
def test_each_inner_command_is_stored_as_meshcat_python_packs_it_alone():
    commands = [lowered("/meshcat/rtt/Tank/CHASSIS", pose(1.25)), lowered("/meshcat/rtt/Tank/TURRET_Y", pose(0, 2))]
    split = split_batch(pack_batch(commands))
    assert [path for path, _ in split] == [
        ["meshcat", "rtt", "Tank", "CHASSIS"],
        ["meshcat", "rtt", "Tank", "TURRET_Y"],
    ]
    assert [data for _, data in split] == [umsgpack.packb(c) for c in commands]


GOOD = {"type": "set_transform", "path": "/meshcat/a", "matrix": [0.0] * 16}


def batch_of(*commands) -> bytes:
    return umsgpack.packb({"type": "set_transforms", "commands": list(commands)})


def transform(**changes) -> dict:
    return dict(GOOD, **changes)


@pytest.mark.unit
@pytest.mark.parametrize(
    "data",
    [
        b"\xc1",  # never used in msgpack
        umsgpack.packb([1, 2, 3]),
        umsgpack.packb({"type": "set_transform", "commands": []}),
        umsgpack.packb({"type": "set_transforms", "commands": "no"}),
        batch_of({"type": "delete", "path": "/a"}),
        batch_of(transform(path=3)),
        batch_of(transform(matrix=[0.0] * 15)),
        batch_of(transform(matrix=[True] * 16)),
        batch_of(transform(matrix=["1"] * 16)),
        batch_of(GOOD, transform(matrix=None)),  # a good command first: the batch is still refused whole
        batch_of(transform(path="/a" * (MAX_PATH_PARTS + 1))),  # deeper than the server walks
        batch_of(transform(path="/" + "x" * MAX_PATH_CHARS)),
        batch_of(*[GOOD] * (MAX_COMMANDS + 1)),
    ],
    ids=lambda d: f"{len(d)}B",
)
def test_a_bad_batch_is_refused_whole(data):
    with pytest.raises(BadBatch):
        split_batch(data)


@pytest.mark.unit
@examples(60)
@given(st.binary(max_size=300))
def test_any_bytes_are_a_batch_or_a_bad_batch(data):
    try:
        split = split_batch(data)
    except BadBatch:
        return
    assert all(isinstance(path, list) and isinstance(packed, bytes) for path, packed in split)


_INT = st.integers(-(2**63), 2**63 - 1)  # what msgpack can hold
_ANY = st.one_of(
    st.none(),
    st.booleans(),
    _INT,
    st.floats(),
    st.text(max_size=40),
    st.lists(st.floats(), max_size=20),
    st.lists(_INT, min_size=16, max_size=16),
)
_COMMAND = st.one_of(
    st.fixed_dictionaries({"type": st.just("set_transform"), "path": _ANY, "matrix": _ANY}),
    st.fixed_dictionaries(
        {
            "type": st.just("set_transform"),
            "path": st.text(max_size=80),
            "matrix": st.lists(st.one_of(st.floats(), _INT, st.booleans()), min_size=16, max_size=16),
        }
    ),
    st.dictionaries(st.text(max_size=8), _ANY, max_size=4),
    _ANY,
)


@pytest.mark.unit
@examples(60)
@given(st.lists(_COMMAND, max_size=6))
def test_any_commands_in_a_well_formed_batch_are_taken_whole_or_refused_whole(commands):
    try:
        split = split_batch(batch_of(*commands))
    except BadBatch:
        assert not all(
            isinstance(c, dict)
            and c.get("type") == "set_transform"
            and isinstance(c.get("path"), str)
            and isinstance(c.get("matrix"), list)
            and len(c["matrix"]) == 16
            and not any(isinstance(x, bool) or not isinstance(x, (int, float)) for x in c["matrix"])
            and len(c["path"]) <= MAX_PATH_CHARS
            and c["path"].count("/") <= MAX_PATH_PARTS
            for c in commands
        )
        return
    assert len(split) == len(commands)
    for (path, packed), command in zip(split, commands):
        assert path == [part for part in command["path"].split("/") if part]
        assert umsgpack.unpackb(packed) == command


# ---- the project's server, and meshcat's own (a process each, no ROS) ----------------------------------


def tank():
    model = build_world([ModelEntry("Tank", MODEL / "tank.xml")])
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    return model, data


def stored_transforms(server) -> dict[str, list[float]]:
    """What the server would send a page that opens now: each path's newest transform (its ``get_scene``)."""
    import zmq

    sock = zmq.Context.instance().socket(zmq.REQ)
    sock.setsockopt(zmq.LINGER, 0)
    sock.connect(server.zmq_url)
    try:
        sock.send(b"get_scene")
        assert sock.poll(10000), "the server did not answer get_scene"
        html = sock.recv().decode()
    finally:
        sock.close()
    out = {}
    for blob in re.findall(r"application/octet-binary;base64,([A-Za-z0-9+/=]+)", html):
        command = msgpack.unpackb(base64.b64decode(blob), strict_map_key=False)  # set_object blobs have int keys
        if isinstance(command, dict) and command.get("type") == "set_transform":
            out[command["path"]] = command["matrix"]
    return out


@pytest.fixture
def server_of():
    servers = []

    def start(batch: bool):
        from tutorial.tools.standalone.meshcat_server import start_server

        servers.append(start_server(batch=batch))
        return servers[-1]

    yield start
    for s in servers:
        s.close()


@pytest.mark.cross_process
@pytest.mark.parametrize("batch", [True, False], ids=["project_server", "meshcats_own_server"])
def test_the_scene_sends_a_frame_as_one_message_where_it_can_and_every_pose_arrives(server_of, batch):
    from tutorial.tools.standalone.sinks import BatchSink, frame_sink
    from tutorial.view.scene import Scene

    server = server_of(batch)
    model, data = tank()
    vis = server.visualizer()
    scene = Scene(vis, model, sink=frame_sink(vis))  # as the App makes it
    assert isinstance(scene.sink, BatchSink)
    try:
        scene.build(data)  # the first frame: three moving bodies
        first = scene.sink.messages
        data.qpos[0] += 0.5  # the chassis moves: the turret and the barrel ride on it
        mujoco.mj_kinematics(model, data)
        assert scene.update(data) == 3
        frame = scene.sink.messages - first
        assert scene.sink.batch is batch
        assert first == (1 if batch else 1 + 3)  # meshcat's own server refused the batch, then took three singles
        assert frame == (1 if batch else 3)
        stored = stored_transforms(server)
        for body in scene.moving_bodies:  # each body's newest pose is what a page that opens now is sent
            path = f"/meshcat/{scene.body_path(body)}"
            expected = np.eye(4)
            expected[:3, :3], expected[:3, 3] = data.xmat[body].reshape(3, 3), data.xpos[body]
            np.testing.assert_allclose(np.array(stored[path]).reshape(4, 4).T, expected, atol=1e-12)
    finally:
        scene.close()


def ask(server, frames: list[bytes]) -> bytes:
    """One request to the server's zmq socket, its reply (10 s at most)."""
    import zmq

    sock = zmq.Context.instance().socket(zmq.REQ)
    sock.setsockopt(zmq.LINGER, 0)
    sock.connect(server.zmq_url)
    try:
        sock.send_multipart(frames)
        assert sock.poll(10000), f"no reply to {frames[0][:20]!r}"
        return sock.recv()
    finally:
        sock.close()


@pytest.mark.cross_process
def test_a_bad_batch_is_answered_with_an_error_stores_nothing_and_the_server_goes_on(server_of):
    server = server_of(True)
    deep = lowered("/meshcat" + "/a" * 3000, pose(1.0))  # deeper than Python's recursion limit
    for frames in (
        [b"set_transforms", b"", b"\xc1"],
        [b"set_transforms", b""],
        [b"set_transforms", b"", pack_batch([lowered("/meshcat/early", pose(0.5)), deep])],
    ):
        assert ask(server, frames).startswith(b"error: ")
    assert "/meshcat/early" not in stored_transforms(server)  # a refused batch is refused whole
    assert ask(server, [b"set_transforms", b"", pack_batch([lowered("/meshcat/box", pose(0.75))])]) == b"ok"
    assert stored_transforms(server)["/meshcat/box"][12] == 0.75  # column-major: x is the 13th number
    assert server.process.poll() is None


@pytest.mark.cross_process
@pytest.mark.parametrize("batch", [True, False], ids=["project_server", "meshcats_own_server"])
def test_what_meshcats_own_handler_cannot_take_gets_an_error_not_a_dead_server(server_of, batch):
    from meshcat.commands import SetTransform

    server = server_of(batch)
    deep = "/meshcat" + "/a" * 3000
    single = umsgpack.packb(SetTransform(np.eye(4), type("P", (), {"lower": lambda self: deep})()).lower())
    for frames in ([b"\xff\xfe", b"", b""], [b"set_transform", deep.encode(), single]):
        assert ask(server, frames).startswith(b"error: ")
    assert ask(server, [b"url"]) == server.web_url.encode()  # still answering


@pytest.mark.unit
def test_a_page_that_closed_meanwhile_is_skipped_and_the_others_still_get_the_frame():
    from types import SimpleNamespace

    import tornado.websocket

    from tutorial.tools.standalone.meshcat_server import _bridge_classes

    class Page:
        def __init__(self, closed: bool):
            self.closed, self.got = closed, []

        def write_message(self, data, binary=False):
            if self.closed:
                raise tornado.websocket.WebSocketClosedError()
            self.got.append((data, binary))

    gone, open_page = Page(closed=True), Page(closed=False)
    LocalhostBridge, _ = _bridge_classes()
    LocalhostBridge.forward_to_websockets(SimpleNamespace(websocket_pool={gone, open_page}), [b"k", b"", b"frame"])
    assert open_page.got == [(b"frame", True)]


@pytest.mark.cross_process
def test_meshcats_own_server_serves_meshcats_own_page_and_the_project_server_its_page(server_of):
    import meshcat.servers.zmqserver as z

    own = urllib.request.urlopen(server_of(False).web_url, timeout=10).read()
    with open(f"{z.VIEWER_ROOT}/{z.VIEWER_HTML}", "rb") as f:
        assert own == f.read()
    ours = urllib.request.urlopen(server_of(True).web_url, timeout=10).read().decode()
    assert ours == meshcat_page.with_page_script(own.decode())
    assert ours.startswith(own.decode()[: own.decode().rfind("</body>")])  # meshcat's page, unchanged, then ours
    assert ours.count("<script>") == own.decode().count("<script>") + 1


@pytest.mark.unit
def test_a_programs_page_is_also_named_through_the_jupyter_it_runs_under():
    """rtt-run's line: under a JupyterHub (its server's environment) or in a Jupyter terminal, the page through
    jupyter-server-proxy as well; outside Jupyter, the page alone.  tests/test_hub.py opens it on a hub."""
    from tutorial.tools.rtt_run import format_record
    from tutorial.tools.standalone.meshcat_server import through_jupyter

    url = "http://127.0.0.1:7003/static/"
    hub = {"JUPYTERHUB_SERVICE_PREFIX": "/user/ada/", "JUPYTER_SERVER_URL": "http://127.0.0.1:41000/user/ada/"}
    assert through_jupyter(url, hub) == "/user/ada/proxy/7003/static/"  # the hub's own address is not known
    public = dict(hub, JUPYTERHUB_PUBLIC_URL="https://hub.example.edu/user/ada/")
    assert through_jupyter(url, public) == "https://hub.example.edu/user/ada/proxy/7003/static/"
    terminal = {"JUPYTER_SERVER_URL": "http://127.0.0.1:8888/"}
    assert through_jupyter(url, terminal) == "http://127.0.0.1:8888/proxy/7003/static/"
    assert through_jupyter(url, {}) is None
    record = {"event": "meshcat", "node": "/rtt", "url": url}
    assert format_record(record) == f"[/rtt] meshcat: open {url} in a browser"
    assert format_record(dict(record, through_jupyter=through_jupyter(url, hub))) == (
        "[/rtt] meshcat: open this JupyterHub's address followed by /user/ada/proxy/7003/static/ in a browser"
    )
    assert format_record(dict(record, through_jupyter=through_jupyter(url, terminal))) == (
        f"[/rtt] meshcat: open {url} in a browser, or through Jupyter: http://127.0.0.1:8888/proxy/7003/static/"
    )


# ---- the page, in a real browser ----------------------------------------------------------------------


@pytest.mark.browser
@pytest.mark.skipif(chromium() is None, reason="chromium is not installed (make test installs it)")
def test_the_page_draws_every_transform_of_a_batch_from_one_websocket_message(server_of):
    import meshcat.geometry as g
    import zmq

    from jupyterlab import browser

    server = server_of(True)
    vis = server.visualizer()
    for name in ("a", "b", "c"):
        vis[name].set_object(g.Box([0.1, 0.1, 0.1]))
    sock = zmq.Context.instance().socket(zmq.REQ)
    sock.setsockopt(zmq.LINGER, 0)
    sock.connect(server.zmq_url)
    with browser(480, 380) as page:
        # Count the WebSocket messages the page is sent, before meshcat's script makes its socket.
        page.add_init_script(
            """
            window.__messages = 0;
            const Native = window.WebSocket;
            window.WebSocket = function (url, protocols) {
              const ws = protocols === undefined ? new Native(url) : new Native(url, protocols);
              ws.addEventListener("message", () => { window.__messages += 1; });
              return ws;
            };
            window.WebSocket.prototype = Native.prototype;
            """
        )
        page.goto(server.web_url)
        page.wait_for_function("window.viewer && viewer.scene_tree.find(['meshcat', 'c', '<object>']).object.isMesh")
        before = page.evaluate("window.__messages")
        commands = [lowered(f"/meshcat/{name}", pose(x, 2 * x)) for name, x in (("a", 0.5), ("b", 1.5), ("c", -2.5))]
        try:
            sock.send_multipart([b"set_transforms", b"", pack_batch(commands)])
            assert sock.poll(10000) and sock.recv() == b"ok"
        finally:
            sock.close()
        page.wait_for_function("viewer.scene_tree.find(['meshcat', 'c']).object.position.x === -2.5", timeout=10000)
        drawn = page.evaluate(
            "['a', 'b', 'c'].map(n => viewer.scene_tree.find(['meshcat', n]).object.position.toArray())"
        )
        assert drawn == [[0.5, 1.0, 0.0], [1.5, 3.0, 0.0], [-2.5, -5.0, 0.0]]
        assert page.evaluate("window.__messages") - before == 1


# make test: the page's other software-renderer setting (fewer triangles, below)
@pytest.mark.more
@pytest.mark.browser
@pytest.mark.skipif(chromium() is None, reason="chromium is not installed (make test installs it)")
def test_the_page_leaves_out_multisampling_on_a_software_renderer_unless_asked(server_of):
    from jupyterlab import browser

    server = server_of(True)
    attributes = "viewer.renderer.getContext().getContextAttributes().antialias"
    with browser(480, 380) as page:
        page.goto(server.web_url)
        page.wait_for_function("window.rttPage !== undefined")
        chosen = page.evaluate("window.rttPage")
        assert "SwiftShader" in chosen["renderer"]  # this machine has no GPU: Chromium rasterizes on the CPU
        assert chosen["software"] is True and chosen["antialias"] is False
        assert page.evaluate(attributes) is False
        assert page.evaluate("document.querySelectorAll('#meshcat-pane canvas').length") == 1  # replaced, not added
        assert messages_after_one(page) == 1  # meshcat's bundled GIF worker does not answer it
        page.goto(server.web_url + "?antialias=1")
        page.wait_for_function("window.rttPage !== undefined")
        assert page.evaluate("window.rttPage.antialias") is True
        assert page.evaluate(attributes) is True


@pytest.mark.browser
@pytest.mark.skipif(chromium() is None, reason="chromium is not installed (make test installs it)")
def test_the_page_draws_round_shapes_with_fewer_triangles_on_a_software_renderer_unless_asked(server_of):
    import meshcat.geometry as g

    from jupyterlab import browser

    server = server_of(True)
    vis = server.visualizer()  # set before the pages open: each page gets the server's stored objects
    vis["s"].set_object(g.Sphere(0.1))
    vis["c"].set_object(g.Cylinder(0.2, 0.1))
    vis["b"].set_object(g.Box([0.1, 0.2, 0.3]))
    vis["t"].set_object(g.Sphere(0.1), g.MeshLambertMaterial(opacity=0.5, transparent=True))
    vis["o"].set_object(g.Box([0.1, 0.1, 0.1]), g.MeshLambertMaterial(depthTest=False))
    parameters = """['s', 'c', 'b'].map(n => {
        const p = viewer.scene_tree.find(['meshcat', n, '<object>']).object.geometry.parameters;
        return [p.widthSegments, p.heightSegments, p.radialSegments, p.width, p.height, p.depth];
    })"""
    sides = "'scbto'.split('').map(n => viewer.scene_tree.find(['meshcat', n, '<object>']).object.material.side)"
    loaded = "window.viewer && viewer.scene_tree.find(['meshcat', 'b', '<object>']).object.isMesh"
    with browser(480, 380) as page:
        page.goto(server.web_url)
        page.wait_for_function(loaded)
        assert page.evaluate("window.rttPage.detail") == "low"  # SwiftShader: this machine has no GPU
        sphere, cylinder, box = page.evaluate(parameters)
        assert sphere[:2] == [12, 8] and cylinder[2] == 16
        assert box[3:] == [0.1, 0.2, 0.3]  # a box has no segments to spare: as sent
        # Opaque closed shapes: their back faces are never seen.  The see-through sphere and the box drawn
        # over everything (depthTest off) keep both sides: their back faces show through.
        assert page.evaluate(sides) == [FRONT_SIDE] * 3 + [DOUBLE_SIDE] * 2
        page.goto(server.web_url + "?detail=full")  # the server kept meshcat's own counts for every page
        page.wait_for_function(loaded)
        assert page.evaluate("window.rttPage.detail") == "full"
        sphere, cylinder, box = page.evaluate(parameters)
        assert sphere[:2] == [20, 20] and cylinder[2] == 50
        assert page.evaluate(sides) == [DOUBLE_SIDE] * 5  # meshcat's materials, as sent


FRONT_SIDE, DOUBLE_SIDE = 0, 2  # three.js's THREE.FrontSide, THREE.DoubleSide (meshcat-python sends 2)


@pytest.mark.browser
@pytest.mark.skipif(chromium() is None, reason="chromium is not installed (make test installs it)")
def test_the_page_paints_meshcats_background_once_under_the_canvas_and_it_looks_the_same(server_of):
    import io

    import meshcat.geometry as g
    from PIL import Image

    from jupyterlab import browser

    server = server_of(True)
    vis = server.visualizer()  # boxes: the same triangles in both details, so only sides and background differ
    vis["opaque"].set_object(g.Box([0.4, 0.4, 0.4]), g.MeshLambertMaterial(color=0xCC3333))
    vis["opaque"].set_transform(pose(0.0, 0.6))
    glass = g.MeshLambertMaterial(color=0x3333CC, opacity=0.5, transparent=True)
    vis["glass"].set_object(g.Box([0.6, 0.6, 0.6]), glass)
    loaded = "window.rttPage !== undefined && viewer.scene_tree.find(['meshcat', 'glass', '<object>']).object.isMesh"

    def picture(data: bytes) -> np.ndarray:
        return np.asarray(Image.open(io.BytesIO(data)).convert("RGBA"), dtype=int)

    def captured(page) -> np.ndarray:
        url = page.evaluate("viewer.capture_image()")  # meshcat's "save image": the canvas alone
        return picture(base64.b64decode(url.split(",", 1)[1]))

    # The canvas right after one render, in the same task (before the browser may clear it); as a frame
    # of meshcat's animation recording when `recording`.
    rendered = """(recording) => {
        viewer.animator.recording = recording;
        try { viewer.render(); return viewer.renderer.domElement.toDataURL(); }
        finally { viewer.animator.recording = false; }
    }"""

    with browser(480, 380) as page:
        page.goto(server.web_url + "?detail=full")  # meshcat's own: a textured quad drawn each frame
        page.wait_for_function(loaded)
        assert page.evaluate("viewer.scene.background !== null")
        meshcats, meshcats_image = picture(page.screenshot()), captured(page)
        page.goto(server.web_url + "?detail=low")  # a CSS gradient under a transparent canvas
        page.wait_for_function(loaded)
        assert page.evaluate("viewer.scene.background") is None
        assert "linear-gradient" in page.evaluate("viewer.renderer.domElement.style.background")
        ours, our_image = picture(page.screenshot()), captured(page)
        assert page.evaluate("viewer.scene.background") is None  # the capture put meshcat's back only for itself
        # The same picture, to a unit of rounding: the gradient, top (light sky blue) to bottom (midnight
        # blue); the opaque box from the front only; the see-through box with its back faces showing.
        assert tuple(ours[0, 0]) != tuple(ours[-1, 0])
        assert np.abs(ours - meshcats).max() <= 2
        assert np.abs(our_image - meshcats_image).max() <= 2  # a saved image keeps its background too
        # A frame of meshcat's animation recording is read from the canvas: it gets meshcat's background;
        # a frame on screen leaves the canvas see-through over the CSS gradient.
        recorded = picture(base64.b64decode(page.evaluate(rendered, True).split(",", 1)[1]))
        on_screen = picture(base64.b64decode(page.evaluate(rendered, False).split(",", 1)[1]))
        assert np.abs(recorded[0, 0] - meshcats_image[0, 0]).max() <= 2 and recorded[0, 0, 3] == 255
        assert on_screen[0, 0, 3] == 0
        # meshcat's background texture is made once for a pair of colours, not once a picture.
        textures = "viewer.renderer.info.memory.textures"
        before = page.evaluate(textures)
        for _ in range(5):
            captured(page)
        assert page.evaluate(textures) == before
        page.evaluate("viewer.set_property(['Background'], 'visible', false)")  # meshcat's own control
        assert page.evaluate("viewer.renderer.domElement.style.background") == ""
        page.evaluate("viewer.set_property(['Background'], 'top_color', [1, 0, 0])")
        page.evaluate("viewer.set_property(['Background'], 'visible', true)")
        assert "rgb(255, 0, 0)" in page.evaluate("viewer.renderer.domElement.style.background")
        assert tuple(captured(page)[0, 0, :3]) == (255, 0, 0)  # the new colours' texture, the old one let go
        assert page.evaluate(textures) == before


# ---- the scene's socket: its fallback, a refusal, a timeout (a stand-in server in a thread) ------------


class StandInServer:
    """A zmq REP socket on 127.0.0.1 answering each request from ``replies`` in turn; a thread of its own.

    A reply may be an ``threading.Event``-gated one: ``(event, reply)`` waits for the event (10 s at most)
    before answering.  Requests are kept; exceptions in the thread are collected in ``errors``.
    """

    def __init__(self, replies: list):
        import threading

        import zmq

        self.socket = zmq.Context.instance().socket(zmq.REP)
        self.socket.setsockopt(zmq.LINGER, 0)
        port = self.socket.bind_to_random_port("tcp://127.0.0.1")
        self.url = f"tcp://127.0.0.1:{port}"
        self.replies, self.requests, self.errors = list(replies), [], []
        self.thread = threading.Thread(target=self._serve, daemon=True)
        self.thread.start()

    def _serve(self) -> None:
        try:
            for reply in self.replies:
                if not self.socket.poll(10000):
                    return
                self.requests.append(self.socket.recv_multipart())
                if isinstance(reply, tuple):
                    event, reply = reply
                    assert event.wait(10), "the test never released the late reply"
                self.socket.send(reply)
        except Exception as error:  # collected: the test asserts there were none
            self.errors.append(error)

    def close(self) -> None:
        self.thread.join(15)
        self.socket.close()
        assert not self.thread.is_alive() and not self.errors, self.errors


FRAME = [("/meshcat/rtt/a", pose(1.0)), ("/meshcat/rtt/b", pose(2.0))]


@pytest.mark.unit
def test_meshcats_unknown_command_answer_turns_batching_off_and_the_frame_goes_as_singles():
    from tutorial.tools.standalone.sinks import BatchSink

    server = StandInServer([b"error: unrecognized comand", b"ok", b"ok", b"ok", b"ok"])
    pipe = BatchSink(server.url)
    try:
        pipe.send_transforms(FRAME)
        pipe.send_transforms(FRAME)
    finally:
        pipe.close()
        server.close()
    assert pipe.batch is False and pipe.messages == 1 + 2 + 2
    assert [r[0] for r in server.requests] == [b"set_transforms", b"set_transform", b"set_transform"] + [
        b"set_transform"
    ] * 2


@pytest.mark.unit
def test_any_other_refusal_of_a_frame_is_raised_not_hidden_by_a_fallback():
    from tutorial.tools.standalone.sinks import BatchSink

    server = StandInServer([b"error: not msgpack within the limits: ExtraData"])
    pipe = BatchSink(server.url)
    try:
        with pytest.raises(RuntimeError, match="refused a frame"):
            pipe.send_transforms(FRAME)
        assert pipe.batch is True
    finally:
        pipe.close()
        server.close()


@pytest.mark.unit
def test_after_a_timeout_a_late_reply_is_not_taken_for_the_next_frames():
    import threading

    from tutorial.tools.standalone.sinks import BatchSink

    release = threading.Event()
    # The first frame's reply comes late, and says something the next frame must never read as its own.
    server = StandInServer([(release, b"error: the first frame's late reply"), b"ok"])
    pipe = BatchSink(server.url)
    try:
        with pytest.raises(RuntimeError, match="did not answer"):
            pipe.send_transforms(FRAME, timeout_ms=200)
        release.set()
        pipe.send_transforms(FRAME, timeout_ms=10000)  # its own reply: ok
        assert pipe.batch is True
    finally:
        release.set()
        pipe.close()
        server.close()

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
from tutorial.view.meshcat_batch import BadBatch, pack_batch, split_batch

from browser import chromium
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


@pytest.mark.unit
@pytest.mark.parametrize(
    "data",
    [
        b"\xc1",  # never used in msgpack
        umsgpack.packb([1, 2, 3]),
        umsgpack.packb({"type": "set_transform", "commands": []}),
        umsgpack.packb({"type": "set_transforms", "commands": "no"}),
        umsgpack.packb({"type": "set_transforms", "commands": [{"type": "delete", "path": "/a"}]}),
        umsgpack.packb(
            {"type": "set_transforms", "commands": [{"type": "set_transform", "path": 3, "matrix": [0.0] * 16}]}
        ),
        umsgpack.packb(
            {"type": "set_transforms", "commands": [{"type": "set_transform", "path": "/a", "matrix": [0.0] * 15}]}
        ),
        umsgpack.packb(
            {"type": "set_transforms", "commands": [{"type": "set_transform", "path": "/a", "matrix": [True] * 16}]}
        ),
        umsgpack.packb(
            {"type": "set_transforms", "commands": [{"type": "set_transform", "path": "/a", "matrix": ["1"] * 16}]}
        ),
    ],
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
def server_of(request):
    servers = []

    def start(batch: bool):
        from tutorial.view.meshcat_server import start_server

        servers.append(start_server(batch=batch))
        return servers[-1]

    yield start
    for s in servers:
        s.close()


@pytest.mark.cross_process
@pytest.mark.parametrize("batch", [True, False], ids=["project_server", "meshcats_own_server"])
def test_the_scene_sends_a_frame_as_one_message_where_it_can_and_every_pose_arrives(server_of, batch):
    from tutorial.view.scene import Scene

    server = server_of(batch)
    model, data = tank()
    vis = server.visualizer()
    scene = Scene(vis, model)
    try:
        scene.build(data)  # the first frame: three moving bodies
        first = scene._pipe.messages
        data.qpos[0] += 0.5  # the chassis moves: the turret and the barrel ride on it
        mujoco.mj_kinematics(model, data)
        assert scene.update(data) == 3
        frame = scene._pipe.messages - first
        assert scene._pipe.batch is batch
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


@pytest.mark.cross_process
def test_a_bad_batch_is_answered_with_an_error_and_the_server_goes_on(server_of):
    import zmq

    server = server_of(True)
    sock = zmq.Context.instance().socket(zmq.REQ)
    sock.setsockopt(zmq.LINGER, 0)
    sock.connect(server.zmq_url)
    try:
        for frames in ([b"set_transforms", b"", b"\xc1"], [b"set_transforms", b""]):
            sock.send_multipart(frames)
            assert sock.poll(10000)
            assert sock.recv().startswith(b"error: ")
        good = pack_batch([lowered("/meshcat/box", pose(0.75))])
        sock.send_multipart([b"set_transforms", b"", good])
        assert sock.poll(10000)
        assert sock.recv() == b"ok"
    finally:
        sock.close()
    assert stored_transforms(server)["/meshcat/box"][12] == 0.75  # column-major: x is the 13th number
    assert server.process.poll() is None


@pytest.mark.cross_process
def test_meshcats_own_server_serves_meshcats_own_page_and_the_project_server_its_page(server_of):
    import meshcat.servers.zmqserver as z

    own = urllib.request.urlopen(server_of(False).web_url, timeout=10).read()
    with open(f"{z.VIEWER_ROOT}/{z.VIEWER_HTML}", "rb") as f:
        assert own == f.read()
    ours = urllib.request.urlopen(server_of(True).web_url, timeout=10).read().decode()
    assert ours == meshcat_page.PAGE_HTML
    assert 'src="main.min.js"' in ours


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
        page.goto(server.web_url + "?antialias=1")
        page.wait_for_function("window.rttPage !== undefined")
        assert page.evaluate("window.rttPage.antialias") is True
        assert page.evaluate(attributes) is True

"""rtt-foxglove serves the live tank: a client of the Foxglove WebSocket protocol (written here, on
the ``websockets`` package) subscribes to the joint states and to /tf and decodes them."""

from __future__ import annotations

import json
import re
import struct
import time

import numpy as np
import pytest

from conftest import module_command

# foxglove-sdk 0.30 speaks the protocol as "foxglove.sdk.v1" and refuses the old name; the Foxglove app
# offers both, as this client does (the messages are those of foxglove.websocket.v1).
SUBPROTOCOLS = ["foxglove.sdk.v1", "foxglove.websocket.v1"]
MESSAGE_DATA = 0x01  # the server's binary opcode for a message


class FoxgloveClient:
    """A minimal client of the Foxglove WebSocket protocol: advertise, subscribe, message data."""

    def __init__(self, ws):
        self.ws = ws  # a websockets.sync.client connection
        assert self.ws.subprotocol in SUBPROTOCOLS
        self.channels: dict[str, dict] = {}  # topic -> advertised channel
        self.subscriptions: dict[int, str] = {}  # subscription id -> topic
        self.decoders: dict[str, object] = {}

    def pump(self, until, timeout: float):
        """Read what the server sends until ``until(message)`` returns something; that."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            try:
                frame = self.ws.recv(timeout=max(0.01, deadline - time.monotonic()))
            except TimeoutError:
                break
            if isinstance(frame, str):
                op = json.loads(frame)
                if op.get("op") == "advertise":
                    for channel in op["channels"]:
                        self.channels[channel["topic"]] = channel
                found = until(("json", op))
            else:
                assert frame[0] == MESSAGE_DATA, frame[0]
                sub, log_time = struct.unpack_from("<IQ", frame, 1)
                found = until(("message", self.subscriptions[sub], log_time, bytes(frame[13:])))
            if found is not None:
                return found
        raise AssertionError(f"nothing matched in {timeout} s; channels: {sorted(self.channels)}")

    def subscribe(self, topic: str) -> None:
        from mcap_ros2._dynamic import generate_dynamic

        channel = self.channels[topic]
        assert channel["encoding"] == "cdr" and channel["schemaEncoding"] == "ros2msg"
        sub = len(self.subscriptions) + 1
        self.subscriptions[sub] = topic
        self.decoders[topic] = generate_dynamic(channel["schemaName"], channel["schema"])[channel["schemaName"]]
        self.ws.send(json.dumps({"op": "subscribe", "subscriptions": [{"id": sub, "channelId": channel["id"]}]}))


@pytest.mark.cross_process
def test_rtt_foxglove_serves_the_live_tank(procs):
    sim = procs(
        module_command("tutorial.tools.rtt_run", "project/step2.yaml", "--headless", "--duration", "60", "--describe")
    )
    bridge = procs(module_command("tutorial.tools.rtt_foxglove", "--port", "0", "--duration", "60"))
    line = bridge.wait_for_line(lambda s: "serving ws://127.0.0.1:" in s, timeout=30)
    url = re.search(r"ws://127\.0\.0\.1:\d+", line).group(0)
    bridge.wait_for_line(lambda s: "TF of Tank" in s, timeout=30)  # it has the description
    from websockets.sync.client import connect

    with connect(url, subprotocols=SUBPROTOCOLS, open_timeout=30, max_size=None) as ws:
        client = FoxgloveClient(ws)
        wanted = {"/Tank/joint_state", "/tf", "/tf_static", "/robot_description", "/Tank/odom"}
        client.pump(lambda m: True if wanted <= set(client.channels) else None, timeout=30)
        for topic in ("/Tank/joint_state", "/tf", "/tf_static", "/robot_description"):
            client.subscribe(topic)
        got: dict[str, object] = {}

        def collect(m):
            if m[0] == "message":
                got.setdefault(m[1], client.decoders[m[1]](m[3]))
            return True if {"/Tank/joint_state", "/tf", "/tf_static", "/robot_description"} <= set(got) else None

        client.pump(collect, timeout=30)
    state = got["/Tank/joint_state"]
    assert list(state.name) == ["TURRET_Y", "TURRET_P"] and len(state.position) == 2
    assert all(np.isfinite(state.position))
    moving = {(t.header.frame_id, t.child_frame_id) for t in got["/tf"].transforms}
    # /tf carries either the joints (CHASSIS -> TURRET_Y, TURRET_Y -> TURRET_P) or the odometry (world -> CHASSIS)
    assert moving in ({("CHASSIS", "TURRET_Y"), ("TURRET_Y", "TURRET_P")}, {("world", "CHASSIS")}), moving
    for t in got["/tf"].transforms:
        r = t.transform.rotation
        assert abs(r.x**2 + r.y**2 + r.z**2 + r.w**2 - 1.0) < 1e-9
    fixed = {t.child_frame_id for t in got["/tf_static"].transforms}
    assert fixed == {"TRACK_L", "TRACK_R"} | {f"TRACK_{s}_W{i}" for s in "LR" for i in range(4)}
    assert (
        got["/robot_description"].data.lstrip().startswith("<?xml")
        and '<robot name="Tank">' in got["/robot_description"].data
    )
    bridge.p.send_signal(2)
    assert bridge.wait(30) == 0, bridge.err
    sim.p.send_signal(2)
    assert sim.wait(30) == 0, sim.err

"""No traceback from any message our nodes subscribe to: generated messages into the real callbacks.

Every subscription in the library is listed in :data:`FUZZED` with the test
that feeds it generated messages of its type (NaN, infinities, huge and
empty arrays, names of any text, absurd image sizes): Step 1's ``/joy``,
Step 3's joint-state monitor (live and late-joiner paths), Step 5's IMU
viewer, ``rtt-image``'s receiver (raw and compressed), ``rtt-plot``'s history,
a viewer's robot description and its floating base's odometry.  Each
property checks that the callback does not raise, that a bad message is
rejected and counted (never applied in part where a whole is needed), and
that what is shown stays finite.  :func:`test_every_subscription_in_the_library_is_fuzzed`
fails when a new subscription appears without a property here.  No ROS context: the callbacks are called directly, with
message objects of the real types.
"""

from __future__ import annotations

import math
import re
import warnings
from types import SimpleNamespace

import mujoco
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tutorial.core.body import Body
from tutorial.core.controller import ControllerConfig, ControllerIO
from tutorial.core.world import ModelEntry, build_world

from conftest import MODEL, ROOT
from fuzzing import examples

pytestmark = pytest.mark.unit

# message type -> the property below that feeds generated messages of it to every subscriber of it
FUZZED = {
    "Joy": "test_step1_takes_any_joy",
    "JointState": "test_step3_monitor_takes_any_joint_state (and rtt-plot: test_rtt_plot_takes_any_joint_state)",
    "Imu": "test_step5_viewer_takes_any_imu",
    "Image": "test_rtt_image_receiver_takes_any_image",
    "CompressedImage": "test_rtt_image_receiver_takes_any_compressed_image",
    "String": "test_a_viewer_takes_any_robot_description",
    "Odometry": "test_a_floating_base_takes_any_odometry",
    "any_type": "test_rtt_ros2_echo_prints_any_message (rtt-ros2 echo and hz: any topic's type)",
}


def test_every_subscription_in_the_library_is_fuzzed():
    """Each message type the library subscribes to (by name, as the source writes it) has a property here."""
    subscribed = set()
    for path in (ROOT / "tutorial").rglob("*.py"):
        for match in re.finditer(r"create_subscription\(\s*(\w+)\s*,", path.read_text()):
            subscribed.add(match.group(1))
    subscribed.discard("msg_type")  # rtt-bag's recorder: raw bytes, never decoded (the bag fuzz covers reading)
    assert subscribed, "the scan found no subscription"
    assert subscribed <= set(FUZZED), f"subscribed but not fuzzed: {sorted(subscribed - set(FUZZED))}"


class FakeNode:
    """Stands in for the rclpy node: subscriptions are recorded, never made."""

    def create_subscription(self, msg_type, topic, callback, qos, **kw):
        return SimpleNamespace(msg_type=msg_type, topic_name=topic, callback=callback)

    def destroy_subscription(self, subscription):
        pass

    def get_fully_qualified_name(self):
        return "/fuzz"


TEXT = st.text(max_size=12)
FLOAT32 = st.floats(width=32)  # NaN and infinities included
FLOAT64 = st.floats()
INT32 = st.integers(-(2**31), 2**31 - 1)
UINT32 = st.integers(0, 2**32 - 1)


def stamp(msg, sec, nanosec):
    msg.header.stamp.sec, msg.header.stamp.nanosec = sec, nanosec
    return msg


def world(*files, odometry=None):
    model = build_world([ModelEntry(name, MODEL / f, odometry=odometry) for name, f in files])
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    return model, data


def configured(controller, name, model, data, output=lambda record: None) -> Body:
    """``controller`` configured on the tank of ``model`` with a fake node; returns that body."""
    body = Body(model, data, "Tank")
    assert controller.configure(ControllerConfig(name=name, body=body, node=FakeNode(), output=output))
    return body


# ------------------------------------------------------------ Step 1: /joy
def joys():
    from sensor_msgs.msg import Joy

    axes = st.lists(FLOAT32 | st.sampled_from([1.0, -1.0, 0.0]), max_size=12)
    return st.builds(
        lambda a, b, s: stamp(Joy(axes=a, buttons=b), *s), axes, st.lists(INT32, max_size=12), st.tuples(INT32, UINT32)
    )


@pytest.fixture(scope="module")
def tank_controller():
    from tutorial.controllers.tank_controller import RttTankController

    model, data = world(("Room", "room.xml"), ("Tank", "tank.xml"))
    controller = RttTankController()
    body = configured(controller, "C", model, data)
    assert controller.initialize(ControllerIO(body=body, time_step=model.opt.timestep, node=None, data=data))
    return controller, model, data


@examples(60)
@given(msg=joys())
def test_step1_takes_any_joy(tank_controller, msg):
    from tutorial.controllers import tank_controller as tc

    controller, model, data = tank_controller
    before = controller.summary()
    controller.on_joy(msg)  # the subscription callback
    for _ in range(3):
        assert controller.control()
        mujoco.mj_step(model, data)
    after = controller.summary()
    well_formed = len(msg.axes) >= 8 and len(msg.buttons) >= 8 and all(math.isfinite(a) for a in msg.axes)
    assert after["joy_received"] == before["joy_received"] + 1
    assert after["joy_malformed"] == before["joy_malformed"] + (not well_formed)
    for track in controller.tracks:
        assert math.isfinite(track.dq_target) and abs(track.dq_target) <= tc.TRACK_SPEED_GAIN + tc.TURN_SPEED_GAIN
    for joint, q_ref in zip(controller.turret, controller.q_ref):
        assert joint.info.lower <= q_ref <= joint.info.upper or not joint.info.limited
    assert np.isfinite(data.qpos).all()


# ------------------------------------------------------------ Step 3: /<body>/joint_state
TURRET = ["TURRET_Y", "TURRET_P"]


def joint_states():
    from sensor_msgs.msg import JointState

    names = st.lists(st.sampled_from(TURRET) | TEXT, max_size=6)
    values = st.lists(FLOAT64 | st.floats(-1.0, 1.0), max_size=6)
    return st.builds(
        lambda n, p, v, e, s, f: stamp(JointState(name=n, position=p, velocity=v, effort=e), *s),
        names,
        values,
        values,
        values,
        st.tuples(INT32, UINT32),
        TEXT,
    )


@pytest.fixture(scope="module")
def monitor():
    from tutorial.controllers.joint_state_subscriber import RttJointStateMonitor

    model, data = world(("Tank", "tank.xml"))
    records = []
    controller = RttJointStateMonitor()
    body = configured(controller, "M", model, data, records.append)
    return controller, body, records


@examples(60)
@given(msg=joint_states(), late=st.booleans())
def test_step3_monitor_takes_any_joint_state(monitor, msg, late):
    from tutorial.interfaces.joint_state import HINGE_TOLERANCE

    controller, body, records = monitor
    before = body.joint_positions()
    rejected_before = sum(controller.rejected.values())
    if late:  # the late joiner's subscription: shown only before any live state
        controller.late_subscription = controller.late_subscription or object()
        controller.on_late_state(msg)
    controller.on_joint_state(msg)  # the live subscription (call_later runs it at once here)
    controller.report_status()
    controller.check_stale()
    entries = max(len(msg.name), len(msg.position))
    applied = {n for n, q in zip(msg.name, msg.position) if n in TURRET and msg.name.count(n) == 1}
    assert sum(controller.rejected.values()) - rejected_before <= entries
    after = body.joint_positions()
    for info in body.joint_infos:
        q = after[info.name]
        assert math.isfinite(q)
        if info.limited:
            assert info.lower - HINGE_TOLERANCE <= q <= info.upper + HINGE_TOLERANCE
        if info.name not in applied:
            assert q == before[info.name]  # a joint the message did not name well keeps its value
    status = [r for r in records if r["event"] == "status"][-1]  # check_stale() may have said "stale" after it
    assert status["matched"] <= len(TURRET)


def test_rtt_plot_takes_any_joint_state():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from tutorial.view.joint_plot import JointStateHistory, draw

    # The examples share one history, as one run's messages do; at most 50 samples of it, so that each
    # example draws a bounded plot (unbounded, make fuzz's 2,000 examples drew ever more lines and
    # ran past pytest's 300 s on a slow hour) and the dropping of the oldest samples is exercised too.
    history = JointStateHistory(FakeNode(), "/Tank/joint_state", max_samples=50)
    fig, ax = plt.subplots()

    @examples(20)
    @given(msg=joint_states())
    def property_(msg):
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # matplotlib's overflow warning for a huge value: none allowed
            history.on_message(msg)
            draw(ax, history.series(), "/Tank/joint_state")
        assert all(abs(q) <= 1e6 for _t, values in history.samples for q in values.values())

    try:
        property_()
    finally:
        plt.close(fig)


# ------------------------------------------------------------ Step 5: /<body>/imu
def imus():
    from sensor_msgs.msg import Imu

    def build(a, w, frame, s):
        msg = Imu()
        msg.linear_acceleration.x, msg.linear_acceleration.y, msg.linear_acceleration.z = a
        msg.angular_velocity.x, msg.angular_velocity.y, msg.angular_velocity.z = w
        msg.header.frame_id = frame
        return stamp(msg, *s)

    vector = st.tuples(*[FLOAT64 | st.floats(-50, 50)] * 3)
    frames = st.sampled_from(["", "CHASSIS", "map"]) | TEXT
    return st.builds(build, vector, vector, frames, st.tuples(INT32, UINT32))


@pytest.fixture(scope="module")
def imu_viewer():
    from tutorial.controllers.imu_state_subscriber import RttImuStateSubscriber

    model, data = world(("Tank", "tank.xml"))
    controller = RttImuStateSubscriber()
    configured(controller, "I", model, data)
    return controller


@examples(60)
@given(msg=imus())
def test_step5_viewer_takes_any_imu(imu_viewer, msg):
    controller = imu_viewer
    before = controller.summary()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a numpy overflow warning on stderr reads like a traceback: none allowed
        controller.on_imu(msg)  # the subscription callback (call_later runs the update at once here)
        controller.shake_tick()
        controller.report_status()
    s = controller.summary()
    handled = s["accepted"] + sum(s["rejected"].values()) - before["accepted"] - sum(before["rejected"].values())
    assert s["received"] == before["received"] + 1 and handled == 1  # shown, or rejected and counted
    for arrow in (controller.accel_arrow, controller.gyro_arrow):
        assert np.isfinite(arrow.vector).all() and np.isfinite(arrow.origin).all()


# ------------------------------------------------------------ a viewer's floating base: /<body>/odom
def odometries():
    from nav_msgs.msg import Odometry

    def build(p, q, child, s):
        msg = Odometry()
        msg.pose.pose.position.x, msg.pose.pose.position.y, msg.pose.pose.position.z = p
        o = msg.pose.pose.orientation
        o.w, o.x, o.y, o.z = q
        msg.child_frame_id = child
        return stamp(msg, *s)

    position = st.tuples(*[FLOAT64 | st.floats(-100, 100) | st.sampled_from([2e6, -1e300])] * 3)
    near_unit = st.tuples(*[st.floats(-1, 1)] * 4).map(lambda q: tuple(c / (math.hypot(*q) or 1.0) for c in q))
    rotation = near_unit | st.tuples(*[FLOAT64] * 4)
    child = st.sampled_from(["", "CHASSIS"]) | TEXT
    return st.builds(build, position, rotation, child, st.tuples(INT32, UINT32))


@pytest.fixture(scope="module")
def floating_base():
    from tutorial.tools.standalone.floating_base import FloatingBase

    model, data = world(("Tank", "tank.xml"), odometry="/Tank/odom")
    controller = FloatingBase("/Tank/odom")
    configured(controller, "F", model, data)
    return controller


@examples(60)
@given(msg=odometries())
def test_a_floating_base_takes_any_odometry(floating_base, msg):
    controller = floating_base
    before = controller.summary()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        controller.on_odometry(msg)  # the subscription callback (call_later runs the update at once here)
    s = controller.summary()
    handled = s["applied"] + sum(s["rejected"].values()) - before["applied"] - sum(before["rejected"].values())
    assert handled == 1  # placed, or refused and counted
    if s["applied"] == before["applied"]:  # refused: the robot stays where it was
        assert s["position"] == before["position"] and s["orientation_wxyz"] == before["orientation_wxyz"]
    assert np.isfinite(controller.body.data.xpos).all() and np.isfinite(controller.body.data.xquat).all()
    assert abs(np.linalg.norm(s["orientation_wxyz"]) - 1.0) < 1e-6


# ------------------------------------------------------------ rtt-image: /<body>/camera/image
def images():
    from sensor_msgs.msg import Image

    side = st.integers(0, 24) | st.sampled_from([8192, 8193, 2**31, 2**32 - 1])

    @st.composite
    def build(draw):
        msg = Image()
        msg.height, msg.width = draw(side), draw(side)
        msg.encoding = draw(st.sampled_from(["rgb8", "bgr8", "rgba8", "bgra8", "mono8", "16UC1", ""]) | TEXT)
        msg.step = draw(st.integers(0, 120) | UINT32)
        msg.is_bigendian = draw(st.integers(0, 255))
        exact = msg.step * msg.height
        if exact <= 20_000 and draw(st.booleans()):
            msg.data = bytes(exact)
        else:
            msg.data = draw(st.binary(max_size=64))
        msg.header.frame_id = draw(TEXT)
        return stamp(msg, draw(INT32), draw(UINT32))

    return build()


def test_rtt_image_receiver_takes_any_image():
    from tutorial.view.images import ImageReceiver

    receiver = ImageReceiver(FakeNode(), "/Tank/camera/image")

    @examples(60)
    @given(msg=images())
    def property_(msg):
        before = receiver.counts()
        receiver.on_image(msg)  # the subscription callback
        after = receiver.counts()
        assert after["accepted"] + after["rejected"] == before["accepted"] + before["rejected"] + 1
        if after["accepted"] > before["accepted"]:
            assert receiver.newest().pixels.shape == (msg.height, msg.width, 3)

    property_()


def compressed_images():
    """CompressedImages: real JPEG and PNG files (whole, cut, with bytes changed), junk, and any format text."""
    import io

    from PIL import Image as PilImage
    from sensor_msgs.msg import CompressedImage

    def encoded(codec: str, width: int, height: int) -> bytes:
        buf = io.BytesIO()
        PilImage.fromarray(np.full((height, width, 3), 90, np.uint8)).save(buf, format=codec)
        return buf.getvalue()

    files = {codec: encoded(codec, 5, 3) for codec in ("JPEG", "PNG")}

    @st.composite
    def build(draw):
        msg = CompressedImage()
        msg.format = draw(
            st.sampled_from(["rgb8; jpeg compressed bgr8", "jpeg", "png", "rgb8; png compressed rgb8", "", "bmp"])
            | TEXT
        )
        data = draw(st.sampled_from(list(files.values())) | st.binary(max_size=64))
        if data and draw(st.booleans()):
            cut = draw(st.integers(0, len(data) - 1))
            data = data[:cut] + draw(st.binary(max_size=8)) + data[cut + draw(st.integers(0, 8)) :]
        msg.data = data
        msg.header.frame_id = draw(TEXT)
        return stamp(msg, draw(INT32), draw(UINT32))

    return build()


def test_rtt_image_receiver_takes_any_compressed_image():
    from tutorial.view.images import ImageReceiver

    receiver = ImageReceiver(FakeNode(), "/Tank/camera/image", transport="compressed")

    @examples(60)
    @given(msg=compressed_images())
    def property_(msg):
        before = receiver.counts()
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # a decoder's warning is a failure too: it reaches the user's terminal
            receiver.on_image(msg)  # the subscription callback
        after = receiver.counts()
        assert after["accepted"] + after["rejected"] == before["accepted"] + before["rejected"] + 1
        if after["accepted"] > before["accepted"]:
            pixels = receiver.newest().pixels
            assert pixels.ndim == 3 and pixels.shape[2] == 3 and pixels.dtype == np.uint8

    property_()


def test_a_viewer_takes_any_robot_description():
    """What a viewer does with a received description (``load_description``, then the world) raises only
    ``DescriptionError`` or ``ValueError`` (``rtt-run``: one line), whatever the text: junk, or the tank's
    own URDF cut short, with a value or a name changed."""
    from tutorial.interfaces.robot_description import DescriptionError
    from tutorial.tools.urdf.export import export_body
    from tutorial.tools.urdf.mujoco_load import load_description

    model = build_world([ModelEntry("Tank", MODEL / "tank.xml")])
    tank = export_body(Body(model, mujoco.MjData(model), "Tank")).xml()
    numbers = [m.span() for m in re.finditer(r'"-?[0-9.e+-]+"', tank)]

    @st.composite
    def texts(draw):
        kind = draw(st.sampled_from(["junk", "cut", "value", "name"]))
        if kind == "junk":
            return draw(st.text(max_size=200) | st.sampled_from(["<robot/>", '<robot name="r"><link/></robot>']))
        if kind == "cut":
            return tank[: draw(st.integers(0, len(tank)))]
        if kind == "value":
            a, b = draw(st.sampled_from(numbers))
            value = draw(st.sampled_from(['"nan"', '"inf"', '"-1e999"', '""', '"x"', '"1 2"']))
            return tank[:a] + value + tank[b:]
        name = draw(st.sampled_from([m.group(1) for m in re.finditer(r'name="([^"]+)"', tank)]))
        return tank.replace(f'name="{name}"', f'name="{draw(TEXT)}"', 1)

    @examples(40)
    @given(text=texts())
    def property_(text):
        try:
            prepared, _ = load_description(text, "/Tank/robot_description")
            build_world([ModelEntry("Tank", None, description="/Tank/robot_description", text=prepared.text)])
        except (DescriptionError, ValueError):
            pass  # refused, as rtt-run reports it: one line, exit status 2

    property_()


def test_rtt_ros2_echo_prints_any_message():
    """``rtt-ros2 topic echo`` prints whatever arrives: NaN, infinities, any text, long arrays, as YAML that
    reads back with the message's fields in their order (``hz`` only counts arrivals)."""
    import yaml
    from nav_msgs.msg import Odometry
    from sensor_msgs.msg import Imu, JointState

    from tutorial.ros.messages import to_yaml

    @examples(40)
    @given(
        name=st.lists(TEXT, max_size=300),
        position=st.lists(st.floats(), max_size=300),
        frame=TEXT,
        q=st.floats(),
        covariance=st.lists(st.floats(), min_size=36, max_size=36),
    )
    def property_(name, position, frame, q, covariance):
        state = JointState(name=name, position=position)
        state.header.frame_id = frame
        imu = Imu()
        imu.orientation.w = q
        odometry = Odometry()
        odometry.pose.covariance = covariance
        for msg in (state, imu, odometry):
            text = to_yaml(msg)
            assert list(yaml.safe_load(text)) == list(msg.get_fields_and_field_types())
        shown = yaml.safe_load(to_yaml(state))
        assert len(shown["name"]) == min(len(name), 128) + (len(name) > 128)  # cut at 128, then '...'

    property_()

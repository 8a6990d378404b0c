"""The parts of the checks of notebooks 05 and 06 that whole answers do not pin down: no simulation, no ROS node.

The exercises' tests (tests/test_exercises.py) run each check on worked
solutions and on wrong answers.  These hold the hidden runs' draws to what
their statements promise, and the checks' own model of a rule to the rule
at its edge (found by make mutate: a mutant of each survived the whole
answers).
"""

from __future__ import annotations

import functools
import math
import random

import numpy as np
import pytest

from tutorial.exercises import step5_imu_viewer as step5

pytestmark = pytest.mark.unit

SECOND, GRID = step5.SECOND, step5.GRID
SEEDS = range(400)


# ---- 5.2's rule, as the check models it --------------------------------------------------------------


def test_5_2_the_rule_a_stamp_up_to_a_second_back_is_old_news_and_further_back_a_restart():
    newest = 7 * SECOND
    assert step5._judge(None, 0, "ok") == (None, 0)  # the first message is shown
    assert step5._judge(newest, newest, "ok") == ("out_of_order", newest)  # the same stamp
    assert step5._judge(newest, newest - SECOND, "hit") == ("out_of_order", newest)  # exactly a second back
    assert step5._judge(newest, newest - SECOND - 1, "ok") == (None, newest - SECOND - 1)  # 1 ns more: a restart
    assert step5._judge(newest, newest + 1, "ok") == (None, newest + 1)
    assert step5._judge(newest, newest + 1, "nan") == ("not_finite", newest)  # refused, the newest kept
    assert step5._judge(newest, newest - 1, "nan") == ("out_of_order", newest)  # old news before anything else


# ---- 5.2's hidden runs -----------------------------------------------------------------------------


def newest_before(messages) -> list:
    """The newest stamp shown before each message, by the rule (None before the first)."""
    out = [None]
    for stamp, kind in messages[:-1]:
        out.append(step5._judge(out[-1], stamp, kind)[1])
    return out


def hows(messages) -> list[str]:
    """What each message after the first is, by the rule: newer, same, late, second (back), restart."""
    out = []
    for (stamp, kind), newest in zip(messages[1:], newest_before(messages)[1:]):
        if stamp > newest:
            out.append("nan" if kind == "nan" else "newer")
        elif stamp == newest:
            out.append("same")
        elif stamp == newest - SECOND:
            out.append("second")
        elif stamp > newest - SECOND:
            out.append("late")
        else:
            out.append("restart")
    return out


@pytest.mark.parametrize("n", [1, 2, 14, 30])
def test_5_2_a_random_run_has_its_length_and_starts_between_1_and_60_s_with_a_plain_message(n):
    for seed in SEEDS:
        messages = step5._messages(random.Random(seed), n)
        assert len(messages) == n
        first, kind = messages[0]
        assert SECOND <= first < 60 * SECOND and first % GRID == 0 and kind == "ok"


def test_5_2_random_runs_stay_on_the_grid_above_0_and_a_grid_away_from_a_second_back_unless_exactly_on_it():
    firsts = []
    for seed in SEEDS:
        messages = step5._messages(random.Random(seed), 14)
        firsts.append(messages[0][0])
        for (stamp, kind), newest in zip(messages[1:], newest_before(messages)[1:]):
            assert stamp >= 0 and stamp % GRID == 0 and kind in ("ok", "hit", "nan")
            back = newest - SECOND
            assert stamp == back or abs(stamp - back) >= GRID
            if stamp == back:  # exactly a second back: a pair of whole seconds, exact as float seconds
                assert newest // SECOND in step5.WHOLE_SECONDS and newest % SECOND == 0
    assert min(firsts) < 2 * SECOND and max(firsts) > 59 * SECOND  # the whole range of firsts is drawn


def test_5_2_random_runs_draw_every_kind_of_message_the_statement_names():
    seen, kinds = set(), set()
    steps_newer, steps_late = [], []
    for seed in SEEDS:
        messages = step5._messages(random.Random(seed), 14)
        said = hows(messages)
        seen |= set(said)
        kinds |= {k for _, k in messages}
        for i, ((stamp, _), how, newest) in enumerate(zip(messages[1:], said, newest_before(messages)[1:])):
            # the first of a pair (a whole second, then a second back of it; the run may end between them)
            pair = stamp % SECOND == 0 and (i + 1 == len(said) or said[i + 1] == "second")
            if how == "newer" and not pair:
                steps_newer.append((stamp - newest) // GRID)
            elif how == "late":
                steps_late.append((newest - stamp) // GRID)
    assert seen == {"newer", "same", "late", "second", "restart", "nan"}
    assert kinds == {"ok", "hit", "nan"}
    # newer by 1 to 99 grid steps, late by 1 to 511: both ends drawn, never a second or more
    assert min(steps_newer) == 1 and max(steps_newer) == 99
    assert min(steps_late) == 1 and max(steps_late) == 511


def draws(messages) -> list[str]:
    """The draws a run was made of, in order: a "second" draw is two messages (a whole second, then a second back)."""
    said, out, i = hows(messages), [], 0
    while i < len(said):
        if i + 1 < len(said) and said[i + 1] == "second":
            out.append("second")
            i += 2
        else:
            out.append(said[i])
            i += 1
    return out


def test_5_2_random_runs_draw_each_kind_as_often_as_the_statement_weighs_it():
    """3 newer, 2 late, 1 each of the same stamp, a second back, a restart, a NaN: in 9."""
    counts: dict[str, int] = {}
    for seed in SEEDS:
        for draw in draws(step5._messages(random.Random(seed), 14))[:-1]:  # the last may be a cut pair
            counts[draw] = counts.get(draw, 0) + 1
    total = sum(counts.values())
    weights = {"newer": 3, "late": 2, "same": 1, "second": 1, "restart": 1, "nan": 1}
    for draw, weight in weights.items():
        assert abs(counts[draw] / total - weight / 9) < 0.03, (draw, counts[draw] / total, counts)


def test_5_2_a_second_back_follows_a_whole_second_newer_than_everything_before_it():
    pairs = 0
    for seed in SEEDS:
        messages = step5._messages(random.Random(seed), 30)
        newest = newest_before(messages)
        for i, how in enumerate(hows(messages), start=1):
            if how == "second":
                pairs += 1
                assert messages[i - 1][0] == messages[i][0] + SECOND
                assert messages[i - 1][0] > newest[i - 1]  # the whole second was newer than all before it
                # and one of the next three whole seconds: the run stays within a few seconds
                ahead = [w for w in step5.WHOLE_SECONDS if w * SECOND > newest[i - 1]][:3]
                assert messages[i - 1][0] // SECOND in ahead
    assert pairs > 100


class ScriptedRandom(random.Random):
    """A Random that draws ``numbers`` in turn, then the lowest number each time, picks a run's next message by
    ``prefer`` where offered, and keeps what each pick was offered."""

    def __init__(self, numbers: list[int], prefer: list[str]):
        super().__init__(0)
        self.numbers, self.prefer, self.offered = list(numbers), list(prefer), []

    def randrange(self, start, stop=None, step=1):
        return self.numbers.pop(0) if self.numbers else start

    def choice(self, seq):
        if "newer" in seq:  # the draw of a run's next message
            self.offered.append(list(seq))
            for how in self.prefer:
                if how in seq:
                    return how
        return seq[0]


def test_5_2_after_a_restart_to_0_no_late_message_and_no_restart_is_offered():
    rng = ScriptedRandom([1024], prefer=["restart", "late", "newer"])  # 2 s, then a restart to 0, then ...
    messages = step5._messages(rng, 3)
    assert messages[:2] == [(2 * SECOND, "ok"), (0, "ok")]
    assert "restart" in rng.offered[0] and "late" in rng.offered[0]
    assert "late" not in rng.offered[1] and "restart" not in rng.offered[1]  # nothing below 0 to draw
    assert all(stamp >= 0 for stamp, _ in messages)


def test_5_2_a_late_message_is_at_least_a_grid_step_back():
    rng = ScriptedRandom([1024], prefer=["late"])  # 2 s, then late by the fewest steps drawn
    assert step5._messages(rng, 2) == [(2 * SECOND, "ok"), (2 * SECOND - GRID, "ok")]


def test_5_2_a_late_message_may_land_on_0():
    rng = ScriptedRandom([1024, 1, 1], prefer=["restart", "late"])  # 2 s, a restart to 1/512 s, late by 1/512 s
    assert step5._messages(rng, 3) == [(2 * SECOND, "ok"), (GRID, "ok"), (0, "ok")]
    assert "late" in rng.offered[1]


def test_5_2_a_restart_lands_more_than_a_second_back_and_may_go_down_to_0():
    backs, lowest = [], []
    for seed in SEEDS:
        messages = step5._messages(random.Random(seed), 30)
        for (stamp, _), how, newest in zip(messages[1:], hows(messages), newest_before(messages)[1:]):
            if how == "restart":
                assert stamp <= newest - SECOND - GRID
                backs.append(newest - stamp)
                lowest.append(stamp)
    assert min(lowest) == 0 and min(backs) <= SECOND + 64 * GRID


def test_5_2_the_second_back_case_is_first_newest_a_second_back_just_over_then_newer():
    wholes, befores, afters = set(), [], []
    for seed in SEEDS:
        (first, k1), (newest, k2), (back, k3), (over, k4), (last, k5) = step5._a_second_back(random.Random(seed))
        assert {k1, k2, k3, k4, k5} == {"ok"}
        assert newest % SECOND == 0 and newest // SECOND in step5.WHOLE_SECONDS
        wholes.add(newest // SECOND)
        assert (newest - first) % GRID == 0 and (last - over) % GRID == 0
        assert back == newest - SECOND and over == newest - SECOND - GRID
        befores.append((newest - first) // GRID)
        afters.append((last - over) // GRID)
    assert len(wholes) > 20  # drawn, not one fixed second
    # the first 1 to 99 grid steps before the newest, the last 1 to 49 after the one just over: both ends drawn
    assert (min(befores), max(befores), min(afters), max(afters)) == (1, 99, 1, 49)


# ---- 5.1's hidden readings -------------------------------------------------------------------------


def test_5_1_the_exact_length_reading_is_half_a_m_s2_along_any_horizontal_axis():
    readings = [step5._exact_reading(random.Random(seed)) for seed in SEEDS]
    assert {(x, y) for x, y, _ in readings} == {(0.5, 0.0), (-0.5, 0.0), (0.0, 0.5), (0.0, -0.5)}
    assert all(0.1 * math.hypot(x, y) == 0.05 for x, y, _ in readings)  # exactly the shortest arrow shown
    zs = [z for _, _, z in readings]
    assert all(5.0 <= z <= 15.0 for z in zs) and min(zs) < 5.1 and max(zs) > 14.9


def test_5_1_hidden_poses_are_four_anywhere_within_2_m_and_turned_any_way():
    poses = [step5._hidden_poses(random.Random(seed)) for seed in SEEDS]
    assert {len(p) for p in poses} == {4}
    positions = np.array([position for p in poses for position, _ in p])  # (1600, 3)
    quaternions = np.array([q for p in poses for _, q in p])  # (1600, 4)
    assert positions.shape == (1600, 3) and quaternions.shape == (1600, 4)
    assert np.all(np.abs(positions) <= 2.0)
    assert np.all(positions.min(axis=0) < -1.95) and np.all(positions.max(axis=0) > 1.95)  # each axis, both ways
    # each component a standard normal: turned and tilted any way, with no direction preferred
    assert np.all(np.abs(quaternions.mean(axis=0)) < 0.1)
    assert np.all(np.abs(quaternions.std(axis=0) - 1.0) < 0.1)


def test_5_1_hidden_readings_are_bumps_drives_and_hits_never_at_the_shortest_arrow_shown():
    readings = [step5._reading(random.Random(seed)) for seed in range(2000)]
    horizontal = [max(abs(x), abs(y)) for x, y, _ in readings]
    assert all(h <= 40.0 for h in horizontal)
    assert sum(h <= 0.6 for h in horizontal) / len(horizontal) > 0.3  # a bump, one in three
    assert any(0.6 < h <= 5.0 for h in horizontal)  # a drive
    assert any(h > 5.0 for h in horizontal) and max(horizontal) > 30.0  # a hit
    assert sum(5.0 < h <= 6.0 for h in horizontal) / len(horizontal) < 0.02  # a drive stays under 5 m/s^2
    assert any(x < -5.0 for x, _, _ in readings) and any(y < -5.0 for _, y, _ in readings)  # both signs
    zs = [z for _, _, z in readings]
    assert all(0.0 <= z < 20.0 for z in zs) and min(zs) < 0.1 and max(zs) > 19.9
    for x, y, _ in readings:  # an arrow of 0.05 m is the shortest shown: never drawn that close to it
        assert abs(0.1 * math.hypot(x, y) - 0.05) > 1e-6


class ReadingsRandom(random.Random):
    """Draws the readings it is given, one (x, y, z) per call of ``_reading``'s loop, at the bumps' scale."""

    def __init__(self, readings):
        super().__init__(0)
        self.values = [v for reading in readings for v in reading]

    def choice(self, seq):
        return seq[0]

    def uniform(self, a, b):
        return self.values.pop(0)


def test_5_1_a_reading_at_the_shortest_arrow_shown_is_drawn_again():
    # 0.1 m per m/s^2: (0.3, 0.4) is 0.5 m/s^2 horizontally, an arrow of exactly 0.05 m
    assert step5._reading(ReadingsRandom([(0.3, 0.4, 1.0), (0.2, 0.1, 2.0)])) == (0.2, 0.1, 2.0)
    assert step5._reading(ReadingsRandom([(0.4, -0.3, 1.0), (0.2, 0.1, 2.0)])) == (0.2, 0.1, 2.0)
    assert step5._reading(ReadingsRandom([(0.3, 0.41, 1.0)])) == (0.3, 0.41, 1.0)  # 0.0505 m: shown


# ---- 6.1's stamp rule, at its edges ----------------------------------------------------------------


def _header(sec: int, nanosec: int):
    from types import SimpleNamespace

    return SimpleNamespace(stamp=SimpleNamespace(sec=sec, nanosec=nanosec))


def test_6_1_a_stamp_is_right_to_the_nanosecond_with_nanosec_below_a_second():
    from tutorial.exercises import step6_camera as step6

    assert step6._stamp_fault(_header(5, 0), 5.0) is None  # whole seconds in sec
    assert step6._stamp_fault(_header(0, 500_000_001), 0.5) is None  # 1 ns off: truncated or rounded
    assert step6._stamp_fault(_header(0, 499_999_999), 0.5) is None
    assert "nanosec=500000002" in step6._stamp_fault(_header(0, 500_000_002), 0.5)  # 2 ns off
    assert step6._stamp_fault(_header(1, 1_000_000_000), 2.0) is not None  # the sum is right, nanosec is not
    assert step6._stamp_fault(_header(0, 2_000_000_000), 2.0) is not None
    assert step6._stamp_fault(_header(2, -1), 2.0) is not None


# ---- 6.1's picture rule: each fault named with its rule and hint -------------------------------------------


def _gray_picture(camera, colour, **changed):
    """A message as a right answer publishes it for ``colour`` at 2.5 s, with the fields ``changed``."""
    from types import SimpleNamespace

    from tutorial.exercises import step6_camera as step6

    gray = np.round(colour @ np.array(step6.LUMA)).astype(np.uint8)
    msg = SimpleNamespace(
        encoding="mono8", height=camera.height, width=camera.width, step=camera.width, is_bigendian=0,
        header=SimpleNamespace(frame_id=camera.name, stamp=SimpleNamespace(sec=2, nanosec=500_000_000)),
        data=gray.tobytes(),
    )  # fmt: skip
    for name, value in changed.items():
        setattr(msg.header if name in ("frame_id", "stamp") else msg, name, value)
    return msg


def test_6_1_a_gray_pictures_faults_each_name_their_rule_and_hint():
    from tutorial.exercises import step6_camera as step6
    from tutorial.exercises.camera_rig import Camera

    camera = Camera(name="Eye", width=4, height=3)
    colour = np.random.default_rng(6).integers(0, 256, (3, 4, 3)).astype(float)
    fault = functools.partial(step6._gray_fault, t=2.5, colour=colour, camera=camera)
    assert fault(_gray_picture(camera, colour)) is None
    assert fault(_gray_picture(camera, colour, width=3)) == (
        "layout", "width was 3, expected 4", "height is the number of rows, width the pixels in a row."
    )  # fmt: skip
    assert fault(_gray_picture(camera, colour, is_bigendian=1)) == (
        "layout", "is_bigendian was 1, expected 0", "set is_bigendian to 0."
    )  # fmt: skip
    assert fault(_gray_picture(camera, colour, frame_id="Kinect")) == (
        "frame",
        "frame_id was 'Kinect', expected 'Eye'",
        "keep the frame_id RttCameraImagePublisher.configure set: reuse self.msg.",
    )
    assert fault(_gray_picture(camera, colour, data=bytes(24))) == (
        "layout", "data has 24 bytes, expected step x height = 12", "one byte a pixel: the gray array as uint8."
    )  # fmt: skip
    stamp = fault(_gray_picture(camera, colour, stamp=_header(2, 0).stamp))
    assert stamp[0] == "stamp" and stamp[2] == "stamp each picture with its time_s: stamp_parts(time_s)."


def test_6_1_off_by_one_in_at_most_1_percent_of_the_pixels_and_more_than_one_never():
    from tutorial.exercises import step6_camera as step6
    from tutorial.exercises.camera_rig import Camera

    camera = Camera(width=10, height=10)  # 100 pixels: one may be off by one
    colour = np.random.default_rng(61).integers(0, 256, (10, 10, 3)).astype(float)
    right = np.frombuffer(_gray_picture(camera, colour).data, np.uint8).reshape(10, 10).astype(int)

    def fault(*changes):  # (row, column, change) of the right picture's pixels
        gray = right.copy()
        for r, c, d in changes:
            gray[r, c] = gray[r, c] + d if 0 <= gray[r, c] + d <= 255 else gray[r, c] - d
        found = step6._gray_fault(
            _gray_picture(camera, colour, data=gray.astype(np.uint8).tobytes()), 2.5, colour, camera
        )
        return found and found[1].split(", e.g.")[0]

    assert fault() is None
    assert fault((3, 4, 1)) is None  # one pixel in a hundred
    assert fault((3, 4, 1), (5, 6, 1)) == "2 of 100 pixels are off by 1"
    assert fault((3, 4, 2)) == "1 of 100 pixels are off by more than 1"
    assert fault((3, 4, 2), (5, 6, 1), (7, 8, 1)) == "1 of 100 pixels are off by more than 1"  # the worse first
    gray = right.copy()
    gray[0, 0] += 2 if gray[0, 0] < 200 else -2
    rule, what, hint = step6._gray_fault(
        _gray_picture(camera, colour, data=gray.astype(np.uint8).tobytes()), 2.5, colour, camera
    )
    assert (rule, what.split(", e.g. ")[1].split(" is ")[0]) == ("pixels", "row 0, column 0")
    assert hint == (
        "gray = 0.299 R + 0.587 G + 0.114 B, rounded (np.round: astype alone cuts the fraction off): "
        "green counts most, blue least."
    )


def test_6_1_a_camera_publishing_no_image_on_its_topic_is_told_so(monkeypatch):
    """Fast DDS refuses a second type on one topic, so only an answer that makes its own publisher instead of
    the Image's gets here: a stand-in rig shows the line."""

    from rclpy.qos import QoSProfile

    from tutorial.exercises import step6_camera as step6

    publisher = {"topic": "/Tank/camera/image", "type": "sensor_msgs/msg/CompressedImage", "qos": QoSProfile(depth=1)}
    record = {"publishers": [{**publisher, "destroyed": True, "messages": []}], "destroyed": [0], "times": []}
    monkeypatch.setattr(step6, "_drove", lambda cls, camera, poses, pictures: {**record, "references": []})
    monkeypatch.setattr(step6, "hidden_random", lambda exercise: None)
    result = step6.check_gray_camera(type("RttGrayCameraPublisher", (), {}))
    assert not result.passed
    assert "RttGrayCameraPublisher publishes CompressedImage on /Tank/camera/image, expected an Image." in str(result)


def test_6_the_rig_finds_the_image_publisher_among_others_and_names_what_was_made_without_one():
    """The rig's Image publisher is the one of the camera's image topic, whatever was made before it (a
    CameraInfo publisher made first); without one, the line names the topic, what was made, and the hint."""
    from types import SimpleNamespace

    from tutorial.exercises.camera_rig import Camera, Rig
    from tutorial.exercises.grader import CaseFailed

    info, image = (SimpleNamespace(topic=f"/Eye/camera/{k}") for k in ("camera_info", "image"))

    def rig(publishers):
        made = Rig.__new__(Rig)  # its images() alone: no simulation, no node
        made.name, made.camera = "RttGrayCameraPublisher", Camera(body="Eye")
        made.node = SimpleNamespace(published=lambda topic=None: [p for p in publishers if topic in (None, p.topic)])
        return made

    assert rig([info, image]).images() is image
    with pytest.raises(CaseFailed) as failed:
        rig([info]).images()
    assert (failed.value.what, failed.value.hint) == (
        "RttGrayCameraPublisher made no publisher of /Eye/camera/image (it made ['/Eye/camera/camera_info']).",
        "let RttCameraImagePublisher.configure create it: call super().configure(config).",
    )


def test_6_a_hidden_cameras_world_is_the_room_and_one_tank_of_its_name_with_that_camera():
    """camera_rig.world of a camera not the Kinect: the tank renamed, its camera renamed, sized and of its field
    of view; the room as it is; no second tank."""
    from tutorial.exercises.camera_rig import STEP, Camera, world

    model, cam = world(Camera(body="Eye", name="Cam", width=64, height=48, fovy=45.0))
    bodies = [model.body(i).name for i in range(model.nbody)]
    geoms = [model.geom(i).name for i in range(model.ngeom)]
    assert model.camera(cam).name == "Eye/Cam" and model.ncam == 1
    assert tuple(model.cam_resolution[cam]) == (64, 48) and model.cam_fovy[cam] == 45.0
    assert "Eye/CHASSIS" in bodies and not any(b.startswith("Tank/") for b in bodies), bodies
    assert any(g.startswith("Room/") for g in geoms), geoms
    assert model.opt.timestep == STEP


def test_6_1_hidden_poses_are_three_with_the_yaw_anywhere_and_the_pitch_within_the_turrets_range():
    from tutorial.exercises import step6_camera as step6

    drawn = [step6._hidden_poses(random.Random(seed)) for seed in SEEDS]
    assert {len(poses) for poses in drawn} == {3}
    assert {label for poses in drawn for label, _, _ in poses} == {""}
    yaws = [yaw for poses in drawn for _, yaw, _ in poses]
    pitches = [pitch for poses in drawn for _, _, pitch in poses]
    assert -math.pi <= min(yaws) < -3.0 and 3.0 < max(yaws) <= math.pi
    assert -0.15 <= min(pitches) < -0.14 and 0.74 < max(pitches) <= 0.75


def test_6_hidden_cameras_are_of_every_size_field_of_view_and_name_the_rules_allow():
    from tutorial.exercises import step6_camera as step6

    cameras = [step6._random_camera(random.Random(seed)) for seed in range(2000)]  # each size at least once
    assert {c.body for c in cameras} == {"Scout", "Rover"} and {c.name for c in cameras} == {"Eye", "Xtion"}
    assert (min(c.width for c in cameras), max(c.width for c in cameras)) == (64, 240)
    assert (min(c.height for c in cameras), max(c.height for c in cameras)) == (48, 180)
    assert any(c.height > c.width for c in cameras) and any(c.width > c.height for c in cameras)
    fovy = [c.fovy for c in cameras]
    assert 30 <= min(fovy) < 31 and 99 < max(fovy) <= 100
    starts = [c.start for c in cameras]
    assert {math.floor(s) for s in starts} == {1, 2, 3}  # a second or more, below four
    fractions = [round(s - math.floor(s), 3) for s in starts]
    assert 0.5 <= min(fractions) < 0.51 and 0.69 < max(fractions) <= 0.7  # past the half second
    assert all(abs(s * 1000 - round(s * 1000)) < 1e-6 for s in starts)  # whole milliseconds


@pytest.mark.parametrize(
    "rule, broken, told",
    [
        ("layout", {"width": -1}, "a camera of another size: encoding, height, width, step"),
        ("frame", {"frame_id": "Kinect"}, "a camera of another name: the frame_id"),
        ("stamp", {"sec": 1}, "stamps of a second or more: sec and nanosec"),
        ("pixels", {"luma": 3}, "the turret at random poses: each pixel's luma"),
    ],
)
def test_6_1_each_hidden_case_fails_on_its_own_rule_on_the_hidden_camera(monkeypatch, rule, broken, told):
    """A stand-in rig publishes right pictures of the Kinect, and pictures of the hidden camera that break one
    rule: the hidden case of that rule is the one that fails."""
    from types import SimpleNamespace

    from tutorial.exercises import step6_camera as step6
    from tutorial.interfaces.timing import stamp_parts

    rng = np.random.default_rng(7)

    from rclpy.qos import QoSProfile

    def drove(cls, camera, poses, pictures):  # the experiment's record of a drive
        camera = step6.Camera(**camera)
        times = [camera.start + 0.1 * k for k in range(len(poses))]
        colours = [rng.integers(0, 256, (camera.height, camera.width, 3)).astype(float) for _ in poses]
        messages = []
        for t, colour in zip(times, colours):
            sec, nanosec = stamp_parts(t)
            msg = _gray_picture(camera, colour, stamp=SimpleNamespace(sec=sec, nanosec=nanosec))
            if camera != step6.KINECT:  # the hidden camera's pictures break the rule
                if "width" in broken:
                    msg.width += broken["width"]
                if "frame_id" in broken:
                    msg.header.frame_id = broken["frame_id"]
                if "sec" in broken:
                    msg.header.stamp.sec += broken["sec"]
                if "luma" in broken:
                    gray = np.frombuffer(msg.data, np.uint8).astype(int)
                    msg.data = np.clip(gray + np.where(gray < 128, 3, -3), 0, 255).astype(np.uint8).tobytes()
            messages.append(msg)
        publisher = {"topic": camera.topic("image"), "type": "sensor_msgs/msg/Image", "qos": QoSProfile(depth=1)}
        publisher.update(destroyed=True, messages=messages)
        return {"publishers": [publisher], "destroyed": [0], "times": times, "references": colours}

    monkeypatch.setattr(step6, "_drove", drove)
    monkeypatch.setattr(step6, "hidden_random", lambda exercise: random.Random(f"test/{exercise}"))
    result = step6.check_gray_camera(type("Gray", (), {}))
    assert not result.passed and result.case == told and result.message.startswith(f"a hidden case failed: {told}.")


def test_6_a_drive_of_the_judge_with_no_image_publisher_names_the_class():
    """A drive as the judge builds it back from the kernel's record (:class:`_Drove`): with no publisher of the
    camera's Image topic, the line names the learner's class (found by make mutate: only the rig's own drive,
    in the kernel's process, was tried)."""
    from tutorial.exercises.camera_rig import Camera
    from tutorial.exercises.grader import CaseFailed
    from tutorial.exercises.step6_camera import _Drove

    drove = _Drove(
        "RttGrayCameraPublisher", Camera(), {"publishers": [], "destroyed": [], "times": [], "references": []}
    )
    with pytest.raises(CaseFailed) as failed:
        drove.images()
    assert str(failed.value).startswith("RttGrayCameraPublisher made no publisher of /Tank/camera/image"), failed.value

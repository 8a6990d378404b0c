"""Checks for the exercises of notebook 05 (Step 5, the IMU viewer).

Exercise 5.1, a third arrow: a ``RttImuStateSubscriber`` subclass that also
draws the acceleration's horizontal part as a green arrow
``<body>/horizontal_acceleration``, turned with the body, hidden when short,
following the IMU while the view shakes.
Exercise 5.2, refuse old news: a ``RttImuStateSubscriber`` subclass that
refuses, as ``out_of_order``, a message whose stamp is not newer than the
newest it showed, unless it is more than 1 s older (a restarted publisher).

Each check opens the viewer project (``project/tank_view.yaml`` with the
learner's class) headless on the calling thread, which plays the viewer's
main thread, and hands it messages directly, as ``call_later`` would: no
network, no wall-clock timing (the controller's ``clock`` is replaced by a
simulated one), so the same code always gets the same line.

While grading (:func:`tutorial.exercises.grader.hidden_random`) each check
also runs hidden cases, drawn from the learner's seed: for 5.1, readings
with the tank moved, tilted and turned any way, and an arrow exactly
``ACCEL_MIN_LENGTH`` long; for 5.2, a stamp exactly 1 s older than the
newest, and random runs of messages stamped past 1 s (never below 0).

The module is over 400 lines and still one job: the two checks share one
headless viewer (``_viewer``) and the messages they hand it (``_imu``).
"""

from __future__ import annotations

import contextlib
import math

import numpy as np

from tutorial.exercises.grader import Case, CaseFailed, Result, experiments, grade, hidden_random, observe, show

GREEN = (0.2, 0.8, 0.2)
ARROW = "Tank/horizontal_acceleration"
RESTART = 1.0  # s: a stamp further back than this is a restarted publisher
SECOND = 1_000_000_000  # ns
GRID = 1_953_125  # ns, 1/512 s: hidden stamps are whole numbers of it
# Seconds n whose stamps n s and n - 1 s (nanosec 0) are exact in every common float form, (sec * 10**9 + nanosec)
# * 1e-9 too (15 s is not: 15.000000000000002): a hidden stamp exactly 1 s older than the newest is on these alone;
# a float form of another stamp may be a hair off, so no other is within a GRID of 1 s older.
WHOLE_SECONDS = tuple(n for n in range(2, 1000) if all(k * 10**9 * 1e-9 == k for k in (n, n - 1)))


class _Clock:
    """A simulated monotonic clock, s: ``clock()`` reads it, the check moves it."""

    def __init__(self, now: float = 100.0):
        self.now = now

    def __call__(self) -> float:
        return self.now


@contextlib.contextmanager
def _viewer(cls, name: str):
    """The tank viewer with ``cls`` attached as ``name``, open on this thread: ``(app, controller, clock)``.

    Raises:
        CaseFailed: the controller refused to configure.
    """
    import rclpy

    from tutorial.app.app import App, ControllerError
    from tutorial.notebook.runs import load

    project = load("tank_view.yaml").with_controller("Tank", name, cls)
    node = rclpy.create_node("exercise_check_imu_viewer")
    app = App(project, node=node, headless=True, output=lambda record: None)
    try:
        try:
            app.open()
        except ControllerError as exc:
            if isinstance(exc.__cause__, NotImplementedError):
                raise NotImplementedError from exc
            raise CaseFailed(
                f"{cls.__name__}: {exc}.", "call super().configure(config) and return what it returns (True)."
            ) from None
        controller = app.controller(name)
        clock = _Clock()
        controller.clock = clock
        yield app, controller, clock
    finally:
        app.close()
        node.destroy_node()


def _imu(accel, gyro=(0.0, 0.0, 0.0), stamp: float = 0.0, frame_id: str = "CHASSIS", stamp_ns: int | None = None):
    from sensor_msgs.msg import Imu

    msg = Imu()
    msg.header.frame_id = frame_id
    stamp_ns = round(stamp * 1e9) if stamp_ns is None else stamp_ns
    msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(stamp_ns, 1_000_000_000)
    a, w = msg.linear_acceleration, msg.angular_velocity
    a.x, a.y, a.z = (float(v) for v in accel)
    w.x, w.y, w.z = (float(v) for v in gyro)
    return msg


def _turn_left(app, angle: float) -> None:
    """Yaw the viewer's tank by ``angle`` rad about z (its root's orientation), main thread."""
    _place(app, orientation=[math.cos(angle / 2), 0.0, 0.0, math.sin(angle / 2)])


def _place(app, position=None, orientation=None) -> None:
    """Put the viewer's tank's root at ``position`` (m), turned by the quaternion ``orientation`` (w, x, y, z).

    The tank's body is the app's (the controller's ``body`` is the learner's attribute, which a class could replace).
    """
    body = app.bodies["Tank"]
    root = body.root_qpos_address  # the tank's free joint: its position (3,), then its orientation (4,)
    if position is not None:
        app.data.qpos[root : root + 3] = position
    if orientation is not None:
        app.data.qpos[root + 3 : root + 7] = np.asarray(orientation) / np.linalg.norm(orientation)
    body.notify_kinematic_state_change()


def check_horizontal_arrow(cls) -> Result:
    """Check a ``RttImuStateSubscriber`` subclass drawing a third, green arrow.

    The arrow ``<body>/horizontal_acceleration``, color (0.2, 0.8, 0.2), starts
    at the IMU; its vector is 0.1 m per m/s^2 of the reading's x and y (z = 0
    in the IMU's axes), turned into the world like the other two; hidden when
    shorter than 0.05 m; redrawn whenever the others are (the shake too).
    Hidden cases: random readings with the tank moved, tilted and turned
    (so the horizontal part in the IMU's axes is not the world's); an arrow
    exactly 0.05 m long, shown.
    """
    name = cls.__name__

    def arrow_of(seen: dict) -> dict:
        if "arrow" not in seen:
            raise CaseFailed(
                f"{name} made the arrows {seen['arrows']}, expected also {ARROW!r}.",
                "in configure, after super().configure(config): "
                'config.overlays.arrow(f"{config.body_name}/horizontal_acceleration", '
                "(0.2, 0.8, 0.2)).",
            )
        return seen["arrow"]

    def shows(label, accel, vector, visible, turn=0.0, hint=""):
        call = f"{name}.update_imu(acceleration {show(list(accel))} m/s^2) ({label})"

        def run():
            seen = observe(_arrow_shown, cls, list(accel), turn)
            arrow = arrow_of(seen)
            if tuple(round(c, 6) for c in arrow["color"]) != GREEN:
                raise CaseFailed(
                    f"{call}: the arrow's color is {arrow['color']}, expected {GREEN}.", "green: (0.2, 0.8, 0.2)."
                )
            origin = seen["imu"]
            if not np.allclose(arrow["origin"], origin, atol=1e-9):
                raise CaseFailed(
                    f"{call}: the arrow starts at {show(arrow['origin'].tolist())}, the IMU "
                    f"is at {show(origin.tolist())} m.",
                    "start it at self.data.site_xpos[self.site].",
                )
            if not np.allclose(arrow["vector"], vector, atol=1e-9) or arrow["visible"] != visible:
                raise CaseFailed(
                    f"{call}: the arrow is {show(arrow['vector'].tolist())} m, visible="
                    f"{arrow['visible']}; expected {show(list(vector))} m, visible={visible}.",
                    hint,
                )
            red = seen["red"]
            expected_red = 0.1 * (np.array(accel) + [0.0, 0.0, -9.8])
            if not turn and not np.allclose(red, expected_red, atol=1e-9):
                raise CaseFailed(
                    f"{call}: the red arrow became {show(red.tolist())} m, expected "
                    f"{show(expected_red.tolist())} as before.",
                    "keep the other two arrows: call super().draw_arrows().",
                )

        return Case(call, run, hint)

    def keeps_after_rejection():
        call = f"{name}.update_imu() of (3, 4, 11.8) m/s^2, then of a NaN"
        before, after = (arrow_of(seen) for seen in observe(_arrow_after_rejection, cls))
        if not np.array_equal(after["vector"], before["vector"]) or after["visible"] != before["visible"]:
            raise CaseFailed(
                f"{call}: the arrow changed to {show(after['vector'].tolist())} m.",
                "a rejected message changes nothing: draw from self.accel, which only an accepted message sets.",
            )

    def follows_the_shake():
        call = f"{name}: a hit of (-30, 0, 9.8) m/s^2, then a shake tick 20 ms later"
        home, seen = observe(_arrow_shaken, cls)
        arrow, moved = arrow_of(seen), seen["imu"]
        if np.array_equal(moved, home):
            raise CaseFailed(
                f"{call}: the view did not shake.", "keep the viewer's behaviour: call super().update_imu()."
            )
        if not np.allclose(arrow["origin"], moved, atol=1e-12):
            raise CaseFailed(
                f"{call}: the IMU moved to {show(moved.tolist())} m, but the green "
                f"arrow still starts at {show(arrow['origin'].tolist())}.",
                "draw it in draw_arrows(), which the shake tick calls too, not in update_imu().",
            )

    def readings(poses, accels):
        """Each reading with the tank placed at its pose: the arrow, by the statement's rule."""
        for seen, accel in zip(observe(_arrows_placed, cls, poses, accels), accels):
            arrow = arrow_of(seen)
            horizontal = 0.1 * np.array([accel[0], accel[1], 0.0])
            to_world = seen["imu_axes"].reshape(3, 3)
            if not (
                np.allclose(arrow["origin"], seen["imu"], atol=1e-9)
                and np.allclose(arrow["vector"], to_world @ horizontal, atol=1e-9)
                and arrow["visible"] == (np.linalg.norm(horizontal) >= 0.05)
            ):
                raise CaseFailed(f"{name}: the arrow of a reading is wrong.")

    hint_turn = (
        "the reading is in the IMU's axes: turn the vector into the world with "
        "self.data.site_xmat[self.site].reshape(3, 3) @ vector, as draw_arrows() does."
    )
    hidden = []
    rng = hidden_random("5.1")  # while grading: this learner's own poses and readings
    for _ in range(3 if rng else 0):
        poses = _hidden_poses(rng)
        accels = [_reading(rng) for _ in poses]
        hidden.append(
            Case(
                "readings with the tank moved, tilted and turned any way",
                lambda poses=poses, accels=accels: readings(poses, accels),
                "x and y of the reading in the IMU's axes, z set to zero, then turned into the world: on a "
                "tilted tank that is not the world's horizontal part.",
                True,
            )
        )
    if rng:
        exact = _exact_reading(rng)
        hidden.append(
            Case(
                "an arrow exactly as long as ACCEL_MIN_LENGTH: shown",
                lambda: readings([(None, [1.0, 0.0, 0.0, 0.0])], [exact]),
                "hidden when shorter than ACCEL_MIN_LENGTH: an arrow exactly that long is shown (>=).",
                True,
            )
        )
    return grade(
        "Exercise 5.1, a third arrow",
        [
            shows(
                "driving over a bump",
                (3.0, 4.0, 11.8),
                (0.3, 0.4, 0.0),
                True,
                hint="0.1 m per m/s^2 of x and y only: z is not horizontal.",
            ),
            shows(
                "0.042 m: hidden",
                (0.3, 0.3, 12.0),
                (0.03, 0.03, 0.0),
                False,
                hint="hide the arrow when it is shorter than ACCEL_MIN_LENGTH (0.05 m).",
            ),
            shows(
                "the tank turned 90 degrees left",
                (5.0, 0.0, 9.8),
                (0.0, 0.5, 0.0),
                True,
                turn=math.pi / 2,
                hint=hint_turn,
            ),
            Case(
                f"{name}.update_imu() of (3, 4, 11.8) m/s^2, then of a NaN",
                keeps_after_rejection,
                "a rejected message changes nothing: draw from self.accel, which only an accepted message sets.",
            ),
            Case(f"{name}: a hit of (-30, 0, 9.8) m/s^2, then a shake tick 20 ms later", follows_the_shake),
            *hidden,
        ],
    )


def _seen(app) -> dict:
    """What 5.1's check reads of a viewer: ``{"arrows"`` (the names drawn), ``"arrow"`` (the green one's
    ``color``, ``origin`` m, ``vector`` m and ``visible``, if drawn), ``"imu"`` (the IMU site's position, m),
    ``"imu_axes"`` (its orientation, 3 x 3, flat)``}``."""
    from tutorial.interfaces.imu import find_imu

    arrows, body = app.overlays.arrows, app.bodies["Tank"]
    site = find_imu(body.model, body.body_ids)[2]  # the IMU's site, from the model (not the class's self.site)
    seen = {
        "arrows": sorted(arrows),
        "imu": app.data.site_xpos[site].copy(),
        "imu_axes": app.data.site_xmat[site].copy(),
    }
    arrow = arrows.get(ARROW)
    if arrow is not None:
        seen["arrow"] = {"color": arrow.color, "origin": arrow.origin.copy(), "vector": arrow.vector.copy()}
        seen["arrow"]["visible"] = arrow.visible
    return seen


def _red(app):
    """The viewer's red arrow (the acceleration's), as the app's overlays hold it (not the class's attribute).

    Raises:
        KeyError: the viewer drew none.
    """
    return app.overlays.arrows["Tank/acceleration"]


def _arrow_shown(cls, accel, turn: float) -> dict:
    """A viewer of ``cls``, its tank yawed ``turn`` rad, given one reading ``accel`` (m/s^2): :func:`_seen`, and
    the red arrow's vector (``"red"``, m)."""
    with _viewer(cls, "HorizontalArrow") as (app, controller, _):
        if ARROW not in app.overlays.arrows:
            return _seen(app)
        if turn:
            _turn_left(app, turn)
        controller.update_imu(_imu(accel), controller.clock())
        return {**_seen(app), "red": _red(app).vector.copy()}


def _arrow_after_rejection(cls) -> tuple[dict, dict]:
    """A viewer of ``cls`` given (3, 4, 11.8) m/s^2, then a NaN: :func:`_seen` after each."""
    with _viewer(cls, "HorizontalArrow") as (app, controller, _):
        if ARROW not in app.overlays.arrows:
            return _seen(app), _seen(app)
        controller.update_imu(_imu((3.0, 4.0, 11.8)), controller.clock())
        before = _seen(app)
        controller.update_imu(_imu((math.nan, 0.0, 9.8)), controller.clock())
        return before, _seen(app)


def _arrow_shaken(cls) -> tuple:
    """A viewer of ``cls`` hit by (-30, 0, 9.8) m/s^2, then shaken 20 ms later: ``(the IMU's position before, m,
    :func:`_seen` after)``."""
    with _viewer(cls, "HorizontalArrow") as (app, controller, clock):
        home = _seen(app)["imu"]
        if ARROW not in app.overlays.arrows:
            return home, _seen(app)
        controller.update_imu(_imu((-30.0, 0.0, 9.8)), clock())
        clock.now += 0.02
        controller.shake_tick()
        return home, _seen(app)


def _arrows_placed(cls, poses, accels) -> list[dict]:
    """A viewer of ``cls``, its tank placed at each pose of ``poses`` (:func:`_place`) and given the reading of
    ``accels`` there: :func:`_seen` after each."""
    seen = []
    with _viewer(cls, "HorizontalArrow") as (app, controller, clock):
        for (position, orientation), accel in zip(poses, accels):
            if ARROW not in app.overlays.arrows:
                return [*seen, _seen(app)]
            _place(app, position, orientation)
            controller.update_imu(_imu(accel), clock())
            seen.append(_seen(app))
    return seen


def _hidden_poses(rng) -> list[tuple[list[float], list[float]]]:
    """Four random poses of the tank ``(position m, quaternion w, x, y, z)``: anywhere within 2 m of the origin
    on each axis, turned and tilted any way (four normal components; :func:`_place` normalizes them)."""
    return [([rng.uniform(-2, 2) for _ in "xyz"], [rng.gauss(0, 1) for _ in "wxyz"]) for _ in range(4)]


def _exact_reading(rng) -> tuple[float, float, float]:
    """A reading, m/s^2, whose green arrow is exactly ACCEL_MIN_LENGTH (0.05 m) long: 0.5 along +x, -x, +y or -y
    (exact in binary, so the arrow's length is exactly 0.05 m in floats too), and a z of 5 to 15."""
    return (*rng.choice(((0.5, 0.0), (-0.5, 0.0), (0.0, 0.5), (0.0, -0.5))), rng.uniform(5, 15))


def _reading(rng) -> tuple[float, float, float]:
    """A random acceleration, m/s^2: a bump, a drive, or a hit; never within 1e-6 m of the shortest arrow shown."""
    while True:
        scale = rng.choice((0.6, 5.0, 40.0))
        accel = (rng.uniform(-scale, scale), rng.uniform(-scale, scale), rng.uniform(0.0, 20.0))
        if abs(0.1 * math.hypot(accel[0], accel[1]) - 0.05) > 1e-6:
            return accel


def check_in_order(cls) -> Result:
    """Check a ``RttImuStateSubscriber`` subclass refusing old news.

    A message whose stamp is not newer than the newest message shown is
    refused: counted as ``rejected["out_of_order"]``, nothing drawn, no
    shake.  A stamp more than 1 s older than the newest is a restarted
    publisher: shown, and the newest from then on.  A message rejected for
    another reason does not count as shown.  Hidden cases: a stamp exactly
    1 s older than the newest (refused), then one just over (shown); random
    runs of stamps of many seconds, newer, late, repeated, restarted, NaN
    and hits, each message's return value, arrow and shake judged.
    """
    name = cls.__name__

    def sequence(label, stamps, accepted, rejected, shown, shakes=None, nan=(), hits=(), hint=""):
        sent = ", ".join(f"{t:.2f}" for t in stamps)
        call = f"{name}.update_imu() of messages stamped {sent} s ({label})"

        def run():
            summary, x = observe(_sequence_shown, cls, list(stamps), list(nan), list(hits), shown is not None)
            got = (summary["accepted"], summary["rejected"])
            if got != (accepted, rejected):
                raise CaseFailed(
                    f"{call} gave accepted={got[0]}, rejected={got[1]}; expected "
                    f"accepted={accepted}, rejected={rejected}.",
                    hint,
                )
            if shown is not None and not abs(x - 0.1 * (shown + 1)) <= 1e-9:  # a NaN arrow fails
                which = round(x / 0.1) - 1  # message k's arrow is 0.1 (k + 1) m long in x
                shows = (
                    f"the message stamped {stamps[which]:.2f} s"
                    if abs(x - 0.1 * (which + 1)) < 1e-9 and 0 <= which < len(stamps)
                    else f"none of them (x = {x:.3f} m)"
                )
                raise CaseFailed(
                    f"{call}: the arrow shows {shows}, expected the one stamped {stamps[shown]:.2f} s.", hint
                )
            if shakes is not None and summary["shakes"] != shakes:
                got = summary["shakes"]
                times = "once" if got == 1 else f"{got} times"
                raise CaseFailed(f"{call} shook the view {times}, expected {shakes}.", hint)

        return Case(call, run, hint)

    def judged(label, messages, hint):
        """A hidden case: ``messages`` ``[(stamp ns, "ok" | "nan" | "hit")]``, each judged by :func:`_judge`."""

        def run():
            newest, accel_x, hits, counts = None, None, 0, {}
            returned, summary = observe(_messages_shown, cls, messages)
            for k, ((stamp, kind), (got, arrow_x)) in enumerate(zip(messages, returned)):
                reason, newest = _judge(newest, stamp, kind)
                if reason is None:
                    accel_x, hits = 0.1 * _message_accel(k, kind), hits + (kind == "hit")
                else:
                    counts[reason] = counts.get(reason, 0) + 1
                if not (got is None if reason is None else type(got) is str and got == reason):
                    raise CaseFailed(f"{name}.update_imu() returned {got!r}, expected {reason!r}.")
                if accel_x is not None and not (arrow_x is not None and abs(arrow_x - accel_x) <= 1e-9):
                    raise CaseFailed(f"{name}: the arrow does not show the newest message shown.")
            want = (len(messages) - sum(counts.values()), dict(sorted(counts.items())), hits)
            if (summary["accepted"], summary["rejected"], summary["hits"]) != want:
                raise CaseFailed(f"{name}: the summary {summary} counts otherwise.")

        return Case(label, run, hint, True)

    refuse = (
        "a stamp not newer than the newest shown is refused: count self.rejected['out_of_order'] "
        '+= 1 and return "out_of_order" before super().update_imu() can show it.'
    )
    hidden = []
    rng = hidden_random("5.2")  # while grading: this learner's own stamps, judged by the statement's rule
    if rng:
        hidden.append(
            judged(
                "a stamp exactly a second older than the newest, then one just over a second older",
                _a_second_back(rng),
                "exactly a second older is not more than a second: refuse it; just over is a restarted publisher.",
            )
        )
        for _ in range(5):
            hidden.append(
                judged(
                    "a random run of messages: newer, late, repeated, restarted, NaN and hits",
                    _messages(rng, 14),
                    "follow each rule of the statement, for every message, in order; return what it says.",
                )
            )
    return grade(
        "Exercise 5.2, refuse old news",
        [
            sequence("in order", [1.0, 1.05, 1.1], 3, {}, 2, hint="messages in order are all shown, as before."),
            sequence("one late", [1.0, 1.1, 1.05], 2, {"out_of_order": 1}, 1, hint=refuse),
            sequence(
                "the same stamp twice",
                [1.0, 1.0],
                1,
                {"out_of_order": 1},
                0,
                hint="the same stamp again is not newer: refuse it too.",
            ),
            sequence("0.5 s back", [5.0, 4.5], 1, {"out_of_order": 1}, 0, hint=refuse),
            sequence(
                "a NaN stamped 2.00 s, then one stamped 1.50 s",
                [1.0, 2.0, 1.5],
                2,
                {"not_finite": 1},
                2,
                nan=(1,),
                hint="only a message that was shown sets the newest stamp: a rejected NaN "
                "must not hold back the good messages after it.",
            ),
            sequence(
                "a restarted publisher",
                [5.0, 5.05, 0.0, 0.05],
                4,
                {},
                3,
                hint="more than 1 s back is a new run (a restarted simulation): show it, and "
                "take its stamp as the newest.",
            ),
            sequence(
                "a late hit",
                [1.0, 1.1, 1.05],
                2,
                {"out_of_order": 1},
                1,
                shakes=0,
                hits=(2,),
                hint="a refused message is not shown and does not shake the view: return "
                "before calling super().update_imu().",
            ),
            sequence(
                "a hit in order",
                [1.0, 1.05],
                2,
                {},
                None,
                shakes=1,
                hits=(1,),
                hint="a message in order is shown as before, and a hit still shakes.",
            ),
            *hidden,
        ],
    )


def _sequence_accel(k: int, nan, hits) -> tuple[float, float, float]:
    """Message ``k``'s acceleration (m/s^2) in a visible run of 5.2: a NaN, a hit, or (k + 1, 0, 9.8), which
    shows a red arrow of 0.1 (k + 1) m in x."""
    if k in nan:
        return (math.nan, 0.0, 9.8)
    return (-30.0, 0.0, 9.8) if k in hits else (k + 1.0, 0.0, 9.8)


def _sequence_shown(cls, stamps, nan, hits, arrow: bool) -> tuple:
    """A viewer of ``cls`` given a message stamped each of ``stamps`` (s; :func:`_sequence_accel`):
    ``(its summary(), the red arrow's x in m if ``arrow`` else None)``."""
    with _viewer(cls, "InOrder") as (app, controller, _clock):
        for k, t in enumerate(stamps):
            controller.update_imu(_imu(_sequence_accel(k, nan, hits), stamp=t), controller.clock())
        summary = controller.summary()
        return summary, (_red(app).vector[0] if arrow else None)


def _message_accel(k: int, kind: str) -> float:
    """Message ``k``'s acceleration in x (m/s^2) in a hidden run of 5.2: a NaN, a hit of its own, or k + 1."""
    return {"nan": math.nan, "hit": -30.0 - k}.get(kind, 1.0 + k)


def _messages_shown(cls, messages) -> tuple[list, object]:
    """A viewer of ``cls`` given each of ``messages`` (``(stamp ns, kind)``; :func:`_message_accel`):
    ``([(what update_imu returned, the red arrow's x in m or None if unread), ...], its summary())``."""
    returned = []
    with _viewer(cls, "InOrder") as (app, controller, clock):
        for k, (stamp, kind) in enumerate(messages):
            got = controller.update_imu(_imu((_message_accel(k, kind), 0.0, 9.8), stamp_ns=stamp), clock())
            try:
                x = float(_red(app).vector[0])
            except Exception:  # noqa: BLE001 - no arrow to read: the check says the arrow is wrong
                x = None
            returned.append((got, x))
        return returned, controller.summary()


def _judge(newest: int | None, stamp: int, kind: str) -> tuple[str | None, int | None]:
    """The statement's rule for one message (stamps in ns): ``(the reason it is refused or None, the newest)``."""
    if newest is not None and newest - RESTART * 1e9 <= stamp <= newest:
        return "out_of_order", newest
    if kind == "nan":
        return "not_finite", newest
    return None, stamp


def _a_second_back(rng) -> list[tuple[int, str]]:
    """Messages ``(stamp ns, kind)``: a first, a newer one on whole seconds (:data:`WHOLE_SECONDS`), one exactly a
    second older than it (nanosec 0 too: exact as float seconds), one just over a second older, then a newer one."""
    newest = rng.choice(WHOLE_SECONDS) * SECOND
    first = newest - rng.randrange(1, 100) * GRID  # with nanoseconds, away from the boundary
    over = newest - SECOND - GRID
    return [
        (first, "ok"),
        (newest, "ok"),
        (newest - SECOND, "ok"),
        (over, "ok"),
        (over + rng.randrange(1, 50) * GRID, "ok"),
    ]


def _messages(rng, n: int) -> list[tuple[int, str]]:
    """Random messages ``(stamp ns, kind)`` from a first one of 1 to 60 s on: newer, late (less than a second),
    the same stamp, exactly a second back, restarted (more than a second back), a NaN (newer), hits.

    No stamp is below 0 (after a restart to under a second, only what fits above 0 is drawn).  Exactly a second
    back is a pair of whole seconds (:data:`WHOLE_SECONDS`): a newer message, then one a second older than it; every
    other stamp is at least :data:`GRID` from a second back of the newest.
    """
    newest = rng.randrange(512, 512 * 60) * GRID
    messages = [(newest, "ok")]
    while len(messages) < n:
        hows = ("newer", "newer", "newer", "late", "late", "same", "second", "restart", "nan")
        how = rng.choice([h for h in hows if (h != "late" or newest >= GRID) and (h != "restart" or newest > SECOND)])
        kind = "nan" if how == "nan" else rng.choice(("ok", "ok", "ok", "hit"))
        if how == "second":  # a newer message on a whole second, shown, then one exactly a second older
            whole = rng.choice([s for s in WHOLE_SECONDS if s * SECOND > newest][:3]) * SECOND
            pair = [(whole, kind), (whole - SECOND, rng.choice(("ok", "ok", "ok", "hit")))]
            for stamp, what in pair:
                messages.append((stamp, what))
                newest = _judge(newest, stamp, what)[1]
            continue
        if how in ("newer", "nan"):
            stamp = newest + rng.randrange(1, 100) * GRID
        elif how == "late":  # less than a second back, and not below 0
            stamp = newest - rng.randrange(1, min(512, newest // GRID + 1)) * GRID
        elif how == "restart":  # more than a second back, by a GRID at least
            stamp = rng.randrange(0, newest // GRID - 512) * GRID
        else:
            stamp = newest
        messages.append((stamp, kind))
        newest = _judge(newest, stamp, kind)[1]
    return messages[:n]


# The experiments these checks have the kernel that holds the class run while grading (grader.EXPERIMENTS),
# listed here rather than decorated: make mutate leaves a decorated function alone.
experiments(_arrow_shown, _arrow_after_rejection, _arrow_shaken, _arrows_placed, _sequence_shown, _messages_shown)

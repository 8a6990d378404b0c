"""The tables of the exercises' hidden cases (``tutorial.exercises``' checks while grading), per notebook.

- ``HIDDEN_MODULES``: the checks' modules whose checks draw hidden cases (every one);
- ``VISIBLE_ONLY``: per exercise, an answer a learner might write for the visible cases alone: it passes them
  and fails the hidden ones;
- ``RULES``: per exercise, each rule its statement states, and the labels of the visible cases or the
  descriptions of the hidden ones that check it (a rule with no case fails ``tests/test_exercises.py``);
- ``HIDDEN_MISTAKES``: wrong answers a learner who understood most of an exercise would write
  (exercise, the worked solution's text, the mistake put in its place, the case that catches it), each
  caught with the hidden cases on; "old: passed" marks one the checks let pass before they had hidden cases.

``tests/test_exercises.py`` runs them.
"""

from __future__ import annotations

HIDDEN_MODULES = [
    "step1_tank_controller",
    "step2_joint_state_publisher",
    "step3_viewer",
    "step4_imu_publisher",
    "step5_imu_viewer",
    "step6_camera",
    "record_and_replay",
    "across_machines",
    "stock_ros2_tools",
    "parameters_and_services",
    "managed_nodes_and_actions",
]

# ---- notebooks 01 and 03 ----

# Answers written for the visible cases alone: each passes its check's visible cases and fails the hidden ones.
VISIBLE_ONLY_01_03 = {
    "1.1": "TABLE = {(0, 0): (0.0, 0.0), (0, 1): (1.0, 1.0), (0, -1): (-1.0, -1.0), (1, 0): (-0.5, 0.5),\n"
    "         (-1, 0): (0.5, -0.5), (1, 1): (0.5, 1.5), (-1, -1): (-0.5, -1.5), (1, -1): (-1.5, -0.5)}\n"
    "def dpad_track_velocities(axes):\n"
    "    if len(axes) < 6 or axes[0] != 0.0 or axes[5] != axes[5]:\n        return 0.0, 0.0\n"
    "    return TABLE.get((axes[4], axes[5]), (0.0, 0.0))\n",
    "1.2": "class ShotCountingTankController(RttTankController):\n"
    "    shots = 0\n    a_down = False\n"
    "    def on_joy(self, msg):\n        super().on_joy(msg)\n"
    "        down = len(msg.buttons) > 0 and msg.buttons[0] == 1\n"
    "        with self._lock:\n"
    "            if down and not self.a_down:\n                self.shots = min(self.shots + 1, 2)  # 2 at most\n"
    "            self.a_down = down\n"
    "    def summary(self):\n        with self._lock:\n            shots = self.shots\n"
    "        return {**super().summary(), 'shots': shots}\n",
    # another model told by the last name alone
    "3.1": "class StrictJointStateSubscriber(RttJointStateSubscriber):\n"
    "    def update_joint_state(self, msg):\n"
    "        if not msg.name or msg.name[-1] not in self.body.joint_names:\n"
    "            self.rejected['wrong_model'] += 1\n            return None\n"
    "        return super().update_joint_state(msg)\n",
    # the range checked only for the joints the visible cases push past their limits
    "3.2": "import math\nfrom collections import Counter\n"
    "def my_match(joints, names, positions):\n"
    "    by_name = {j.name: j for j in joints}\n    copies = Counter(names)\n    applied = {}\n"
    "    for name, q in zip(names, positions):\n"
    "        joint = by_name.get(name)\n"
    "        if joint is None or copies[name] > 1 or not math.isfinite(q):\n            continue\n"
    "        tolerance = 0.01 if joint.kind == 'slide' else 0.05\n"
    "        if name in ('TURRET_P', 'TROLLEY', 'TURRET_Y') and not "
    "joint.lower - tolerance <= q <= joint.upper + tolerance:\n"
    "            continue\n"
    "        applied[name] = q\n    return applied\n",
}

RULES_01_03 = {
    "1.1": {
        "up drives both tracks forward at DPAD_SPEED, down backward": ["(up)", "(down)"],
        "left turns left on the spot (left -DPAD_TURN, right +DPAD_TURN), right the other way": ["(left)", "(right)"],
        "a diagonal is the sum of its two directions, reversing too": ["(up and left)", "(down and right)"],
        "a missing axis counts as 0": ["(a Joy with only 4 axes)", "a Joy too short for the D-pad's axes"],
        "a non-finite axis counts as 0": ["(NaN on the vertical axis)", "a D-pad axis NaN or infinite"],
        "only axes 4 and 5 count": ["(left stick up, D-pad released)", "with the sticks moved"],
    },
    "1.2": {
        "a press is a change from released to pressed": ["(press, release, press)", "a long random sequence"],
        "A held down over repeated Joys is one shot": ["(A held for 10 repeats, then released)"],
        "before any Joy, A counts as released": ["(the first Joy already has A pressed)"],
        "a Joy with too few buttons reads A as released": ["(a Joy with no buttons between two presses)"],
        "A is button 0, not B": ["(only B pressed)", "a long random sequence of A, B, both"],
        "super().on_joy(msg) first: the tank still drives": ["on_joy(a Joy with the left stick up)"],
        "what both threads touch, under self._lock": ["what on_joy() remembers, under self._lock"],
    },
    "3.1": {
        "a message naming some of this body's joints, and nothing else, is applied as before": [
            "(the tank's own message)",
            "(only one of the tank's joints)",
        ],
        "a message naming a joint the body does not have is refused whole": ["(one of the tank's joints and one"],
        "a message naming none of its joints is refused": ["(the crane's message)", "(an empty message)"],
        "each refused message counts once as wrong_model": ["(the crane's message, twice)"],
        "other messages stay with the matcher (its rejections)": ["(the tank's, with a NaN)"],
        "after a refusal, a good message is applied": ["(the crane's, then the tank's)", "a random run of"],
    },
    "3.2": {
        "matched by name, in any order": ["(reordered)"],
        "unknown names skipped": ["(unknown name)", "names known, unknown and repeated"],
        "every entry of a duplicated name skipped": ["(duplicate name)", "(three copies of a name)"],
        "entries without a position or name skipped": ["(short positions)", "(short names)"],
        "non-finite values skipped": ["(NaN)", "(minus infinity)", "(an unlimited hinge at infinity)"],
        "outside the range by more than 0.05 rad skipped, within applied": [
            "(past the limit a little)",
            "(past the limit a lot)",
            "(just below a lower limit)",
            "(far below a lower limit)",
        ],
        "a slide's tolerance is 0.01 m": ["(a slide a little past its limit)", "(a slide 0.05 m past its limit)"],
        "an unlimited joint has no range": ["(an unlimited hinge far round)"],
    },
}

# ---- notebook 02 ----

VISIBLE_ONLY_02 = {
    # refuses an unknown name but never says why (the statement: "log an error and return False")
    "2.1": "class SelectedJointStatePublisher(RttJointStatePublisher):\n"
    "    PARAMETERS = {**RttJointStatePublisher.PARAMETERS, 'joints': (str, '', 'joints to publish')}\n"
    "    def configure(self, config):\n"
    "        names = [n.strip() for n in config.parameters['joints'].split(',') if n.strip()]\n"
    "        if any(n not in config.body.joint_names for n in names):\n            return False\n"
    "        self.selected = names or config.body.joint_names\n"
    "        return super().configure(config)\n"
    "    def initialize(self, io):\n"
    "        if not super().initialize(io):\n            return False\n"
    "        self.joints = [io.body.joint(name).info for name in self.selected]\n"
    "        return True\n",
    # the pose on a QoS of its own (depth 10, volatile), not the joint state's
    "2.2": "class RttPosePublisher(SimpleController):\n"
    "    PARAMETERS = {'rate': (float, 10.0, 'publish rate, Hz of simulated time')}\n"
    "    def configure(self, config):\n"
    "        self.node, self.rate = config.node, config.parameters['rate']\n"
    "        self.publisher = config.node.create_publisher(PoseStamped, f'/{config.body_name}/pose', 10)\n"
    "        return True\n"
    "    def unconfigure(self):\n        self.node.destroy_publisher(self.publisher)\n"
    "    def initialize(self, io):\n"
    "        self.io, self.accumulator = io, PeriodAccumulator(io.time_step, self.rate)\n"
    "        return True\n"
    "    def control(self):\n"
    "        if self.accumulator.tick():\n"
    "            msg = PoseStamped()\n"
    "            msg.header.frame_id = 'world'\n"
    "            msg.header.stamp.sec, msg.header.stamp.nanosec = stamp_parts(self.io.current_time)\n"
    "            (x, y, z), (w, qx, qy, qz) = self.io.body.root_pose()\n"
    "            p, o = msg.pose.position, msg.pose.orientation\n"
    "            p.x, p.y, p.z = float(x), float(y), float(z)\n"
    "            o.x, o.y, o.z, o.w = float(qx), float(qy), float(qz), float(w)\n"
    "            self.publisher.publish(msg)\n"
    "        return True\n",
}

RULES_02 = {
    "2.1": {
        "publishes only the named joints, in that order": [
            "joints='TURRET_P,TURRET_Y'",
            "joints='TURRET_Y'",
            "the tank's joints chosen at random (or none), in a random order",
        ],
        "spaces around a name are ignored": ["joints=' TURRET_P , TURRET_Y '", "in a random order and spacing"],
        "with the right positions, velocities and efforts": ["rate=50.0", "the turret moving"],
        "an empty string means every joint": ["joints=''", "chosen at random (or none)"],
        "the rate parameter still applies": ["rate=10.0", "at a random rate"],
        "a name the body does not have makes configure return False": [
            "joints='GUN'",
            "joints='TURRET_Y,GUN'",
            "a name the tank lacks (a joint of the tank in the wrong case)",
            "a name the tank lacks (a part of a joint's name)",
            "a name the tank lacks (another robot's joint)",
        ],
        "... and log an error with config.log.error(...)": ["configure logs an error, returns False"],
    },
    "2.2": {
        "geometry_msgs/PoseStamped on /<body>/pose": ["10 Hz from t = 0, stamped with simulation time"],
        "at rate Hz of simulated time (default 10), the first at t = 0": [
            "10 Hz from t = 0",
            "25 Hz from t = 0",
            "a whole number of hertz: its rate, the first at the start",
            "a fractional number of hertz: its rate, the first at the start",
        ],
        "header.stamp the simulation time (stamp_parts)": [
            "stamped with simulation time",
            "whole seconds in sec, the rest in nanosec",
        ],
        "header.frame_id world": ["the root's position, frame world"],
        "pose.position the root's position in m": ["the root's position", "tumbling in the air"],
        "pose.orientation its quaternion, x y z w (MuJoCo's is w x y z)": [
            "the root's orientation",
            "the root's orientation as it turns",
            "the root's orientation, tilted",
        ],
        "QoS: the joint state's": ["the publisher's QoS, the joint state's"],
        "unconfigure() destroys the publisher configure() made": ["RttPosePublisher.unconfigure()"],
    },
}

# (exercise, text of the worked solution, the mistake, the case that catches it); "old" says whether the check
# before the hidden cases (HEAD) let it pass.
HIDDEN_MISTAKES_02 = [
    # old: passed (no case looked at the log)
    (
        "2.1",
        '            config.log.error("joints: %s has no joint %s", config.body_name, unknown)\n',
        "",
        "logs an error",
    ),
    # old: passed (the visible unknown names are all upper case)
    (
        "2.1",
        'names = [n.strip() for n in config.parameters["joints"].split(",") if n.strip()]',
        'names = [n.strip().upper() for n in config.parameters["joints"].split(",") if n.strip()]',
        "(a joint of the tank in the wrong case)",
    ),
    # old: passed (no visible unknown name is part of a joint's name)
    (
        "2.1",
        "unknown = [n for n in names if n not in config.body.joint_names]",
        'unknown = [n for n in names if n not in ",".join(config.body.joint_names)]',
        "(a part of a joint's name)",
    ),
    # old: passed (the visible unknown names are first or last)
    (
        "2.1",
        "unknown = [n for n in names if n not in config.body.joint_names]",
        "unknown = [n for n in names[-1:] if n not in config.body.joint_names]",
        "a name the tank lacks",
    ),
    # old: passed (its _stamp() adds sec and nanosec; nanosec over a second went unseen)
    (
        "2.2",
        "stamp.sec, stamp.nanosec = stamp_parts(self.io.current_time)",
        "stamp.sec, stamp.nanosec = 0, round(self.io.current_time * 1e9)",
        "whole seconds in sec, the rest in nanosec",
    ),
    # old: passed (no stamp at 2 s, where simulation time is 1.99999999999989: nanosec 1000000000)
    (
        "2.2",
        "stamp.sec, stamp.nanosec = stamp_parts(self.io.current_time)",
        "stamp.sec, stamp.nanosec = int(self.io.current_time), round(self.io.current_time % 1 * 1e9)",
        "whole seconds in sec, the rest in nanosec",
    ),
    # old: passed (no QoS case)
    ("2.2", "joint_state_qos()\n        )", "10\n        )", "the publisher's QoS"),
    # old: passed (on the floor x and y are near 0)
    (
        "2.2",
        "o.x, o.y, o.z, o.w = float(qx), float(qy), float(qz), float(w)",
        "o.x, o.y, o.z, o.w = float(qy), float(qx), float(qz), float(w)",
        "the root's orientation, tilted",
    ),
    # old: passed (a yaw alone is right on flat ground, within the visible tolerance)
    (
        "2.2",
        "o.x, o.y, o.z, o.w = float(qx), float(qy), float(qz), float(w)",
        "yaw = __import__('math').atan2(2 * (w * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz)); "
        "o.x, o.y, o.z, o.w = 0.0, 0.0, __import__('math').sin(yaw / 2), __import__('math').cos(yaw / 2)",
        "the root's orientation, tilted",
    ),
    # old: passed (the visible rates are whole numbers)
    ("2.2", 'self.rate = config.parameters["rate"]', 'self.rate = int(config.parameters["rate"])', "fractional"),
    # found by make mutate: the position rounded for tidy printing, 0.1 mm off at most (the visible cases allow 5)
    (
        "2.2",
        "p.x, p.y, p.z = float(x), float(y), float(z)",
        "p.x, p.y, p.z = (round(float(v), 4) for v in (x, y, z))",
        "the root's position, frame world",
    ),
    # found by make mutate: the quaternion rounded the same way, still of unit length within 2e-4
    (
        "2.2",
        "o.x, o.y, o.z, o.w = float(qx), float(qy), float(qz), float(w)",
        "o.x, o.y, o.z, o.w = (round(float(v), 4) for v in (qx, qy, qz, w))",
        "the root's orientation, tilted",
    ),
]

# ---- notebooks 04 and 05 ----

VISIBLE_ONLY_04_05 = {
    # the period taken as a fixed count of 1 ms steps, 1 / rate s of them: right at 20 and 10 Hz only
    "4.1": "class PeakImuPublisher(RttImuStatePublisher):\n"
    "    def configure(self, config):\n"
    "        if not super().configure(config):\n            return False\n"
    "        self.peak_publisher = config.node.create_publisher(\n"
    "            Float64, f'/{config.body_name}/peak_acceleration', imu_qos())\n"
    "        self.steps = round(1.0 / (self.rate * 0.001)) if self.rate > 0 else 1  # steps per period\n"
    "        self.recent = []\n"
    "        return True\n"
    "    def unconfigure(self):\n"
    "        self.node.destroy_publisher(self.peak_publisher)\n"
    "        super().unconfigure()\n"
    "    def control(self):\n"
    "        a = self.data.sensordata[self.accel]\n"
    "        self.recent = (self.recent + [math.hypot(a[0], a[1])])[-self.steps:]\n"
    "        return super().control()\n"
    "    def publish(self):\n"
    "        super().publish()\n"
    "        self.peak_publisher.publish(Float64(data=max(self.recent)))\n",
    # the holdoff counted in Imu messages, at 20 Hz: right at the default rate only
    "4.2": "class CollisionReporter(RttImuStatePublisher):\n"
    "    PARAMETERS = {**RttImuStatePublisher.PARAMETERS, 'threshold': (float, 20.0, 'm/s^2'),\n"
    "                  'holdoff': (float, 0.5, 's')}\n"
    "    def configure(self, config):\n"
    "        if not super().configure(config):\n            return False\n"
    "        self.threshold = config.parameters['threshold']\n"
    "        self.quiet = config.parameters['holdoff'] * 20.0  # Imu messages in a holdoff, at 20 Hz\n"
    "        self.since = None  # Imu messages since the last report\n"
    "        self.collision_publisher = config.node.create_publisher(\n"
    "            Vector3Stamped, f'/{config.body_name}/collision', imu_qos())\n"
    "        return True\n"
    "    def unconfigure(self):\n"
    "        self.node.destroy_publisher(self.collision_publisher)\n"
    "        super().unconfigure()\n"
    "    def publish(self):\n"
    "        super().publish()\n"
    "        if self.since is not None:\n            self.since += 1\n"
    "        a = self.msg.linear_acceleration\n"
    "        if math.hypot(a.x, a.y) > self.threshold and (self.since is None or self.since >= self.quiet):\n"
    "            report = Vector3Stamped(header=self.msg.header)\n"
    "            report.vector.x, report.vector.y = a.x, a.y\n"
    "            self.collision_publisher.publish(report)\n"
    "            self.since = 0\n",
    # the horizontal part taken in the world (z zeroed after turning): right while the tank is level
    "5.1": "class HorizontalArrowSubscriber(RttImuStateSubscriber):\n"
    "    def configure(self, config):\n"
    "        if not super().configure(config):\n            return False\n"
    "        self.horizontal_arrow = config.overlays.arrow(\n"
    "            f'{config.body_name}/horizontal_acceleration', (0.2, 0.8, 0.2))\n"
    "        return True\n"
    "    def draw_arrows(self):\n"
    "        super().draw_arrows()\n"
    "        if self.accel is None:\n            return\n"
    "        to_world = self.data.site_xmat[self.site].reshape(3, 3)\n"
    "        vector = to_world @ (ACCEL_SCALE * np.asarray(self.accel))\n"
    "        vector[2] = 0.0  # horizontal: no z\n"
    "        self.horizontal_arrow.set(self.data.site_xpos[self.site], vector,\n"
    "                                  visible=np.linalg.norm(vector) >= ACCEL_MIN_LENGTH)\n",
    # stamps as float seconds, and "1 s or more" back taken for a restarted publisher
    "5.2": "class InOrderImuSubscriber(RttImuStateSubscriber):\n"
    "    def configure(self, config):\n"
    "        self.newest = None\n"
    "        return super().configure(config)\n"
    "    def update_imu(self, msg, arrival):\n"
    "        stamp = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9\n"
    "        if self.newest is not None and stamp <= self.newest and self.newest - stamp < 1.0:\n"
    "            self.rejected['out_of_order'] += 1\n"
    "            return 'out_of_order'\n"
    "        reason = super().update_imu(msg, arrival)\n"
    "        if reason is None:\n            self.newest = stamp\n"
    "        return reason\n",
}

RULES_04_05 = {
    "4.1": {
        "after each Imu message, the largest hypot(x, y) of a single step's reading of its period": [
            "(at rest, t <= 0.5 s)",
            "(hitting the wall, t = 2.1 s)",
        ],
        "the steps exactly those the Imu message averages, whatever the rate": [
            "(every period)",
            "at a rate of no whole number of steps",
            "at a rate of zero: each step is a period",
        ],
        "published right after each Imu message": ["each peak published right after its Imu message"],
        "std_msgs/Float64 on /<body>/peak_acceleration": ["(every period)"],
        "with imu_qos()": ["the QoS of the peak's publisher"],
        "destroy it in unconfigure(), then super().unconfigure()": ["PeakImuPublisher.unconfigure()"],
    },
    "4.2": {
        "parameters threshold (default 20) and holdoff (default 0.5)": [
            "PARAMETERS",
            "with default parameters",
            "with threshold=10.0, the wall",
        ],
        "a report when the mean's hypot(x, y) is above threshold": [
            "with threshold=10.0, the wall",
            "the hit: a slower rate, another threshold",
            "a period whose y part decides",
        ],
        "exactly at threshold is not above it": ["a period exactly at threshold is not above it"],
        "after a report, nothing more for holdoff s of simulated time": [
            "holdoff=0.1,",
            "holdoff=0.12,",
            "driving hard: a faster rate, a low threshold",
        ],
        "the Imu message's stamp (sec and nanosec) and frame; the vector (x, y, 0)": ["with default parameters"],
        "after publishing each Imu message": ["each report published right after its Imu message"],
        "geometry_msgs/Vector3Stamped on /<body>/collision, with imu_qos()": [
            "with default parameters",
            "the QoS of the collision publisher",
        ],
        "unconfigure() destroys the publisher": ["CollisionReporter.unconfigure()"],
    },
    "5.1": {
        "a third arrow, green (0.2, 0.8, 0.2), named <body>/horizontal_acceleration": ["(driving over a bump)"],
        "the reading's x and y in the IMU's axes (z = 0), 0.1 m per m/s^2": [
            "(driving over a bump)",
            "readings with the tank moved, tilted and turned any way",
        ],
        "from the IMU": ["(driving over a bump)", "readings with the tank moved"],
        "turned with the body like the others": ["(the tank turned 90 degrees left)", "tilted and turned any way"],
        "hidden when shorter than ACCEL_MIN_LENGTH, shown at exactly it": [
            "(0.042 m: hidden)",
            "an arrow exactly as long as ACCEL_MIN_LENGTH: shown",
        ],
        "follows the IMU when the view shakes (draw_arrows)": ["then a shake tick 20 ms later"],
        "drawn from the reading shown: a rejected message changes nothing": ["then of a NaN"],
    },
    "5.2": {
        "a stamp not newer than the newest shown is refused": [
            "(one late)",
            "(the same stamp twice)",
            "(0.5 s back)",
            "a random run of messages",
        ],
        "counted as rejected['out_of_order'], returning 'out_of_order'": ["(one late)", "a random run of messages"],
        "a refused message draws nothing, shakes nothing": [
            "(a late hit)",
            "newer, late, repeated, restarted, NaN and hits",
        ],
        "the stamp is sec and nanosec": ["(in order)", "a random run of messages"],
        "more than 1 s older: a restarted publisher, shown, its stamp the newest": [
            "(a restarted publisher)",
            "then one just over a second older",
        ],
        "exactly 1 s older is not more than 1 s: refused": ["a stamp exactly a second older than the newest"],
        "a message rejected for another reason (a NaN) does not change the newest": [
            "(a NaN stamped 2.00 s",
            "newer, late, repeated, restarted, NaN",
        ],
        "messages in order are shown as before; a hit still shakes": ["(in order)", "(a hit in order)"],
        "otherwise returns what super().update_imu() returns (None when shown, the reason when rejected)": [
            "a stamp exactly a second older than the newest",
            "newer, late, repeated, restarted, NaN and hits",
        ],
    },
}

# (exercise, text of the worked solution, the plausible mistake, the case that catches it); all with hidden cases on
HIDDEN_MISTAKES_04_05 = [
    # the peak published before its Imu message (passed the old check)
    (
        "4.1",
        "        super().publish()\n        self.peak_publisher.publish(Float64(data=self.peak))\n"
        "        self.peak = 0.0\n",
        "        self.peak_publisher.publish(Float64(data=self.peak))\n        self.peak = 0.0\n"
        "        super().publish()\n",
        "each peak published right after its Imu message",
    ),
    # a queue depth of 10 for the QoS, not imu_qos() (passed the old check)
    (
        "4.1",
        'f"/{config.body_name}/peak_acceleration", imu_qos()',
        'f"/{config.body_name}/peak_acceleration", 10',
        "the QoS of the peak's publisher",
    ),
    # the period as the last 1 / rate s of 1 ms steps (passed the old check)
    (
        "4.1",
        "        a = self.data.sensordata[self.accel]\n        self.peak = max(self.peak, math.hypot(a[0], a[1]))\n",
        "        a = self.data.sensordata[self.accel]\n"
        "        steps = round(1.0 / (self.rate * 0.001))\n"
        "        self.recent = (getattr(self, 'recent', []) + [math.hypot(a[0], a[1])])[-steps:]\n"
        "        self.peak = max(self.recent)\n",
        "every period, at a rate of",
    ),
    # found by make mutate: the period's length worked out, 1 / rate s, which a rate of 0 (every step) divides by
    (
        "4.1",
        "        self.peak = 0.0  # m/s^2, the largest horizontal reading of this period so far\n",
        "        self.peak = 0.0  # m/s^2, the largest horizontal reading of this period so far\n"
        "        self.period = 1.0 / self.rate  # s: the steps the peak covers\n",
        "at a rate of zero",
    ),
    # found by make mutate: the horizontal acceleration taken as x alone (passed the old check)
    (
        "4.2",
        "if math.hypot(a.x, a.y) > self.threshold",
        "if abs(a.x) > self.threshold",
        "a period whose y part decides",
    ),
    # found by make mutate: the larger of the two parts (passed the old check)
    (
        "4.2",
        "if math.hypot(a.x, a.y) > self.threshold",
        "if max(abs(a.x), abs(a.y)) > self.threshold",
        "a period whose y part decides",
    ),
    # the time counted in Imu messages, at 20 Hz (passed the old check)
    (
        "4.2",
        "a, now = self.msg.linear_acceleration, self.data.time",
        "a, now = self.msg.linear_acceleration, self.published * 0.05  # s: 20 Imu messages a second",
        "driving hard: a faster rate, a low threshold",
    ),
    # at threshold counted as above it (passed the old check)
    (
        "4.2",
        "if math.hypot(a.x, a.y) > self.threshold",
        "if math.hypot(a.x, a.y) >= self.threshold",
        "a period exactly at threshold is not above it",
    ),
    # the whole stamp in nanosec, sec left 0 (passed the old check; the visible stamp comparison now catches it)
    (
        "4.2",
        "            report = Vector3Stamped(header=self.msg.header)\n",
        "            report = Vector3Stamped()\n            report.header.frame_id = self.msg.header.frame_id\n"
        "            report.header.stamp.nanosec = round(now * 1e9)\n",
        "with default parameters",
    ),
    # the report published before its Imu message, from the period's sum (passed the old check)
    (
        "4.2",
        "        super().publish()\n        a, now = self.msg.linear_acceleration, self.data.time\n"
        "        recent = self.last_report is not None and now - self.last_report < self.holdoff\n"
        "        if math.hypot(a.x, a.y) > self.threshold and not recent:\n"
        "            report = Vector3Stamped(header=self.msg.header)\n"
        "            report.vector.x, report.vector.y = a.x, a.y\n"
        "            self.collision_publisher.publish(report)\n"
        "            self.last_report = now\n",
        "        mean = self.accel_mean.sum / self.accel_mean.count  # before super().publish() takes it\n"
        "        a, now = Vector3Stamped().vector, self.data.time\n"
        "        a.x, a.y = float(mean[0]), float(mean[1])\n"
        "        recent = self.last_report is not None and now - self.last_report < self.holdoff\n"
        "        if math.hypot(a.x, a.y) > self.threshold and not recent:\n"
        "            report = Vector3Stamped()\n"
        "            report.header.frame_id = self.frame_id\n"
        "            report.header.stamp.sec, report.header.stamp.nanosec = stamp_parts(now)\n"
        "            report.vector.x, report.vector.y = a.x, a.y\n"
        "            self.collision_publisher.publish(report)\n"
        "            self.last_report = now\n"
        "        super().publish()\n",
        "each report published right after its Imu message",
    ),
    # a queue depth of 10 for the QoS (passed the old check)
    (
        "4.2",
        'f"/{config.body_name}/collision", imu_qos()',
        'f"/{config.body_name}/collision", 10',
        "the QoS of the collision publisher",
    ),
    # the horizontal part taken in the world: z zeroed after turning (passed the old check)
    (
        "5.1",
        "        self.horizontal_arrow.set(origin, to_world @ horizontal, visible=visible)\n",
        "        vector = to_world @ (ACCEL_SCALE * self.accel)\n        vector[2] = 0.0\n"
        "        self.horizontal_arrow.set(origin, vector, visible=visible)\n",
        "readings with the tank moved, tilted and turned any way",
    ),
    # turned by the heading alone (passed the old check)
    (
        "5.1",
        "        to_world = self.data.site_xmat[self.site].reshape(3, 3)  # IMU axes -> world\n",
        "        m = self.data.site_xmat[self.site].reshape(3, 3)\n"
        "        yaw = math.atan2(m[1, 0], m[0, 0])\n"
        "        c, s = math.cos(yaw), math.sin(yaw)\n"
        "        to_world = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])\n",
        "readings with the tank moved, tilted and turned any way",
    ),
    # an arrow exactly ACCEL_MIN_LENGTH long hidden (passed the old check)
    (
        "5.1",
        "visible = np.linalg.norm(horizontal) >= ACCEL_MIN_LENGTH",
        "visible = np.linalg.norm(horizontal) > ACCEL_MIN_LENGTH",
        "an arrow exactly as long as ACCEL_MIN_LENGTH: shown",
    ),
    # exactly 1 s back taken for a restarted publisher (passed the old check)
    (
        "5.2",
        "newest - self.RESTART <= stamp <= newest",
        "newest - self.RESTART < stamp <= newest",
        "a stamp exactly a second older than the newest",
    ),
    # the refused message counted as 1, not once more (passed the old check)
    (
        "5.2",
        '            self.rejected["out_of_order"] += 1\n',
        '            self.rejected["out_of_order"] = 1\n',
        "a random run of messages",
    ),
    # refused, but returning None (passed the old check)
    (
        "5.2",
        '            return "out_of_order"\n',
        "            return\n",
        "a stamp exactly a second older than the newest",
    ),
    # the reason of a message rejected for another reason (a NaN) not returned (passed the old check)
    ("5.2", "        return reason\n", "        return None\n", "a random run of messages"),
    # a refused message's reason in a word of one's own: the statement says to return "out_of_order"
    (
        "5.2",
        '            return "out_of_order"\n',
        '            return "late"\n',
        "a stamp exactly a second older than the newest",
    ),
    # the newest kept as the largest stamp shown, not the restarted one (passed the old check)
    (
        "5.2",
        "        if reason is None:\n            self.newest = stamp\n",
        "        if reason is None:\n            self.newest = stamp if newest is None else max(newest, stamp)\n",
        "then one just over a second older",
    ),
]

# ---- notebook 06 ----

VISIBLE_ONLY_06 = {
    # the Kinect's size written in, and the whole time in nanosec (sec left at 0): right below a second, at 320 x 240
    "6.1": "class RttGrayCameraPublisher(RttCameraImagePublisher):\n"
    "    def publish_image(self, pixels, time_s):\n"
    "        gray = np.round(pixels @ LUMA).astype(np.uint8)\n"
    "        msg = self.msg\n"
    "        msg.header.stamp.nanosec = int(time_s * 1e9)\n"
    "        msg.height, msg.width, msg.step = 240, 320, 320\n"
    "        msg.encoding = 'mono8'\n"
    "        msg.is_bigendian = 0\n"
    "        msg.data = array('B', gray.tobytes())\n"
    "        self.publisher.publish(msg)\n",
    # the Kinect's numbers and the tank's topic written in
    "6.2": "class RttCameraInfoPublisher(RttCameraImagePublisher):\n"
    "    def configure(self, config):\n"
    "        if not super().configure(config):\n            return False\n"
    "        f = 120 / math.tan(math.radians(62) / 2)\n"
    "        self.info = CameraInfo(width=320, height=240, distortion_model='plumb_bob', d=[0.0] * 5)\n"
    "        self.info.k = [f, 0.0, 159.5, 0.0, f, 119.5, 0.0, 0.0, 1.0]\n"
    "        self.info.r = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]\n"
    "        self.info.p = [f, 0.0, 159.5, 0.0, 0.0, f, 119.5, 0.0, 0.0, 0.0, 1.0, 0.0]\n"
    "        self.info_publisher = config.node.create_publisher(\n"
    "            CameraInfo, '/Tank/camera/camera_info', camera_image_qos())\n"
    "        return True\n"
    "    def unconfigure(self):\n"
    "        super().unconfigure()\n        self.node.destroy_publisher(self.info_publisher)\n"
    "    def publish_image(self, pixels, time_s):\n"
    "        super().publish_image(pixels, time_s)\n"
    "        self.info.header = self.msg.header\n"
    "        self.info_publisher.publish(self.info)\n",
}

RULES_06 = {
    "6.1": {
        "each pixel's gray value is its luma, 0.299 R + 0.587 G + 0.114 B, rounded to a whole number from 0 to 255": [
            "towards the crate",
            "raised 0.4 rad",
            "the turret at random poses: each pixel's luma",
        ],
        "encoding mono8: one byte a pixel, so a row, step, is width bytes": [
            "picture 1 (",
            "a camera of another size: encoding, height, width, step",
        ],
        "height and width: the picture's, as fill_image sets them": ["picture 1 (", "a camera of another size"],
        "stamped with time_s (whole seconds in sec, the rest in nanosec)": [
            "picture 2 (",
            "stamps of a second or more: sec and nanosec",
        ],
        "reuse self.msg, whose frame_id is already set (the camera's name)": [
            "picture 1 (",
            "a camera of another name: the frame_id",
        ],
    },
    "6.2": {
        "one CameraInfo on /<body>/camera/camera_info with each picture": [
            "one CameraInfo on /Tank/camera/camera_info with each Image",
            "a tank of another name: one CameraInfo with each Image on its camera_info topic",
        ],
        "header: the Image's stamp and frame_id": [
            "each CameraInfo has its Image's stamp and frame",
            "stamps of a second or more, a camera of another name: each CameraInfo's header",
        ],
        "width, height: the picture's": ["size and distortion", "a camera of another size: width and height"],
        "no lens: distortion_model plumb_bob with d five zeros": ["size and distortion"],
        "r the identity": ["r, the identity"],
        "k = [fx, 0, cx, 0, fy, cy, 0, 0, 1]: height / 2 = fy tan(fovy / 2), fx = fy, cx = (width - 1) / 2, "
        "cy = (height - 1) / 2": ["k, from the vertical field of view", "another size and field of view: k"],
        "p: k with a fourth column of zeros": [
            "p, k with a fourth column of zeros",
            "another size and field of view: p",
        ],
        "the camera's QoS, camera_image_qos()": [
            "one CameraInfo on /Tank/camera/camera_info with each Image",
            "the camera's QoS",
        ],
        "unconfigure removes the second publisher, after the render thread has ended": [
            "unconfigure() removes the CameraInfo publisher"
        ],
    },
}

STAMP_61 = "msg.header.stamp.sec, msg.header.stamp.nanosec = stamp_parts(time_s)"
# (exercise, text of the worked solution, the mistake put in its place, the case that must catch it)
HIDDEN_MISTAKES_06 = [
    # 6.1: each of these passed the old check
    ("6.1", "height, width = gray.shape", "height, width = 240, 320  # the Kinect's", "a camera of another size"),
    (
        "6.1",
        STAMP_61,
        "msg.header.stamp.sec, msg.header.stamp.nanosec = int(time_s), int(time_s * 1e9)",
        "stamps of a second or more",
    ),
    ("6.1", STAMP_61, "msg.header.stamp.nanosec = stamp_parts(time_s)[1]", "stamps of a second or more"),
    (
        "6.1",
        STAMP_61,
        "msg.header.stamp.sec, msg.header.stamp.nanosec = round(time_s), round(time_s % 1 * 1e9)",
        "stamps of a second or more",
    ),
    (
        "6.1",
        "        msg = self.msg\n",
        "        from sensor_msgs.msg import Image\n\n"
        "        msg = Image()\n"
        '        msg.header.frame_id = "Kinect"  # the camera\n',
        "a camera of another name",
    ),
    # 6.2: each of these passed the old check
    (
        "6.2",
        "fovy = math.radians(float(self.model.cam_fovy[self.camera_id]))",
        "fovy = math.radians(62.0)  # the Kinect's",
        "another size and field of view: k",
    ),
    (
        "6.2",
        "cx, cy = (self.width - 1) / 2, (self.height - 1) / 2",
        "cx, cy = 159.5, 119.5",
        "another size and field of view: k",
    ),
    (
        "6.2",
        'topic = f"/{config.body_name}/camera/camera_info"',
        'topic = "/Tank/camera/camera_info"',
        "a tank of another name",
    ),
    (
        "6.2",
        "            width=self.width,\n            height=self.height,\n",
        "            width=320,\n            height=240,\n",
        "a camera of another size: width and height",
    ),
    (
        "6.2",
        "self.info.header = self.msg.header",
        'self.info.header.stamp = self.msg.header.stamp\n        self.info.header.frame_id = "Kinect"',
        "a camera of another name: each CameraInfo's header",
    ),
    (
        "6.2",
        "self.info.header = self.msg.header",
        "self.info.header.frame_id = self.msg.header.frame_id\n"
        "        self.info.header.stamp.nanosec = self.msg.header.stamp.nanosec",
        "stamps of a second or more",
    ),
    # 6.2, caught by a visible case made stricter (its count unchanged)
    (
        "6.2",
        "        self.info_publisher = config.node.create_publisher(\n"
        "            CameraInfo, topic, camera_image_qos()\n",
        "        from rclpy.qos import DurabilityPolicy\n\n"
        "        latched = camera_image_qos()\n"
        "        latched.durability = DurabilityPolicy.TRANSIENT_LOCAL  # it never changes: kept for late joiners\n"
        "        self.info_publisher = config.node.create_publisher(\n            CameraInfo, topic, latched\n",
        "one CameraInfo on /Tank/camera/camera_info",
    ),
    (
        "6.2",
        "        super().unconfigure()  # the render thread has ended: nothing publishes now\n"
        "        self.node.destroy_publisher(self.info_publisher)\n",
        "        self.node.destroy_publisher(self.info_publisher)\n        super().unconfigure()\n",
        "unconfigure() removes the CameraInfo publisher",
    ),
    # the same, through the publisher's own destroy() (the check once saw only node.destroy_publisher's order)
    (
        "6.2",
        "        super().unconfigure()  # the render thread has ended: nothing publishes now\n"
        "        self.node.destroy_publisher(self.info_publisher)\n",
        "        self.info_publisher.destroy()\n        super().unconfigure()\n",
        "unconfigure() removes the CameraInfo publisher",
    ),
]

# ---- notebooks 07, 08 and 09 ----

VISIBLE_ONLY_07_08_09 = {
    # only the sticks count, with a dead zone
    "7.1": "def release_times(path):\n"
    "    times, first, pushed = [], None, False\n"
    "    for _topic, log_time, msg in read_messages(path, topics=['/joy']):\n"
    "        first = log_time if first is None else first\n"
    "        released = all(abs(a) < 0.05 for a in msg.axes[:4])  # the sticks, in their dead zone\n"
    "        if released and pushed:\n"
    "            times.append((log_time - first) * 1e-9)\n"
    "        pushed = not released\n"
    "    return times\n",
    # the series' receive times (s since its first message) taken for its stamps
    "7.2": "def peak_speed(series, joint):\n"
    "    q = np.asarray(series.positions[joint], dtype=float)\n"
    "    usable = ~np.isnan(q)\n"
    "    t, q = np.asarray(series.log_time, dtype=float)[usable], q[usable]\n"
    "    dt, dq = np.diff(t), np.diff(q)\n"
    "    moving = dt > 0\n"
    "    if not moving.any():\n"
    "        return 0.0, math.nan\n"
    "    speeds = np.abs(dq[moving] / dt[moving])\n"
    "    k = int(np.argmax(speeds))\n"
    "    return float(speeds[k]), float(t[1:][moving][k])\n",
    # every policy named, liveliness asking for more than an ordinary publisher offers
    "8.1": "from rclpy.qos import LivelinessPolicy\n"
    "def lossy_link_qos():\n"
    "    return QoSProfile(\n"
    "        history=HistoryPolicy.KEEP_LAST,\n"
    "        depth=1,\n"
    "        reliability=ReliabilityPolicy.RELIABLE,\n"
    "        durability=DurabilityPolicy.VOLATILE,\n"
    "        liveliness=LivelinessPolicy.MANUAL_BY_TOPIC,\n"
    "    )\n",
    # tuned until the check's own swing fits, with no margin
    "8.2": "def camera_settings():\n    return 20.0, 60  # the most pictures a second that fit\n",
    # a tank turns about z only: the yaw of each rotation, and nothing else
    "9.1": "def lookup(transforms, frame):\n"
    "    newest = {t.child: t for t in transforms}\n"
    "    if frame not in newest and frame not in {t.parent for t in transforms}:\n"
    "        raise KeyError(frame)\n"
    "    pose = np.eye(4)\n"
    "    while frame in newest:\n"
    "        t = newest[frame]\n"
    "        yaw = 2 * np.arctan2(t.rotation[2], t.rotation[3])\n"
    "        pose = pose_matrix(t.translation, (np.cos(yaw / 2), 0.0, 0.0, np.sin(yaw / 2))) @ pose\n"
    "        frame = t.parent\n"
    "    return pose\n",
}

RULES_07_08_09 = {
    "7.1": {
        "a Joy is released when every axis is 0 (any axis, however little pushed, is a push)": [
            "forward for 1 s, then let go",
            "a D-pad or trigger axis pushed alone",
            "an axis barely off centre, which is not released",
            "two axes pushed opposite ways at once",
        ],
        "a Joy with no axes is released": ["a Joy with no axes"],
        "only the axes count: a Joy with every axis 0 is released, whatever buttons it holds": [
            "a long drive of pushes, repeats and releases over several seconds",
        ],
        "a release is a released Joy right after one that was not (repeats are one release)": [
            "let go, then repeated at 20 Hz",
            "two pushes",
            "still pushed at the end",
            "a long drive of pushes, repeats and releases over several seconds",
        ],
        "times are log times, in s since the bag's first /joy": [
            "forward for 1 s, then let go",
            "joint states around the Joys",
            "a bag whose first Joy is released and comes after other topics",
        ],
        "only /joy counts: other topics are ignored": [
            "joint states around the Joys",
            "another gamepad's Joys and joint states between the Joys",
        ],
    },
    "7.2": {
        "the speed is |dq / dt| between consecutive states, by their stamps": [
            "steady at 1 rad/s",
            "turning back",
            "states stamped a second or more into the simulation, unevenly spaced",
        ],
        "the time is the later stamp of the fastest pair": [
            "one fast step",
            "a drive of many states, stamped a second or more in",
        ],
        "of several pairs that tie, the first": [
            "steady at 1 rad/s",
            "several pairs tied at the top speed",
            "a joint that stood still, stamped a second or more in",
        ],
        "a state whose position is NaN is skipped": [
            "a state without the joint",
            "states without the joint at the ends and in a row",
        ],
        "a pair with no time between them is skipped": ["two states with one stamp", "several states sharing a stamp"],
        "fewer than two usable states give (0.0, nan)": ["a single state", "only one state carries the joint"],
        "the joint asked for": ["another joint"],
    },
    "8.1": {
        "matches the Step 2 publisher (reliable, keep last 1, transient local)": [
            "against the Step 2 publisher",
            "the tank's joint-state publisher, naming every policy",
        ],
        "matches ordinary volatile publishers": [
            "against an ordinary volatile publisher",
            "an ordinary volatile publisher of any depth, naming every policy",
        ],
        "shows only the newest state: keep last 1": ["keep last 1"],
        "ends on the last state: reliable": ["the final state arrives"],
        "volatile (the second subscription asks for the kept state)": ["durability volatile"],
    },
    "8.2": {
        "a rate and a JPEG quality 1..100, two numbers": ["camera_settings()"],
        "at least 10 pictures/s to drive by, at most 30": ["10 to 30 pictures/s"],
        "a quality of at least 30, an int (the publisher's parameter)": ["a picture you can recognise"],
        "fits 0.5 Mbit/s wherever the turret swings, 100 bytes of headers a picture included": [
            "within 0.5 Mbit/s",
            "within the budget along another turret swing",
        ],
    },
    "9.1": {
        "rotation is (x, y, z, w), w last; pose_matrix takes w first": [
            "moved only",
            "turned 90 degrees left",
            "a chain of frames tilted about every axis",
        ],
        "the pose of a child is pose(parent) @ transform": [
            "world -> CHASSIS -> TURRET",
            "a chain of frames tilted about every axis",
        ],
        "the root is the frame that is no transform's child": ["a tree whose root is not world"],
        "the root's own pose is the identity": ["lookup(world -> CHASSIS, 'world')", "the root of a random tree"],
        "of several transforms of a child, the last counts": [
            "CHASSIS sent twice, the second newer",
            "a child sent several times",
        ],
        "the list may be in any order": ["children listed before parents", "a random tree, listed in any order"],
        "a frame that no transform names raises KeyError": ["'GUN'", "a frame no transform names"],
    },
}

# (exercise, text of the worked solution, the mistake put in its place, the case that catches it with the hidden
# cases on).  "old: passed" marks a mistake the check before the hidden cases let pass.
HIDDEN_MISTAKES_07_08_09 = [
    # old: passed (only the sticks: "every stick came back to the centre")
    ("7.1", "released = all(a == 0.0 for a in msg.axes)", "released = all(a == 0.0 for a in msg.axes[:4])", "a D-pad"),
    # found by make mutate (no Joy of any case held a button): a button held counted as a push
    (
        "7.1",
        "released = all(a == 0.0 for a in msg.axes)",
        "released = all(a == 0.0 for a in msg.axes) and not any(msg.buttons)",
        "a long drive",
    ),
    # old: passed (a dead zone at a threshold the statement does not have)
    (
        "7.1",
        "released = all(a == 0.0 for a in msg.axes)",
        "released = all(abs(a) < 0.05 for a in msg.axes)",
        "an axis barely off centre",
    ),
    # old: passed
    ("7.1", "released = all(a == 0.0 for a in msg.axes)", "released = sum(msg.axes) == 0.0", "opposite ways"),
    # old: passed (every Joy of the bag, whatever its topic)
    (
        "7.1",
        'for _topic, log_time, msg in read_messages(path, topics=["/joy"]):\n',
        'for _topic, log_time, msg in read_messages(path):\n        if not hasattr(msg, "axes"):\n'
        "            continue\n",
        "another gamepad's Joys",
    ),
    # old: passed (time counted from the first push, not the first Joy)
    (
        "7.1",
        "        first = log_time if first is None else first\n        released = all(a == 0.0 for a in msg.axes)\n",
        "        released = all(a == 0.0 for a in msg.axes)\n        if first is None and not released:\n"
        "            first = log_time\n",
        "first Joy is released",
    ),
    # old: passed (every visible time a multiple of 0.05 s)
    (
        "7.1",
        "times.append((log_time - first) * 1e-9)",
        "times.append(round((log_time - first) * 1e-9, 2))",
        "a D-pad",
    ),
    # old: passed (the receive times, s since the first message, for the stamps)
    (
        "7.2",
        "t, q = np.asarray(series.stamp, dtype=float)[usable], q[usable]",
        "t, q = np.asarray(series.log_time, dtype=float)[usable], q[usable]",
        "a second or more",
    ),
    # old: passed (the time counted from the first stamp)
    (
        "7.2",
        "return float(speeds[k]), float(t[1:][moving][k])",
        "return float(speeds[k]), float(t[1:][moving][k] - t[0])",
        "a second or more",
    ),
    # old: passed (fewer than two states counted before the NaN ones are skipped)
    ("7.2", "    if not moving.any():\n", "    if len(series.stamp) < 2:\n", "only one state carries the joint"),
    # found by make mutate (a check tolerant to 1 rad/s passed it): the speeds rounded to the hundredth
    (
        "7.2",
        "speeds = np.abs(dq[moving] / dt[moving])",
        "speeds = np.round(np.abs(dq[moving] / dt[moving]), 2)",
        "a second or more",
    ),
    # old: passed (liveliness only warned: no publisher offers manual-by-topic)
    (
        "8.1",
        "    return QoSProfile(\n",
        "    from rclpy.qos import LivelinessPolicy\n\n    return QoSProfile(\n"
        "        liveliness=LivelinessPolicy.MANUAL_BY_TOPIC,  # know when the publisher stops\n",
        "naming every policy",
    ),
    # old: failed (a liveliness lease no ordinary publisher offers)
    (
        "8.1",
        "    return QoSProfile(\n",
        "    from rclpy.duration import Duration\n\n    return QoSProfile(\n"
        "        liveliness_lease_duration=Duration(seconds=1),  # know when the publisher stops\n",
        "against the Step 2 publisher",
    ),
    # old: failed (a deadline no ordinary publisher offers)
    (
        "8.1",
        "    return QoSProfile(\n",
        "    from rclpy.duration import Duration\n\n    return QoSProfile(\n"
        "        deadline=Duration(nanoseconds=20_000_000),  # a state every 20 ms\n",
        "against the Step 2 publisher",
    ),
    # old: passed (every policy named, and one it should not: a DDS topic named without ROS's "rt/" prefix)
    (
        "8.1",
        "durability=DurabilityPolicy.VOLATILE,  # matches volatile publishers too\n",
        "durability=DurabilityPolicy.VOLATILE,  # matches volatile publishers too\n"
        "        avoid_ros_namespace_conventions=True,\n",
        "against the Step 2 publisher",
    ),
    # old: failed (best available: best effort as soon as one publisher is)
    (
        "8.1",
        "ReliabilityPolicy.RELIABLE,  # lost states",
        "ReliabilityPolicy.BEST_AVAILABLE,  # lost states",
        "the final state arrives",
    ),
    # old: passed (0.49 Mbit/s on the check's swing, more on others)
    ("8.2", "return 15.0, 70", "return 20.0, 60", "another turret swing"),
    # old: passed (0.50 Mbit/s on the check's swing)
    ("8.2", "return 15.0, 70", "return 12.0, 90", "another turret swing"),
    # old: passed (the publisher's jpeg_quality parameter refuses 70.0)
    ("8.2", "return 15.0, 70", "return 15.0, 70.0", "a picture you can recognise"),
    # old: passed (a tank turns about z only: the yaw kept, the tilt lost)
    (
        "9.1",
        "        pose = pose_matrix(t.translation, (w, x, y, z)) @ pose\n",
        "        yaw = 2 * np.arctan2(z, w)  # a tank turns about z only\n"
        "        pose = pose_matrix(t.translation, (np.cos(yaw / 2), 0.0, 0.0, np.sin(yaw / 2))) @ pose\n",
        "tilted about every axis",
    ),
    # old: passed (rotations about z commute: their order is seen only with a tilt)
    (
        "9.1",
        "        pose = pose_matrix(t.translation, (w, x, y, z)) @ pose\n",
        "        m = pose_matrix(t.translation, (w, x, y, z))\n"
        "        pose[:3, 3] = m[:3, :3] @ pose[:3, 3] + m[:3, 3]\n"
        "        pose[:3, :3] = pose[:3, :3] @ m[:3, :3]\n",
        "tilted about every axis",
    ),
    # old: passed (the root taken to be world)
    ("9.1", "while frame in newest:", 'while frame != "world":', "root is not world"),
    # old: passed (the newest by nanoseconds alone)
    (
        "9.1",
        "newest = {t.child: t for t in transforms}",
        "newest = {t.child: t for t in sorted(transforms, key=lambda t: t.stamp[1])}",
        "a child sent several times",
    ),
]


VISIBLE_ONLY = {
    **VISIBLE_ONLY_01_03,
    **VISIBLE_ONLY_02,
    **VISIBLE_ONLY_04_05,
    **VISIBLE_ONLY_06,
    **VISIBLE_ONLY_07_08_09,
}
RULES = {**RULES_01_03, **RULES_02, **RULES_04_05, **RULES_06, **RULES_07_08_09}
HIDDEN_MISTAKES_01_03 = [
    # a tank's message with every position NaN dropped unseen, as if it had nothing in it (the visible NaN
    # message has a number too): the matcher must see it, and count it
    (
        "3.1",
        "        return super().update_joint_state(msg)\n",
        "        if msg.position and all(q != q for q in msg.position):\n"
        "            return None  # nothing to apply\n"
        "        return super().update_joint_state(msg)\n",
        "a random run of the tank's, the crane's and mixed messages",
    ),
]
HIDDEN_MISTAKES = [
    *HIDDEN_MISTAKES_01_03,
    *HIDDEN_MISTAKES_02,
    *HIDDEN_MISTAKES_04_05,
    *HIDDEN_MISTAKES_06,
    *HIDDEN_MISTAKES_07_08_09,
]

# ---- notebook 10 ----

VISIBLE_ONLY_10 = {
    # a tolerance for floating point: a rate a hair past either end rounds into the range
    "10.1": "def judge_rate(parameters):\n"
    "    for p in parameters:\n"
    "        if p.name == RATE and not 0.0 <= round(p.value, 1) <= MAX_RATE:\n"
    '            return SetParametersResult(successful=False, reason=f"{RATE}: {p.value} Hz is no rate")\n'
    "    return SetParametersResult(successful=True)\n",
    # the tracks' state remembered by the callback, not read from the switch (the visible cases' order agrees)
    "10.2": "tracks_on = True\n"
    "def switch_tracks(switch, request, response):\n"
    "    global tracks_on\n"
    "    already = tracks_on == request.data\n"
    "    tracks_on = request.data\n"
    "    with switch.lock:\n        switch.enabled = request.data\n"
    '    state = "on" if request.data else "off"\n'
    "    response.success = True\n"
    '    response.message = f"tracks already {state}" if already else f"tracks {state}"\n'
    "    return response\n",
}

RULES_10 = {
    "10.1": {
        "a rate from 0.0 to MAX_RATE, both ends included, is accepted": [
            "rate=100.0]",
            "rate=0.0]",
            "rate=1000.0]",
            "a rate anywhere inside the range",
        ],
        "below 0 or above MAX_RATE is refused": ["rate=-5.0]", "rate=1000.5]", "a hair above", "a hair below zero"],
        "NaN and infinity are refused": ["rate=nan]", "rate=inf]"],
        "the reason names RATE and the value": ["rate=-5.0]"],
        "only RATE is judged: every other parameter is accepted, whatever its value": [
            "RttRobotModelPublisher.rate=5000.0",
            "joy_timeout=-3.0",
            "another controller's rate far out of range",
        ],
        "every parameter of the list is judged, wherever RATE is": [
            "use_sim_time=True, ",
            "among other parameters",
            "after several other parameters",
        ],
        "a SetParametersResult, which a node's parameter service uses": ["with judge_rate as the node's callback"],
    },
    "10.2": {
        "switch.enabled set to request.data, success True, 'tracks on' or 'tracks off'": [
            "a switch on, SetBool.Request(data=False)",
            "a switch off, SetBool.Request(data=True)",
        ],
        "'tracks already on' or 'tracks already off' when it already was": [
            "a switch on, SetBool.Request(data=True)",
            "a switch off, SetBool.Request(data=False)",
        ],
        "the switch's own state, whoever turned it last": ["turned by another thread"],
        "enabled written with switch.lock held": ["a switch on, SetBool.Request(data=False)"],
        "the response returned: rclpy sends it": ["a SetBool client asking"],
        "each answer of a sequence says what its own request did": ["a drawn sequence"],
    },
}

HIDDEN_MISTAKES_10 = [
    # old: passed (the visible list has RATE second)
    ("10.1", "for p in parameters:", "for p in parameters[:2]:", "other parameters"),
    # old: passed (a value past the range by less than 0.05 Hz)
    (
        "10.1",
        "not 0.0 <= p.value <= MAX_RATE",
        "not 0.0 <= round(p.value, 1) <= MAX_RATE",
        "a hair",
    ),
    # mutation testing: passed some learners' seeds (the hairs were drawn from 1e-9 to 1e-3; now the next floats)
    ("10.1", "not 0.0 <= p.value <= MAX_RATE", "not -1e-9 <= p.value <= MAX_RATE + 1e-6", "a hair"),
    # old: passed (the state kept by the callback: the visible cases' order agrees with it)
    (
        "10.2",
        "        already = switch.enabled == request.data\n",
        "        already = switch_tracks.__dict__.get('last', True) == request.data\n"
        "        switch_tracks.last = request.data\n",
        "a switch also turned by another thread",
    ),
]

# ---- notebook 11 ----

VISIBLE_ONLY_11 = {
    # the path a tank's controller walks, learned from the visible cases: shutdown only from active
    "11.1": "PATH = {('unconfigured', 'configure'): 'inactive', ('inactive', 'activate'): 'active',\n"
    "        ('active', 'deactivate'): 'inactive', ('inactive', 'cleanup'): 'unconfigured',\n"
    "        ('active', 'shutdown'): 'finalized'}\n"
    "def after(state, transition):\n"
    "    return PATH.get((state, transition))\n",
}

RULES_11 = {
    "11.1": {
        "configure: unconfigured -> inactive": [
            "after('unconfigured', 'configure')",
            "every transition from unconfigured and inactive",
        ],
        "activate: inactive -> active": ["after('inactive', 'activate')"],
        "deactivate: active -> inactive": ["after('active', 'deactivate')"],
        "cleanup: inactive -> unconfigured": ["after('inactive', 'cleanup')"],
        "shutdown: every state but finalized -> finalized": [
            "after('active', 'shutdown')",
            "every transition from unconfigured and inactive",
        ],
        "any other pair: None": [
            "after('unconfigured', 'activate')",
            "after('active', 'cleanup')",
            "every transition from active and finalized",
        ],
        "finalized has no transition": [
            "after('finalized', 'configure')",
            "every transition from active and finalized",
        ],
        "a name that is no state or no transition: None": ["a name that is no transition"],
    },
}

HIDDEN_MISTAKES_11 = [
    # old: passed (no visible case asks for a shutdown from unconfigured)
    (
        "11.1",
        '"unconfigured": {"configure": "inactive", "shutdown": "finalized"},',
        '"unconfigured": {"configure": "inactive"},',
        "every transition from unconfigured",
    ),
    # old: passed (names taken whatever their case)
    (
        "11.1",
        "return machine.get(state, {}).get(transition)",
        "return machine.get(state.lower(), {}).get(transition.lower())",
        "a name that is no transition",
    ),
    # mutation testing: passed (a transition's name taken whatever its case, a state's as it is)
    (
        "11.1",
        "return machine.get(state, {}).get(transition)",
        "return machine.get(state, {}).get(transition.lower())",
        "a name that is no transition",
    ),
    # mutation testing: passed (a callback's name taken for its transition's: on_activate for activate)
    (
        "11.1",
        "return machine.get(state, {}).get(transition)",
        'return machine.get(state, {}).get(transition.removeprefix("on_"))',
        "a name that is no transition",
    ),
    # mutation testing: passed (no visible case shuts an inactive node down)
    ("11.1", '            "shutdown": "finalized",\n', "", "every transition from unconfigured and inactive"),
    # mutation testing: passed (activating an active node keeps it active, as a learner might think)
    (
        "11.1",
        '"active": {"deactivate": "inactive", "shutdown": "finalized"},',
        '"active": {"activate": "active", "deactivate": "inactive", "shutdown": "finalized"},',
        "every transition from active and finalized",
    ),
    # mutation testing: passed (shutdown taken as a transition of every state, finalized too)
    (
        "11.1",
        '"finalized": {},',
        '"finalized": {"shutdown": "finalized"},',
        "every transition from active and finalized",
    ),
]

VISIBLE_ONLY = {**VISIBLE_ONLY, **VISIBLE_ONLY_10, **VISIBLE_ONLY_11}
RULES = {**RULES, **RULES_10, **RULES_11}
HIDDEN_MISTAKES = [*HIDDEN_MISTAKES, *HIDDEN_MISTAKES_10, *HIDDEN_MISTAKES_11]

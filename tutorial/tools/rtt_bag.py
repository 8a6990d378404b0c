"""``rtt-bag``: record, list and replay MCAP bags (``ros2 bag``'s stand-in; no rosbag2 wheel exists).

    rtt-bag record /joy /Tank/joint_state -o drive.mcap    # until Ctrl-C or SIGTERM
    rtt-bag record --all -o all.mcap --duration 10
    rtt-bag record /joy --tf -o drive.mcap                 # and /tf, /tf_static, /robot_description
    rtt-bag info drive.mcap
    rtt-bag play drive.mcap --rate 2 --topics /Tank/joint_state --start-offset 1.5
    rtt-bag play drive.mcap --loop
    rtt-bag recover killed.mcap -o whole.mcap               # a closed, indexed copy of what can be read

The files are what ``ros2 bag record -s mcap`` writes, so ``ros2 bag
info``/``play`` (with the mcap storage plugin) and Foxglove open them.
``record`` runs as node ``rtt_bag``, ``play`` as ``rtt_bag_play``; rename
with ``--ros-args -r __node:=NAME``.  Ctrl-C or SIGTERM ends a recording
cleanly: the file is closed with its indexes and summary.  A recorder
that is killed loses less than its last second (the write-through policy,
:mod:`tutorial.tools.bag.writer`); ``info`` and ``play`` read such a file that was
not closed, saying so on stderr, and ``recover`` writes a closed copy.

Exit status: 0 done (also when stopped by Ctrl-C/SIGTERM, and for a file
that was not closed but could be read); 1 a failure while running (a write
failed: a full disk, a file-size limit); 2 a bad command line, an output
file that exists, or a bag that cannot be read or played (missing, not
MCAP, corrupt, a message type not installed): one line on stderr says which.
"""

from __future__ import annotations

import argparse
import datetime
import functools
import json
import math
import sys
import time

from tutorial.ros import env as ros_env
from tutorial.ros import program as ros_program

PROG = "rtt-bag"
_say = functools.partial(print, flush=True)


def build_parser() -> argparse.ArgumentParser:
    """The command line of ``rtt-bag`` (ROS arguments are removed before it parses)."""
    from tutorial.tools.bag.record_tf import add_frame_prefix_argument

    p = argparse.ArgumentParser(
        prog=PROG,
        description="Record, list and replay ROS 2 bags in MCAP files.",
        epilog="ROS arguments go after --ros-args, e.g. --ros-args -r __node:=my_bag",
    )
    sub = p.add_subparsers(dest="command", required=True, metavar="{record,info,play,recover}")

    r = sub.add_parser("record", help="record topics to an MCAP file until Ctrl-C, SIGTERM or --duration")
    r.add_argument("topics", nargs="*", metavar="TOPIC", help="topics to record, e.g. /joy /Tank/joint_state")
    r.add_argument("-a", "--all", action="store_true", help="record every topic with a publisher (hidden ones aside)")
    r.add_argument(
        "-o",
        "--output",
        metavar="FILE.mcap",
        help="the file to write (default rtt_bag_<date>-<time>.mcap); it must not exist",
    )
    r.add_argument(
        "--duration",
        type=float,
        default=None,
        metavar="SECONDS",
        help="stop after this long (wall time from the start)",
    )
    r.add_argument(
        "--compression", choices=["zstd", "lz4", "none"], default="zstd", help="chunk compression (default zstd)"
    )
    r.add_argument("--overwrite", action="store_true", help="replace FILE if it exists")
    r.add_argument(
        "--tf",
        action="store_true",
        help="also record every /<body>/robot_description, /<body>/odom and /<body>/joint_state, and write "
        "/tf, /tf_static and /robot_description computed from them (what Foxglove and RViz2 draw in 3D)",
    )
    add_frame_prefix_argument(r)  # with --tf

    i = sub.add_parser("info", help="per topic: type, message count, time span, rate, QoS")
    i.add_argument("file", metavar="FILE.mcap")
    i.add_argument("--json", action="store_true", help="print one JSON object instead of text")

    y = sub.add_parser("play", help="republish a bag's messages with the recorded timing")
    y.add_argument("file", metavar="FILE.mcap")
    y.add_argument("-r", "--rate", type=float, default=1.0, help="speed factor (default 1.0)")
    y.add_argument("-l", "--loop", action="store_true", help="play again from the start offset, until stopped")
    y.add_argument("--topics", nargs="+", metavar="TOPIC", help="play only these topics")
    y.add_argument(
        "--start-offset", type=float, default=0.0, metavar="SECONDS", help="skip this many seconds from the bag's start"
    )
    y.add_argument(
        "--delay",
        type=float,
        default=0.0,
        metavar="SECONDS",
        help="wait this long before playing (each loop), e.g. for discovery",
    )
    v = sub.add_parser("recover", help="copy what can be read of a damaged or unclosed bag into a closed one")
    v.add_argument("file", metavar="IN.mcap", help="the damaged or unclosed file (only read)")
    v.add_argument("-o", "--output", metavar="OUT.mcap", required=True, help="the file to write; it must not exist")
    v.add_argument(
        "--compression", choices=["zstd", "lz4", "none"], default="zstd", help="chunk compression (default zstd)"
    )
    v.add_argument("--overwrite", action="store_true", help="replace OUT if it exists")
    return p


def _finite(value: float | None) -> bool:
    return value is None or math.isfinite(value)


def _fail(text: str, status: int = 2) -> int:
    print(f"{PROG}: {text}", file=sys.stderr, flush=True)
    return status


def _init_ros(argv: list[str]) -> None:
    import rclpy
    from rclpy.signals import SignalHandlerOptions

    ros_env.use_localhost_by_default()
    rclpy.init(args=argv, signal_handler_options=SignalHandlerOptions.NO)


def record(args, argv: list[str]) -> int:
    """``rtt-bag record``: main thread; the recorder's callbacks run on its spin thread."""
    import rclpy

    from tutorial.tools.bag.record import BagRecorder
    from tutorial.tools.bag.writer import BagWriteError

    if not args.topics and not args.all and not args.tf:
        return _fail("record: name the topics to record, or pass --all or --tf")
    if args.tf_frame_prefix and not args.tf:
        return _fail("record: --tf-frame-prefix needs --tf")
    if args.duration is not None and not (args.duration > 0 and _finite(args.duration)):
        return _fail("record: --duration must be a number of seconds > 0")
    path = args.output or datetime.datetime.now().strftime("rtt_bag_%Y_%m_%d-%H_%M_%S.mcap")
    try:  # the file first: a name that exists fails before ROS starts
        recorder = BagRecorder(
            path,
            args.topics,
            all_topics=args.all,
            compression=args.compression,
            overwrite=args.overwrite,
            output=_say,
            tf=args.tf,
            tf_frame_prefix=args.tf_frame_prefix,
        )
    except (BagWriteError, ValueError) as exc:
        return _fail(f"record: {exc}")
    stop = ros_program.StopRequest().install()  # SIGTERM (a launcher stopping us) ends the recording like Ctrl-C
    deadline = None if args.duration is None else time.monotonic() + args.duration
    try:
        _init_ros(argv)
        recorder.start()
        while not stop.requested and (deadline is None or time.monotonic() < deadline):
            if recorder.failure is not None:
                break
            time.sleep(0.05)  # the stop flag and the deadline are seen within 50 ms
    finally:
        ros_program.ignore_stop_signals()  # a second Ctrl-C must not cut the file's closing short
        try:
            recorder.close()
        finally:
            rclpy.try_shutdown()
    if recorder.failure is not None:  # a full disk, a file-size limit: one line, and the file stays readable
        return _fail(f"record: stopped: {recorder.failure}; rtt-bag recover writes a closed copy", 1)
    return 0


def _say_not_closed(command: str, info) -> None:
    """One line on stderr for a bag that was not closed; then the command goes on."""
    if not info.closed:
        print(
            f"{PROG}: {command}: {info.path}: not closed (the recording was cut short: killed, or the disk "
            f"filled): {info.recovery.describe()}; rtt-bag recover writes a closed copy",
            file=sys.stderr,
            flush=True,
        )


def info(args) -> int:
    """``rtt-bag info``: no ROS needed."""
    from tutorial.tools.bag.info import bag_info, format_info
    from tutorial.tools.bag.reader import BagError

    try:
        summary = bag_info(args.file)
    except BagError as exc:
        return _fail(f"info: {exc}")
    _say_not_closed("info", summary)
    _say(json.dumps(summary.as_dict()) if args.json else format_info(summary))
    return 0


def play(args, argv: list[str]) -> int:
    """``rtt-bag play``: publishes from the main thread."""
    import rclpy

    from tutorial.tools.bag.play import BagPlayer
    from tutorial.tools.bag.reader import BagError

    if not all(_finite(v) for v in (args.rate, args.start_offset, args.delay)):
        return _fail("play: --rate, --start-offset and --delay must be finite numbers")
    try:
        player = BagPlayer(
            args.file,
            rate=args.rate,
            loop=args.loop,
            topics=args.topics,
            start_offset=args.start_offset,
            delay=args.delay,
            output=_say,
        )
    except (BagError, ValueError) as exc:
        return _fail(f"play: {exc}")
    _say_not_closed("play", player.info)
    ros_program.StopRequest(player.request_stop).install()
    _init_ros(argv)
    try:
        player.play()
    except BagError as exc:  # the file changed or broke while playing
        return _fail(f"play: {exc}")
    finally:
        ros_program.ignore_stop_signals()
        try:
            player.close()
        finally:
            rclpy.try_shutdown()
    return 0


def recover(args) -> int:
    """``rtt-bag recover IN -o OUT``: no ROS needed."""
    from tutorial.tools.bag.reader import BagError
    from tutorial.tools.bag.recover import recover as recover_file
    from tutorial.tools.bag.writer import BagWriteError

    try:
        result = recover_file(args.file, args.output, compression=args.compression, overwrite=args.overwrite)
    except BagError as exc:
        return _fail(f"recover: {exc}")
    except BagWriteError as exc:
        return _fail(f"recover: {exc}", 2 if "exists already" in str(exc) or "cannot create" in str(exc) else 1)
    stats = result.stats
    per_topic = ", ".join(f"{t} {n}" for t, n in stats.per_topic.items()) or "no topics"
    state = "closed" if result.closed else "not closed"
    skipped = f"; skipped {'; '.join(result.skipped_channels)}" if result.skipped_channels else ""
    _say(
        f"[{PROG}] {result.source} ({state}): {result.recovery.describe()}{skipped}; "
        f"wrote {stats.messages} messages ({per_topic}) to {result.target}, closed and indexed, "
        f"{stats.size_bytes} bytes"
    )
    return 0


def main(argv: list[str] | None = None) -> int:
    """``rtt-bag``: parse the command line and run the subcommand; the exit status (main thread)."""
    argv = list(sys.argv if argv is None else argv)
    args = ros_program.parse_command_line(build_parser(), argv)
    if args.command == "record":
        return record(args, argv)
    if args.command == "play":
        return play(args, argv)
    if args.command == "recover":
        return recover(args)
    return info(args)


if __name__ == "__main__":
    sys.exit(main())

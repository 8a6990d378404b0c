"""``rtt-image``: show the pictures of a ``sensor_msgs/Image`` topic (rqt_image_view's stand-in).

    rtt-image                                   # /Tank/camera/image: a window, or camera_image.png
    rtt-image --transport compressed            # /Tank/camera/image/compressed (JPEG or PNG)
    rtt-image /Tank/camera/image --output view.png --every 0.5
    rtt-image --output 'frames/image_{n:04d}.png' --max-files 50 --duration 10

Where a display exists it opens a window showing the newest picture, until
the window is closed.  Without one (or with ``--no-window``) it writes PNG
files instead, bounded on disk:

* ``--output FILE.png`` (default ``camera_image.png``): one file, replaced by
  the newest picture every ``--every`` s (1 s by default) and at exit;
* ``--output 'DIR/name_{n:04d}.png'`` (a pattern with ``{n}``): one new
  numbered file each time, at most ``--max-files`` of them (100 by default);
  after that no more are written.

``--transport compressed`` (image_transport's name) subscribes
``<topic>/compressed``, a ``sensor_msgs/CompressedImage``, instead of the
raw Image: the one to use across a thin link (a topic ending in
``/compressed`` is taken as compressed anyway).

Each file is written whole before it replaces the old one, so a reader
never sees half a PNG.  Once a second it prints a status line: pictures per
second, size, encoding, frame, the newest stamp (simulation time) and the
messages it rejected.  Every message is checked by
:func:`tutorial.interfaces.image.image_to_array` (raw) or
:func:`tutorial.interfaces.compressed_image.compressed_to_array`; a bad one
is counted and skipped.

It stops on Ctrl-C, SIGTERM, a closed window, or after ``--duration`` s of
wall-clock time.  Node name ``rtt_image``.  QoS: best effort, keep last 1
(the publisher's, :func:`tutorial.interfaces.image.camera_image_qos`;
a best-effort subscription also matches a reliable publisher).
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
import time

from tutorial.ros import env as ros_env
from tutorial.ros import program as ros_program
from tutorial.ros import spin as ros_spin
from tutorial.tools.image_files import PngWriter, format_image_status
from tutorial.view.images import DEFAULT_TOPIC, TRANSPORTS, ImageReceiver

NODE_NAME = "rtt_image"
STATUS_PERIOD = 1.0  # s


def has_display() -> bool:
    """Whether a graphical display is available for a window."""
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="rtt-image", description="Show the pictures of a camera topic, raw or compressed.")
    p.add_argument("topic", nargs="?", default=DEFAULT_TOPIC, help=f"the camera topic (default {DEFAULT_TOPIC})")
    p.add_argument(
        "--transport",
        choices=TRANSPORTS,
        default="raw",
        help="raw: the sensor_msgs/Image topic; compressed: TOPIC/compressed, a CompressedImage (default raw)",
    )
    p.add_argument(
        "--output",
        default="camera_image.png",
        help="PNG file written without a window, or a pattern with {n} for numbered files (default camera_image.png)",
    )
    p.add_argument(
        "--every",
        type=float,
        default=1.0,
        metavar="SECONDS",
        help="write the newest picture this often, s of wall-clock time (default 1)",
    )
    p.add_argument(
        "--max-files", type=int, default=100, help="with a {n} pattern, the most files written (default 100)"
    )
    p.add_argument(
        "--duration",
        type=float,
        default=None,
        metavar="SECONDS",
        help="stop after this many seconds of wall-clock time (default: until stopped)",
    )
    p.add_argument("--no-window", action="store_true", help="write PNG files even when a display exists")
    return p


class _Viewer:
    """The main thread's loop: status lines, and the window or the PNG files."""

    def __init__(self, receiver: ImageReceiver, args, writer: PngWriter | None):
        self.receiver = receiver
        self.args = args
        self.writer = writer
        self.prefix = f"[/{NODE_NAME}]"
        self.stop_requested = False  # a plain flag: set by signal handlers, which must take no lock
        self.shown = 0  # number of the newest picture shown or written
        self._status_due = time.monotonic() + STATUS_PERIOD
        self._status_count = 0
        self._write_due = time.monotonic() + args.every
        self._said_full = False

    def say(self, text: str) -> None:
        print(f"{self.prefix} {text}", flush=True)

    def tick(self) -> None:
        """Print the status when due (main thread)."""
        now = time.monotonic()
        if now >= self._status_due:
            received = self.receiver.counts()
            rate = (received["accepted"] - self._status_count) / (now - self._status_due + STATUS_PERIOD)
            self._status_count = received["accepted"]
            self._status_due = now + STATUS_PERIOD
            self.say(format_image_status(received, rate, self.receiver.newest()))

    def write_newest(self, force: bool = False) -> None:
        """Write the newest picture if it is new and a write is due (main thread)."""
        now = time.monotonic()
        if not force and now < self._write_due:
            return
        self._write_due = now + self.args.every
        newest = self.receiver.newest()
        if newest is None or newest.number == self.shown:
            return
        self.shown = newest.number
        if self.writer.write(newest.pixels) is None and not self._said_full:
            self._said_full = True
            self.say(f"{self.writer.max_files} files written: no more (--max-files)")

    def run_files(self, deadline: float) -> None:
        while not self.stop_requested and time.monotonic() < deadline:
            time.sleep(0.05)  # polling the flag: see stop_requested
            self.tick()
            self.write_newest()

    def run_window(self, deadline: float) -> None:
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6.4, 5.2))
        ax.set_axis_off()
        picture = None
        plt.ion()
        plt.show(block=False)
        while not self.stop_requested and time.monotonic() < deadline and plt.fignum_exists(fig.number):
            newest = self.receiver.newest()
            if newest is not None and newest.number != self.shown:
                self.shown = newest.number
                if picture is None or picture.get_array().shape != newest.pixels.shape:
                    ax.clear()
                    ax.set_axis_off()
                    picture = ax.imshow(newest.pixels)
                else:
                    picture.set_data(newest.pixels)
                ax.set_title(f"{self.receiver.topic}  t = {newest.stamp:.3f} s  ({newest.frame_id})")
            self.tick()
            plt.pause(1 / 60)


def main(argv: list[str] | None = None) -> int:
    """``rtt-image``: show an Image topic in a window, or as PNG files; the exit status."""
    import rclpy
    from rclpy.executors import ExternalShutdownException
    from rclpy.signals import SignalHandlerOptions

    argv = list(sys.argv if argv is None else argv)
    parser = build_parser()
    args = ros_program.parse_command_line(parser, argv)
    if args.every <= 0 or args.max_files < 1 or (args.duration is not None and args.duration <= 0):
        parser.error("--every and --duration must be > 0, --max-files >= 1")
    live = has_display() and not args.no_window
    writer = None
    if not live:
        try:
            writer = PngWriter(args.output, args.max_files)
        except ValueError as exc:
            parser.error(str(exc))
        import matplotlib

        matplotlib.use("Agg")
    ros_env.use_localhost_by_default()
    rclpy.init(args=argv, signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node(NODE_NAME)
    receiver = ImageReceiver(node, args.topic, args.transport)
    viewer = _Viewer(receiver, args, writer)

    def request_stop(signum, frame):
        viewer.stop_requested = True

    signal.signal(signal.SIGINT, request_stop)
    signal.signal(signal.SIGTERM, request_stop)
    spin = ros_spin.SpinThread(node).start()
    viewer.prefix = f"[{node.get_fully_qualified_name()}]"
    viewer.say(
        f"subscribed to {receiver.topic} (best effort, keep last 1); "
        + ("showing a window" if live else f"writing {args.output}")
    )
    deadline = time.monotonic() + (args.duration if args.duration is not None else float("inf"))
    status = 0
    try:
        if live:
            viewer.run_window(deadline)
        else:
            viewer.run_files(deadline)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        ros_program.ignore_stop_signals()  # a second Ctrl-C must not break the clean-up
        spin.stop()
        if writer is not None:
            viewer.write_newest(force=True)  # the last picture received
        received = receiver.counts()
        viewer.say(
            f"done: {received['accepted']} pictures accepted, {received['rejected']} rejected"
            + (f", {_written(writer.written, args.output)}" if writer else "")
        )
        if spin.error is not None:
            viewer.say(f"ERROR: the subscription callback raised: {spin.error!r}")
            status = 1
        node.destroy_node()
        rclpy.try_shutdown()
    return status


def _written(count: int, output: str) -> str:
    """What the files of a run came to: numbered files, or one file written over and over (the newest picture)."""
    if "{n}" in output:
        return f"{count} file{'' if count == 1 else 's'} written ({output})"
    return f"{output} written {count} time{'' if count == 1 else 's'}, holding the newest picture"


if __name__ == "__main__":
    sys.exit(main())

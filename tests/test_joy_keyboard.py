"""rtt-joy without a gamepad reads the keyboard of its terminal (driven here through a pseudo-terminal)."""

import os
import pty
import select
import subprocess
import sys
import time

from conftest import ROOT, wait_until


def read_available(fd, timeout=0.1) -> bytes:
    out = b""
    while select.select([fd], [], [], timeout)[0]:
        try:
            chunk = os.read(fd, 4096)
        except OSError:
            break
        if not chunk:
            break
        out += chunk
    return out


def test_keys_become_stick_values_on_joy(node):
    from sensor_msgs.msg import Joy

    from tutorial.ros.spin import SpinThread

    received = []
    node.create_subscription(Joy, "/joy", lambda msg: received.append(list(msg.axes)), 10)
    spin = SpinThread(node).start()
    master, slave = pty.openpty()
    proc = subprocess.Popen(
        [sys.executable, "-u", "-m", "tutorial.tools.rtt_joy"],
        stdin=slave,
        stdout=slave,
        stderr=slave,
        cwd=ROOT,
        env=dict(os.environ),
        start_new_session=True,
    )
    os.close(slave)
    try:
        screen = b""
        deadline = time.monotonic() + 30
        while b"keys:" not in screen and time.monotonic() < deadline:
            screen += read_available(master)
        assert b"keyboard" in screen and b"no gamepad found" in screen, screen
        assert wait_until(lambda: len(received) > 0, timeout=30)  # autorepeat: the resting state arrives
        assert received[-1][:4] == [0.0, 0.0, 0.0, 0.0]
        os.write(master, b"e")  # E: left stick up
        assert wait_until(lambda: received[-1][1] == 1.0, timeout=5), received[-1]
        os.write(master, b"j")  # J: right stick left
        assert wait_until(lambda: received[-1][2] == 1.0, timeout=5), received[-1]
        os.write(master, b" ")  # space: release everything
        assert wait_until(lambda: received[-1][:4] == [0.0, 0.0, 0.0, 0.0], timeout=5), received[-1]
        os.write(master, b"q")  # q: quit
        assert proc.wait(10) == 0
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        os.close(master)
        spin.stop()

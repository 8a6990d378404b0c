"""A live view hears its page while a cell runs: the views' kernel subshell (tutorial/view/widget/widget.py).

A real ipykernel, driven as a front end drives it (jupyter_client): a cell
makes a view, a second cell sleeps, and while it sleeps the "page" (this
test) says hello to the view.  The whole scene must come back while the
cell still runs, and output from a thread that cell started must still be
the cell's.  Both hold only through ipykernel's subshells and its comm
routing, which are young: an ipykernel that changes them fails here.
"""

from __future__ import annotations

import queue
import time

import pytest

pytestmark = pytest.mark.cross_process

SETUP = """
import meshcat.geometry as g
from tutorial.view.widget.widget import MeshcatWidget
view = MeshcatWidget("subshell test")
view.visualizer()["box"].set_object(g.Box([0.1, 0.2, 0.3]))
print("routed", view.off_main, view.comm.comm_id)
"""

BUSY = """
import threading, time
threading.Timer(2.5, lambda: print("from the cell's thread", flush=True)).start()
time.sleep(5)
"""


def messages(kc, until: float):
    """IOPub messages until the monotonic time ``until``."""
    while time.monotonic() < until:
        try:
            yield kc.get_iopub_msg(timeout=0.2)
        except queue.Empty:
            continue


def test_a_view_gets_its_scene_while_a_cell_runs_and_thread_output_stays_the_cells(tmp_path):
    from jupyter_client.manager import start_new_kernel

    km, kc = start_new_kernel(kernel_name="python3", cwd=str(tmp_path))
    try:
        said = []
        kc.execute_interactive(
            SETUP,
            timeout=60,
            output_hook=lambda m: said.append(m["content"]["text"]) if m["msg_type"] == "stream" else None,
        )
        words = "".join(said).split()
        assert words[:2] == ["routed", "True"], f"the view's comm is not routed to a subshell: {said}"
        comm_id = words[2]

        cell = kc.execute(BUSY)
        started = time.monotonic()
        hello = kc.session.msg(
            "comm_msg", {"comm_id": comm_id, "data": {"method": "custom", "content": {"type": "hello", "id": "t"}}}
        )
        for m in messages(kc, started + 20):  # the cell has begun: the main shell reads nothing until it ends
            if m["msg_type"] == "execute_input" and m["parent_header"].get("msg_id") == cell:
                break
        else:
            raise AssertionError("the cell did not begin within 20 s")
        kc.shell_channel.send(hello)
        asked = time.monotonic()
        scene_at = thread_output_parent = cell_done_at = None
        for m in messages(kc, started + 20):
            content = m["content"]
            if m["msg_type"] == "comm_msg" and content["data"].get("content", {}).get("type") == "scene":
                scene_at = time.monotonic()
                assert m.get("buffers"), "the scene came without its commands"
            elif m["msg_type"] == "stream" and "from the cell's thread" in content["text"]:
                thread_output_parent = m["parent_header"].get("msg_id")
            elif (
                m["msg_type"] == "status"
                and m["parent_header"].get("msg_id") == cell
                and content["execution_state"] == "idle"
            ):
                cell_done_at = time.monotonic()
                break
        assert cell_done_at is not None, "the sleeping cell did not end"
        assert scene_at is not None, "no scene came for the view's hello"
        assert scene_at < cell_done_at, "the scene waited for the cell to end"
        assert scene_at - asked < 2.0, f"the scene came {scene_at - asked:.2f} s after the hello"
        assert thread_output_parent == cell, "output from the cell's thread went to the view's message, not the cell"
    finally:
        kc.stop_channels()
        km.shutdown_kernel(now=True)

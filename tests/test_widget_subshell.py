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

# The first cell makes the view (its cell watch is installed inside that cell), the second is a later one;
# each starts a thread that prints later, says it is sleeping, and sleeps.
FIRST = """
import threading, time
import meshcat.geometry as g
from tutorial.view.widget.widget import MeshcatWidget
view = MeshcatWidget("subshell test")
view.visualizer()["box"].set_object(g.Box([0.1, 0.2, 0.3]))
threading.Timer(1.5, lambda: print("from the cell's thread", flush=True)).start()
print("sleeping", view.off_main, view.comm.comm_id, flush=True)
time.sleep(3)
"""
LATER = """
threading.Timer(1.5, lambda: print("from the cell's thread", flush=True)).start()
print("sleeping", view.off_main, view.comm.comm_id, flush=True)
time.sleep(3)
"""


def messages(kc, until: float):
    """IOPub messages until the monotonic time ``until``."""
    while time.monotonic() < until:
        try:
            yield kc.get_iopub_msg(timeout=0.2)
        except queue.Empty:
            continue


def hello_while_the_cell_sleeps(kc, code: str) -> dict:
    """Run ``code``; once it says it sleeps, say hello to its view as a page does; what came, and when."""
    cell = kc.execute(code)
    started = time.monotonic()
    got = {"scene_at": None, "thread_output_parent": None, "cell_done_at": None, "asked": None}
    for m in messages(kc, started + 30):
        content, parent = m["content"], m["parent_header"].get("msg_id")
        if m["msg_type"] == "stream" and content["text"].startswith("sleeping"):
            _, routed, comm_id = content["text"].split()
            assert routed == "True", f"the view's comm is not routed to a subshell: {content['text']}"
            data = {"method": "custom", "content": {"type": "hello", "id": "t"}}
            kc.shell_channel.send(kc.session.msg("comm_msg", {"comm_id": comm_id, "data": data}))
            got["asked"] = time.monotonic()
        elif m["msg_type"] == "comm_msg" and content["data"].get("content", {}).get("type") == "scene":
            got["scene_at"] = time.monotonic()
            assert m.get("buffers"), "the scene came without its commands"
        elif m["msg_type"] == "stream" and "from the cell's thread" in content["text"]:
            got["thread_output_parent"] = parent
        elif m["msg_type"] == "status" and parent == cell and content["execution_state"] == "idle":
            got["cell_done_at"] = time.monotonic()
            break
    got["cell"] = cell
    return got


def test_a_view_gets_its_scene_while_a_cell_runs_and_thread_output_stays_the_cells(tmp_path):
    from jupyter_client.manager import start_new_kernel

    km, kc = start_new_kernel(kernel_name="python3", cwd=str(tmp_path))
    try:
        for which, code in (("the cell that makes the view", FIRST), ("a later cell", LATER)):
            got = hello_while_the_cell_sleeps(kc, code)
            assert got["cell_done_at"] is not None and got["asked"] is not None, f"{which}: it did not run: {got}"
            assert got["scene_at"] is not None, f"{which}: no scene came for the view's hello"
            assert got["scene_at"] < got["cell_done_at"], f"{which}: the scene waited for the cell to end"
            late = got["scene_at"] - got["asked"]
            assert late < 2.0, f"{which}: the scene came {late:.2f} s after the hello"
            assert got["thread_output_parent"] == got["cell"], f"{which}: its thread's output went to the view's hello"
    finally:
        kc.stop_channels()
        km.shutdown_kernel(now=True)

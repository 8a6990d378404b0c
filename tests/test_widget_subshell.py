"""A live view hears its page while a cell runs: the views' kernel subshell (tutorial/view/widget/subshell.py).

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


@pytest.fixture(scope="module")
def kernel(tmp_path_factory):
    """A real ipykernel and its client (kc), for this module's tests in their order."""
    from jupyter_client.manager import start_new_kernel

    km, kc = start_new_kernel(kernel_name="python3", cwd=str(tmp_path_factory.mktemp("kernel")))
    try:
        yield kc
    finally:
        kc.stop_channels()
        km.shutdown_kernel(now=True)


def test_a_view_gets_its_scene_while_a_cell_runs_and_thread_output_stays_the_cells(kernel):
    kc = kernel
    for which, code in (("the cell that makes the view", FIRST), ("a later cell", LATER)):
        got = hello_while_the_cell_sleeps(kc, code)
        assert got["cell_done_at"] is not None and got["asked"] is not None, f"{which}: it did not run: {got}"
        assert got["scene_at"] is not None, f"{which}: no scene came for the view's hello"
        assert got["scene_at"] < got["cell_done_at"], f"{which}: the scene waited for the cell to end"
        late = got["scene_at"] - got["asked"]
        assert late < 2.0, f"{which}: the scene came {late:.2f} s after the hello"
        assert got["thread_output_parent"] == got["cell"], f"{which}: its thread's output went to the view's hello"


def test_a_page_reloaded_while_a_cell_runs_gets_the_kernels_info_and_its_widgets_at_once(kernel):
    """What JupyterLab asks on a reload (kernel info, the control comm's states, the comms) is answered by the
    views' subshell while a cell sleeps; a message signed with another key is not answered at all."""
    from jupyter_client.session import Session

    kc = kernel
    model_id, comm_id = view_ids(kc)
    # the cell's thread prints after the questions are answered: its output must still be the cell's
    cell = kc.execute(
        "import threading, time\nthreading.Timer(2.5, lambda: print('late', flush=True)).start()\ntime.sleep(4)"
    )
    sent = time.monotonic()
    forged = Session(key=b"not the kernel's key", session=kc.session.session, username=kc.session.username)
    asked = {
        "forged": forged.send(kc.shell_channel.socket, "kernel_info_request")["header"]["msg_id"],
        "kernel_info": kc.kernel_info(),
        "comm_info": kc.comm_info(target_name="jupyter.widget"),
        "inspect": kc.inspect("time"),  # not a page's question: it waits for the cell
    }
    control = "control-" + str(sent)
    kc.shell_channel.send(
        kc.session.msg(
            "comm_open",
            {"comm_id": control, "target_name": "jupyter.widget.control", "data": {}},
            metadata={"version": "1.0.0"},
        )
    )
    kc.shell_channel.send(kc.session.msg("comm_msg", {"comm_id": control, "data": {"method": "request_states"}}))
    came, states, late_parent = {}, None, None
    deadline = sent + 30
    while time.monotonic() < deadline and (cell not in came or states is None or asked["inspect"] not in came):
        try:
            m = kc.get_shell_msg(timeout=0.05)
            came[m["parent_header"]["msg_id"]] = (time.monotonic() - sent, m)
        except queue.Empty:
            pass
        try:
            m = kc.get_iopub_msg(timeout=0.05)
        except queue.Empty:
            continue
        if m["msg_type"] == "comm_msg" and m["content"]["comm_id"] == control:
            states = (time.monotonic() - sent, m["content"]["data"])
        elif m["msg_type"] == "stream" and "late" in m["content"]["text"]:
            late_parent = m["parent_header"].get("msg_id")
    assert cell in came, f"the sleeping cell never ended: {came}"
    ended = came[cell][0]
    assert ended > 3.5, f"the cell ended after {ended:.2f} s: it did not sleep, nothing was measured"
    for what in ("kernel_info", "comm_info"):
        assert asked[what] in came, f"no {what}_reply"
        at, reply = came[asked[what]]
        assert at < 2.0 and at < ended, f"the {what}_reply came {at:.2f} s after the request (the cell: {ended:.2f} s)"
    assert comm_id in came[asked["comm_info"]][1]["content"]["comms"], "the view's comm is not among the comms"
    assert states is not None, "the control comm's request_states was never answered"
    assert states[0] < 2.0, f"the widgets' states came {states[0]:.2f} s after the request (the cell: {ended:.2f} s)"
    assert states[1]["method"] == "update_states" and model_id in states[1]["states"], states[1].keys()
    assert asked["forged"] not in came, "a message signed with another key was answered"
    assert came[asked["inspect"]][0] >= ended, "an inspect request was answered while the cell ran: not the main shell"
    assert late_parent == cell, f"the cell's thread's output went to {late_parent}, not the cell ({cell})"


def view_ids(kc) -> tuple[str, str]:
    """The view's widget model id and comm id, from the kernel (idle), made if this kernel has none yet."""
    got = []
    code = (
        "from tutorial.view.widget.widget import MeshcatWidget\n"
        "if 'view' not in globals():\n    view = MeshcatWidget('subshell test')\n"
        "print(view.model_id, view.comm.comm_id)"
    )
    reply = kc.execute_interactive(code, timeout=30, output_hook=lambda m: got.append(m))
    assert reply["content"]["status"] == "ok", reply
    text = "".join(m["content"].get("text", "") for m in got if m["msg_type"] == "stream")
    model_id, comm_id = text.split()
    return model_id, comm_id


def test_a_figure_drawn_while_the_view_hears_its_page_stays_the_cells(kernel):
    """ipykernel's comms fire IPython's pre_execute and post_execute around each message; on the views' subshell
    they must not: matplotlib's inline backend would show the running cell's figure there, half drawn, and close
    it (the cell's next pyplot call then draws on a new, second figure)."""
    kc = kernel
    _, comm_id = view_ids(kc)
    kc.execute_interactive("%matplotlib inline", timeout=30)
    cell = kc.execute(
        "import matplotlib.pyplot as plt, time\nplt.plot([0, 1])\nprint('drawing', flush=True)\ntime.sleep(2)\n"
        "plt.title('drawn')\nplt.show()"  # one figure, finished after the view's message: shown once, whole
    )
    pictures, scene, done = [], False, False
    for m in messages(kc, time.monotonic() + 30):
        content = m["content"]
        if m["msg_type"] == "stream" and "drawing" in content.get("text", ""):
            data = {"method": "custom", "content": {"type": "hello", "id": "figure"}}
            kc.shell_channel.send(kc.session.msg("comm_msg", {"comm_id": comm_id, "data": data}))
        elif m["msg_type"] == "comm_msg" and content["data"].get("content", {}).get("type") == "scene":
            scene = True
        elif m["msg_type"] == "display_data" and "image/png" in content["data"]:
            pictures.append(m["parent_header"].get("msg_id"))
        elif m["msg_type"] == "status" and m["parent_header"].get("msg_id") == cell:
            done = content["execution_state"] == "idle"
            if done:
                break
    assert done and scene, f"the cell ended: {done}; the view answered its hello: {scene}"
    assert pictures == [cell], f"the figure was shown under {pictures}, not once under the cell ({cell})"

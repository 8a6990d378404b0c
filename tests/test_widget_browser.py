"""The live view's browser side (tutorial/view/widget/widget.js) in Chromium, with a stand-in for Jupyter.

The widget's module is imported into a blank page and given a model that
records what the view sends and lets the test send what the kernel would:
meshcat's script when asked, the scene after the view's hello, frames.  So
each message a view can be sent is tried exactly, and fast:

- the scene and a frame draw (the box moves on the canvas);
- every frame is answered with ``drawn``, and only after it was drawn: two
  frames drawn together in one answer, a lone frame on its own;
- a message it cannot take (a command that is not msgpack, an unknown
  command type, a buffer over the limit, a ``set_transforms`` to a path the
  scene does not have, a non-finite matrix) is named in the console, that
  frame is dropped whole (nothing of it is drawn), the kernel is told, and
  the next good frame draws;
- a scene meant for another view is ignored; the kernel cut off
  (``comm_live_update`` with no answer to its ping) brings the notice and a
  caption that says "not live", and an answer takes them away.

The same view in JupyterLab, over a real kernel, reloaded and across hosts:
tests/test_jupyterlab.py and tests/test_network_lab.py.
"""

from __future__ import annotations

import base64
import json

import meshcat
import meshcat.geometry as g
import msgpack
import numpy as np
import pytest
import umsgpack
from meshcat.commands import SetObject, SetTransform

from tests.browser import messages_after_one
from tests.jupyterlab import browser
from tutorial.view.meshcat_batch import pack_batch
from tutorial.view.meshcat_page import viewer_script_gzip
from tutorial.view.widget.widget import LIMITS, MeshcatWidget

pytestmark = pytest.mark.browser
MORE = pytest.mark.more

# A stand-in for anywidget's model: records what the view sends, lets the test deliver messages.
HARNESS = """async ([esm, script, ping_ms]) => {
  const listeners = {};
  const state = {label: "test view", height: 300, status: "running"};
  window.sent = [];
  window.model = {
    get: (k) => state[k],
    on: (name, cb) => { (listeners[name] = listeners[name] || []).push(cb); },
    off: (name, cb) => { listeners[name] = (listeners[name] || []).filter((c) => c !== cb); },
    send: (content) => {
      window.sent.push(content);
      if (content.type === "viewer_js") {
        const bytes = Uint8Array.from(atob(script), (c) => c.charCodeAt(0));
        setTimeout(() => window.deliver({type: "viewer_js"}, [new DataView(bytes.buffer)]), 0);
      }
    },
  };
  window.deliver = (msg, buffers) => (listeners["msg:custom"] || []).forEach((cb) => cb(msg, buffers || []));
  window.trigger = (name) => (listeners[name] || []).forEach((cb) => cb());
  const source = esm.replace(/"ping_ms": \\d+/, `"ping_ms": ${ping_ms}`);
  const module = await import(URL.createObjectURL(new Blob([source], {type: "text/javascript"})));
  window.el = document.getElementById("el");
  module.default.render({model: window.model, el: window.el});
}"""

# Deliver packed commands (base64) as one message's buffers; "HUGE:n" is n zero bytes, made in the page.
DELIVER = """([msg, b64s]) => window.deliver(msg, b64s.map((b) => {
  if (b.startsWith("HUGE:")) return new DataView(new ArrayBuffer(Number(b.slice(5))));
  const bytes = Uint8Array.from(atob(b), (c) => c.charCodeAt(0));
  return new DataView(bytes.buffer);
}))"""


def told(page, since: int = 0) -> list[dict]:
    """What the view sent the kernel from message ``since`` on, less its ``here`` (sent on a clock of its own)."""
    return [m for m in page.evaluate("window.sent")[since:] if m["type"] != "here"]


def b64(buffers: list) -> list[str]:
    return [b if isinstance(b, str) else base64.b64encode(b).decode("ascii") for b in buffers]


def box_command() -> bytes:
    return umsgpack.packb(
        SetObject(
            g.Box([0.6, 0.6, 0.6]), g.MeshLambertMaterial(color=0xFF0000), meshcat.path.Path(("meshcat", "box"))
        ).lower()
    )


def move(x: float, path=("meshcat", "box")) -> dict:
    m = np.eye(4)
    m[1, 3] = x  # across meshcat's default camera's view
    return SetTransform(m, meshcat.path.Path(path)).lower()


@pytest.fixture(scope="module")
def view():
    """A page with one view rendered from the widget's real module, its scene (a red box) delivered."""
    with browser(width=500, height=420) as page:
        errors: list[str] = []
        page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
        page.set_content("<html><body style='margin: 0'><div id='el' style='width: 480px'></div></body></html>")
        page.evaluate(HARNESS, [MeshcatWidget._esm, base64.b64encode(viewer_script_gzip()).decode("ascii"), 1500])
        page.wait_for_function("window.sent.some((m) => m.type === 'hello')", timeout=30_000)
        hello = next(m for m in page.evaluate("window.sent") if m["type"] == "hello")
        page.evaluate(DELIVER, [{"type": "scene", "to": hello["id"]}, b64([box_command(), msgpack.packb(move(0.0))])])
        page.wait_for_function("window.el.rttView.scenes === 1", timeout=10_000)
        yield page, errors


def red_x(page) -> float:
    """Where the red box is across the view, px (mean column of its red pixels)."""
    from io import BytesIO

    from PIL import Image

    image = np.asarray(Image.open(BytesIO(page.locator("iframe.rtt-live-view").screenshot())).convert("RGB")).astype(
        int
    )
    red = (image[..., 0] > 120) & (image[..., 1] < 60) & (image[..., 2] < 60)
    assert red.sum() > 50, "no red box in the view"
    return float(np.nonzero(red)[1].mean())


def frame(page, buffers: list[bytes]) -> dict:
    """Deliver one frame; wait for its answer; the view's counts."""
    answers = page.evaluate("window.sent.filter((m) => m.type === 'drawn').length")
    page.evaluate(DELIVER, [{"type": "frame"}, b64(buffers)])
    page.wait_for_function(f"window.sent.filter((m) => m.type === 'drawn').length > {answers}", timeout=10_000)
    return page.evaluate("window.el.rttView")


def test_scene_and_frames_draw_and_each_is_answered(view):
    page, errors = view
    page.wait_for_timeout(300)  # nothing to wait on: the first picture of a static scene
    at_start = red_x(page)
    stats = frame(page, [pack_batch([move(1.0)])])
    assert stats["frames"] >= 2 and stats["dropped"] == 0
    page.wait_for_timeout(200)  # the frame is drawn (it was answered); the screenshot takes the next
    moved = red_x(page)
    assert abs(moved - at_start) > 20, f"the box did not move: {at_start:.0f} -> {moved:.0f} px"
    assert not errors, errors


def test_two_frames_drawn_together_are_answered_once_and_a_lone_frame_on_its_own(view):
    page, errors = view
    frame(page, [pack_batch([move(0.5)])])  # whatever was owed before is answered
    page.wait_for_timeout(600)  # the wait for owed frames (0.25 s) and more: no answer left owed
    before = page.evaluate("window.sent.length")
    page.evaluate(  # two frames in one task: drawn in the same animation frame
        "([a, b]) => { for (const m of [a, b]) window.deliver({type: 'frame'}, "
        "[new DataView(Uint8Array.from(atob(m), (c) => c.charCodeAt(0)).buffer)]); }",
        b64([pack_batch([move(1.0)]), pack_batch([move(1.5)])]),
    )
    page.wait_for_function(f"window.sent.slice({before}).some((m) => m.type === 'drawn')", timeout=10_000)
    page.wait_for_timeout(200)  # a second answer, were there one, would have come by now
    answers = [m for m in page.evaluate("window.sent")[before:] if m["type"] == "drawn"]
    assert answers == [{"type": "drawn", "frames": 2}], answers
    stats = frame(page, [pack_batch([move(0.0)])])  # a lone frame: answered on its own
    assert told(page)[-1] == {"type": "drawn", "frames": 1}
    assert stats["dropped"] == 0 and not errors, errors


@pytest.mark.parametrize(
    "bad, reason",
    [
        (b"\xc1\xc1\xc1", "not msgpack"),
        # make test keeps a message that does not decode and one that decodes to a bad value; the others, each
        # another of the view's checks, are in make test-more
        pytest.param(msgpack.packb({"type": "capture_image", "path": "/x"}), "not a meshcat scene command", marks=MORE),
        pytest.param(
            pack_batch([move(2.0, ("meshcat", "nothing", "here"))]), "no /meshcat/nothing/here in the scene", marks=MORE
        ),
        (msgpack.packb(dict(move(2.0), matrix=[float("nan")] + [0.0] * 15)), "not a finite number"),
        pytest.param(
            msgpack.packb(dict(move(2.0), path="/a" * (LIMITS["max_path_parts"] + 1))), "more than", marks=MORE
        ),
        pytest.param(f"HUGE:{LIMITS['max_command_bytes'] + 1}", "over the limit", marks=MORE),
    ],
    ids=["not-msgpack", "unknown-type", "unknown-path", "nan", "deep-path", "huge"],
)
def test_a_bad_message_drops_that_frame_whole_and_the_view_goes_on(view, bad, reason):
    page, errors = view
    errors.clear()
    frame(page, [pack_batch([move(0.0)])])
    before = dict(page.evaluate("window.el.rttView"), sent=page.evaluate("window.sent.length"))
    x0 = red_x(page)
    # a good command first, then the bad one: nothing of the frame may be drawn
    stats = frame(page, [msgpack.packb(move(1.5)), bad])
    assert stats["dropped"] == before["dropped"] + 1 and stats["frames"] == before["frames"], stats
    assert reason in stats["errors"][-1], stats["errors"][-1]
    assert any("dropped a frame" in e and reason in e for e in errors), errors
    types = [m["type"] for m in told(page, before["sent"])]
    assert "rejected" in types, types
    page.wait_for_timeout(200)  # a frame was not drawn: nothing to wait on but the next animation frame
    assert abs(red_x(page) - x0) < 2, "part of a dropped frame was drawn"
    after = frame(page, [pack_batch([move(1.5)])])
    assert after["frames"] == stats["frames"] + 1, "the view did not go on after a bad frame"
    page.wait_for_timeout(200)
    assert abs(red_x(page) - x0) > 20, "the good frame after the bad one did not draw"


def test_a_frame_that_draws_and_moves_a_new_body_draws_and_a_dropped_frame_asks_for_the_scene(view):
    """A run restarted in the same view sends its bodies and their first poses in one frame."""
    page, errors = view
    errors.clear()
    green = umsgpack.packb(
        SetObject(
            g.Box([0.3, 0.3, 0.3]), g.MeshLambertMaterial(color=0x00FF00), meshcat.path.Path(("meshcat", "new", "g"))
        ).lower()
    )
    dropped = page.evaluate("window.el.rttView.dropped")
    stats = frame(page, [green, pack_batch([move(-1.0, ("meshcat", "new")), move(0.5)])])
    assert stats["dropped"] == dropped, stats["errors"]
    assert not errors, errors
    page.wait_for_timeout(3000)  # past the view's 2 s between asking for the scene again
    n = page.evaluate("window.sent.length")
    frame(page, [pack_batch([move(0.0, ("meshcat", "not", "drawn"))])])
    types = [m["type"] for m in told(page, n)]
    assert types[:2] == ["rejected", "hello"], f"a dropped frame did not ask for the whole scene again: {types}"


def test_a_scene_with_a_bad_command_draws_the_rest(view):
    page, errors = view
    errors.clear()
    hello = [m for m in page.evaluate("window.sent") if m["type"] == "hello"][0]
    before = page.evaluate("window.el.rttView")
    page.evaluate(
        DELIVER, [{"type": "scene", "to": hello["id"]}, b64([b"\xc1", box_command(), msgpack.packb(move(0.2))])]
    )
    after = page.evaluate("window.el.rttView")
    assert after["scenes"] == before["scenes"] + 1 and after["dropped"] == before["dropped"]
    assert any("left out of the scene" in e for e in errors), errors


def test_a_scene_for_another_view_is_ignored(view):
    page, _ = view
    before = page.evaluate("window.el.rttView")
    page.evaluate(DELIVER, [{"type": "scene", "to": "another"}, b64([box_command()])])
    page.evaluate(DELIVER, [{"type": "pong"}, []])  # any message after it: the first has been handled
    assert page.evaluate("window.el.rttView")["scenes"] == before["scenes"]


def test_at_20_frames_a_second_four_frames_are_answered_once_and_the_rest_after_a_quarter_of_a_second(view):
    """A class's 20 frames/s: the fourth frame comes 150 ms after the first, before the wait (0.25 s) ends; the
    fifth, alone, is answered 0.25 s after it was drawn (not with the four, nor early by their wait)."""
    page, errors = view
    frame(page, [pack_batch([move(0.5)])])  # whatever was owed before is answered
    page.wait_for_timeout(600)  # an answer, were one owed, would have gone by now
    before, errors_before = page.evaluate("window.sent.length"), len(errors)
    times = page.evaluate(  # five frames 50 ms apart, the last timed from its delivery to its answer
        """async ([a, b]) => {
          const put = (m) => window.deliver({type: 'frame'},
            [new DataView(Uint8Array.from(atob(m), (c) => c.charCodeAt(0)).buffer)]);
          const drawn = () => window.sent.filter((m) => m.type === 'drawn').length;
          const answered = (n) => new Promise((done) => {
            const look = () => (drawn() >= n ? done() : setTimeout(look, 2));
            look();
          });
          const start = drawn();
          for (const m of [a, b, a, b]) {
            put(m);
            await new Promise((done) => setTimeout(done, 50));
          }
          const t0 = performance.now();
          put(a);
          await answered(start + 2);
          return {lone_ms: performance.now() - t0};
        }""",
        b64([pack_batch([move(1.0)]), pack_batch([move(1.5)])]),
    )
    answers = [m for m in page.evaluate("window.sent")[before:] if m["type"] == "drawn"]
    assert answers == [{"type": "drawn", "frames": 4}, {"type": "drawn", "frames": 1}], answers
    assert 250 <= times["lone_ms"] <= 1500, times  # drawn in the next animation frame, answered 0.25 s after that
    assert errors[errors_before:] == []


def test_the_benchmarks_stand_in_browser_waits_as_long_as_the_view():
    """benchmarks/experiments/learners.py answers frames as widget.js does: as many at once, the same wait."""
    import re

    from benchmarks.experiments.learners import ANSWER_EVERY, LONE_WAIT_MS
    from tutorial.view.widget.flow import WINDOW
    from tutorial.view.widget.widget import MeshcatWidget

    found = re.search(r"const LONE_WAIT_MS = (\d+);", MeshcatWidget._esm)
    assert found and int(found.group(1)) == LONE_WAIT_MS == 250
    found = re.search(r"const ANSWER_EVERY = (\d+);", MeshcatWidget._esm)
    assert found and int(found.group(1)) == ANSWER_EVERY == WINDOW // 2


def test_cut_off_from_its_kernel_the_view_says_it_is_not_live_and_an_answer_takes_that_back(view):
    page, _ = view
    caption = page.locator(".rtt-caption")
    assert caption.inner_text().startswith("test view (live): running")
    before = page.evaluate("window.sent.length")
    page.evaluate("window.trigger('comm_live_update')")
    # one ping for the cut-off (a frame's lone answer, six animation frames late, may be sent beside it)
    asked = [m["type"] for m in told(page, before)]
    assert asked.count("ping") == 1 and set(asked) <= {"ping", "drawn"}, asked
    notice = page.locator(".rtt-not-live")
    notice.wait_for(timeout=10_000)
    assert "Not live any more" in notice.inner_text()
    assert "(not live)" in caption.inner_text()
    page.evaluate(DELIVER, [{"type": "pong"}, []])  # the kernel was only slow
    assert notice.count() == 0 and "(live)" in caption.inner_text()
    # answered in time: no notice at all
    page.evaluate("window.trigger('comm_live_update')")
    page.evaluate(DELIVER, [{"type": "pong"}, []])
    page.wait_for_timeout(2000)  # past the ping's 1.5 s: the notice would have shown by now
    assert notice.count() == 0


def test_a_message_posted_to_the_views_page_starts_nothing(view):
    page, errors = view
    errors.clear()
    assert messages_after_one(page.frames[1]) == 1
    assert not errors, errors


def test_the_module_is_the_widgets_with_its_limits():
    assert json.dumps(LIMITS) in MeshcatWidget._esm

"""3D views in a notebook: live while their run lives, a recording once it has ended.

A :class:`LiveView` belongs to one run (:class:`tutorial.notebook.runs.BackgroundApp`)
and outlives its Start/Stop cycles: its meshcat server stays up, so the
page in the notebook stays connected and shows every restarted run.  A
caption under the page says what the view shows right now: starting,
live, stopped, finished, failed.  When the view closes (``reset()``), the
live page is replaced, in the same output, by a recording of the run's
last seconds, marked as a recording: a view never points at a server that
is gone, and a saved notebook (and the book) shows what happened.

A kernel that is restarted or shut down cannot replace its outputs any
more, and its meshcat servers stop with it.  So a live output watches its
servers from the browser (:func:`live_html`): once one stops answering, a
notice over the page says it is not live any more (the page keeps its last
frame; one that never loaded is hidden, never the browser's error page),
and the caption says so too.

:func:`show` puts one or more views side by side in one output.

Threads: :func:`show` and :meth:`LiveView.close` run on the kernel
thread; :meth:`LiveView.visualizer`, :meth:`LiveView.begin` and
:meth:`LiveView.record` on the run's owner thread; :meth:`LiveView.set_status`
on either (it only sends an output update, which ipykernel accepts from
any thread).  The recorded frames are the one thing both threads touch:
a lock guards them.
"""

from __future__ import annotations

import html
import json
import threading
import time
import uuid
from collections import deque

from tutorial.notebook import replay, session


class LiveView:
    """The inline 3D view of one run, with a meshcat server of its own.

    Args:
        label: what the view shows, e.g. ``"simulation (node /rtt)"``.
        height: height of the page in the notebook, px.

    Raises:
        RuntimeError: the meshcat server did not start.
    """

    FPS = 15.0  # recorded frames per second of wall time
    SECONDS = 60.0  # the recording keeps the last this many seconds of the run

    def __init__(self, label: str, height: int = 380):
        from tutorial.view.meshcat_server import start_server

        self.label = label
        self.height = height
        self.server = start_server()
        self.url = self.server.web_url
        self.status = "not started yet"
        self.closed = False
        self._displays: list[_Display] = []
        self._lock = threading.Lock()  # guards the four below: the owner thread writes, close() reads
        self._model = None
        self._camera = None
        self._overlays = None
        self._frames: deque = deque(maxlen=int(self.FPS * self.SECONDS))  # (qpos, arrows or None)
        self._next_frame = 0.0

    # ---- the run's owner thread ---------------------------------------------------
    def visualizer(self):
        """A ``meshcat.Visualizer`` on this view's server, owned by the calling thread (one per run)."""
        return self.server.visualizer()

    def begin(self, model, camera=None, overlays=None) -> None:
        """A run starts drawing ``model``: its recording starts afresh (owner thread).

        Args:
            model: the run's ``MjModel``.
            camera: ``(position, target)`` the run placed its camera at, m, for the recording.
            overlays: the run's :class:`tutorial.view.overlays.Overlays` (arrows its controllers
                draw), recorded with each frame; None when it has none.
        """
        with self._lock:
            self._model, self._camera, self._overlays = model, camera, overlays
            self._frames.clear()
            self._next_frame = 0.0

    def record(self, data) -> None:
        """Keep ``data.qpos`` (and the arrows) as a frame, at most ``FPS`` times a second (owner thread)."""
        now = time.monotonic()
        if now < self._next_frame:
            return
        self._next_frame = now + 1.0 / self.FPS
        arrows = self._overlays.snapshot() if self._overlays is not None and self._overlays.arrows else None
        with self._lock:
            self._frames.append((data.qpos.copy(), arrows))

    # ---- any thread -------------------------------------------------------------------
    def set_status(self, status: str) -> None:
        """Say what the view shows now (the caption under the page)."""
        self.status = status
        for d in list(self._displays):
            d.refresh_caption()

    # ---- kernel thread ---------------------------------------------------------------------
    def recording(self):
        """A :class:`tutorial.notebook.replay.ViewRecording` of the last run, or None if nothing was drawn."""
        with self._lock:
            model, camera, overlays, frames = self._model, self._camera, self._overlays, list(self._frames)
        if model is None or not frames:
            return None
        qpos = [q for q, _ in frames]
        if all(a is None for _, a in frames):  # the run drew no arrows
            return replay.record_replay(model, qpos, self.FPS, camera=camera)
        # A frame before the first arrow was drawn has none: an empty frame (arrows hidden).
        arrows = [a or {} for _, a in frames]
        return replay.record_replay(model, qpos, self.FPS, camera=camera, overlays=overlays, overlay_frames=arrows)

    def recorded_seconds(self) -> float:
        with self._lock:
            return len(self._frames) / self.FPS

    def close(self) -> None:
        """Replace the live page by the recording and stop the server (kernel thread, once)."""
        if self.closed:
            return
        self.closed = True
        for d in list(self._displays):
            d.view_closed()
        self.server.close()


# Runs in the browser, in a live output: every 2 s it asks each page's server for its page (HEAD).
# When none answers, the kernel has gone (restarted or shut down: nothing in the kernel can say so
# any more), and the output says it.  One closed view alone (its run reset while the other's is
# still stopping) is not that.  The box is looked up by its id at every check, so a cell that
# JupyterLab takes out of the page while scrolled away is watched again when it comes back; the
# watch ends when its output is replaced (by a recording), or after a minute with no box.
_WATCH = """<script>
(() => {
  const urls = %(urls)s, notice = %(notice)s, caption = %(caption)s;
  let missing = 0, answered = false;
  const gone = (box) => {
    const note = document.createElement("div");
    note.textContent = notice + (answered ? " What you see is its last frame." : "");
    note.style.cssText = "position: absolute; left: 0; right: 0; top: 0; padding: 4px 8px; "
      + "background: rgba(255, 236, 179, 0.95); color: #5d4037; font: 13px sans-serif";
    if (!answered) box.querySelectorAll("iframe").forEach((f) => { f.style.visibility = "hidden"; });
    box.appendChild(note);
    const under = document.getElementById(%(caption_id)s);
    if (under) under.innerHTML = caption;
  };
  const check = () => {
    const box = document.getElementById(%(box_id)s);
    if (!box) { if (++missing < 300) setTimeout(check, 200); return; }  // not (or no longer) in the page
    missing = 0;
    const ask = (u) => fetch(u, {method: "HEAD", mode: "no-cors", cache: "no-store"});
    Promise.allSettled(urls.map(ask)).then((results) => {
      if (results.some((r) => r.status === "fulfilled")) {
        answered = true;
        setTimeout(check, 2000);
      } else if (box.isConnected) {
        gone(box);
      }
    });
  };
  check();
})();
</script>"""


def live_html(urls: list[str], frames: str, caption_id: str, what: str) -> str:
    """``frames`` (the live pages of ``urls``) in a box that says so when their servers have gone.

    Args:
        urls: the meshcat pages the frames show.
        frames: their ``<iframe>`` elements.
        caption_id: the ``id`` of the caption under them, rewritten then.
        what: what the frames show, for the notice (e.g. ``"simulation /rtt"``).
    """
    box_id = f"rtt-live-{uuid.uuid4().hex}"
    notice = (
        f"Not live any more: the kernel that ran {what} was restarted or shut down, so nothing runs "
        "here now. Run the section again for a live view."
    )
    caption = (
        f'<div style="font-size: 90%"><b>{html.escape(what)}</b> (not live): its kernel has gone, '
        "so nothing runs; run the section again for a live view.</div>"
    )

    def js(value) -> str:  # a JavaScript literal that cannot end the script early
        return json.dumps(value).replace("</", "<\\/")

    script = _WATCH % {
        "urls": js(urls),
        "notice": js(notice),
        "caption": js(caption),
        "box_id": js(box_id),
        "caption_id": js(caption_id),
    }
    return f'<div id="{box_id}" style="position: relative">{frames}</div>{script}'


class _Display:
    """One output showing one or more views side by side, with a caption under them."""

    def __init__(self, views: list[LiveView], height: int):
        from IPython.display import HTML, display

        self.views = views
        self.height = height
        self.caption_id = f"rtt-caption-{uuid.uuid4().hex}"
        frames = "".join(
            f'<iframe src="{v.url}" style="flex: 1; min-width: 0; height: {height}px; border: none"></iframe>'
            for v in views
        )
        page = live_html(
            [v.url for v in views],
            f'<div style="display: flex; gap: 4px">{frames}</div>',
            self.caption_id,
            " and ".join(v.label for v in views),
        )
        self.page = display(HTML(page), display_id=True)
        self.caption = display(HTML(self._caption()), display_id=True)
        for v in views:
            v._displays.append(self)

    def _caption(self) -> str:
        parts = []
        for v in self.views:
            state = "recording" if v.closed else "live"
            parts.append(f"<b>{html.escape(v.label)}</b> ({state}): {html.escape(v.status)}")
        return f'<div id="{self.caption_id}" style="font-size: 90%">' + " &nbsp;|&nbsp; ".join(parts) + "</div>"

    def refresh_caption(self) -> None:
        from IPython.display import HTML

        self.caption.update(HTML(self._caption()))

    def view_closed(self) -> None:
        """Once every view of this output has closed, show their recordings side by side."""
        from IPython.display import HTML

        if not all(v.closed for v in self.views):
            self.refresh_caption()
            return
        scenes = [v.recording() for v in self.views]
        if any(s is None for s in scenes):
            self.page.update(
                HTML(
                    "<p><i>This view closed before its run drew anything: "
                    "there is nothing to replay. Run the section again to see it live.</i></p>"
                )
            )
        else:
            labels = [f"{v.label}: recorded, {v.recorded_seconds():.1f} s" for v in self.views]
            page = replay.page_html(scenes, labels, title="recording")
            self.page.update(HTML(replay.iframe_html(page, self.height)))
        seconds = ", ".join(f"{v.label} {v.recorded_seconds():.1f} s" for v in self.views)
        self.caption.update(
            HTML(
                '<div style="font-size: 90%"><b>Recorded</b> ('
                + html.escape(seconds)
                + f", {LiveView.FPS:.0f} frames/s): "
                "the run has ended and its live page is gone, so this is a recording of what it showed. "
                "Drag to turn, scroll to zoom; <i>Open Controls, Animations</i> pauses it. "
                "Run the section again for a live view.</div>"
            )
        )


def show(*views: LiveView, height: int | None = None) -> None:
    """Display ``views`` side by side in this cell's output (kernel thread).

    The output stays true: a caption says what each view shows, and when
    the views close their pages become their recordings.
    """
    if not views:
        raise ValueError("show: no views given")
    _Display(list(views), height or max(v.height for v in views))


class MeshcatPage:
    """A meshcat page to draw in by hand, shown inline; a still picture of it stays after it closes.

    ``vis`` is a ``meshcat.Visualizer`` that draws both into the live page
    and into a recording, so :meth:`close` can leave the scene as it was.
    Owned by the kernel thread (meshcat's socket is not thread-safe).
    """

    def __init__(self, label: str = "meshcat page", height: int = 350):
        import meshcat

        from tutorial.view.meshcat_server import start_server

        self.label = label
        self.height = height
        self.server = start_server()
        self.url = self.server.web_url
        self.recording = replay.ViewRecording()
        self.vis = meshcat.Visualizer(window=_Tee(self.server.visualizer().window, self.recording))
        self.closed = False
        self._handle = None
        session.register(self)

    def show(self) -> None:
        """Display the live page, with a caption, in this cell's output."""
        from IPython.display import HTML, display

        caption_id = f"rtt-caption-{uuid.uuid4().hex}"
        frame = f'<iframe src="{self.url}" style="width: 100%; height: {self.height}px; border: none"></iframe>'
        self._handle = display(HTML(live_html([self.url], frame, caption_id, self.label)), display_id=True)
        self._caption = display(
            HTML(f'<div id="{caption_id}" style="font-size: 90%"><b>{html.escape(self.label)}</b> (live)</div>'),
            display_id=True,
        )

    def close(self) -> None:
        """Leave a still copy of the scene in the output, then stop the server (kernel thread)."""
        from IPython.display import HTML

        if self.closed:
            return
        self.closed = True
        if self._handle is not None:
            page = replay.page_html([self.recording], [self.label], title=self.label)
            self._handle.update(HTML(replay.iframe_html(page, self.height)))
            self._caption.update(
                HTML(
                    f'<div style="font-size: 90%"><b>{html.escape(self.label)}</b> '
                    "(a saved copy: the live page has closed; drag to turn, scroll to zoom)</div>"
                )
            )
        self.server.close()


class _Tee:
    """A meshcat window that sends each command to a live window and to a recording."""

    zmq_url = None  # one path for every command, so the recording sees them all

    def __init__(self, live, recording: replay.ViewRecording):
        self.live = live
        self.recording = recording
        self.web_url = live.web_url

    def send(self, command) -> None:
        self.live.send(command)
        self.recording.send(command)


def show_recording(model, frames, fps: float, label: str, camera=None, height: int = 380) -> None:
    """Display a recording of ``frames`` (a finished run, e.g. :func:`tutorial.notebook.runs.run_project`'s).

    Args:
        model: the ``MjModel`` of the frames.
        frames: (nq,) ``qpos`` arrays, ``1/fps`` s apart.
        fps: frames per second of the recording.
        label: what it shows, written in its corner.
        camera: optional ``(position, target)``, m.
        height: px.

    The page is self-contained and the same bytes for the same frames, so a
    deterministic run's recording is checked like any other output.
    """
    from IPython.display import HTML, display

    page = replay.page_html([replay.record_replay(model, frames, fps, camera=camera)], [label], title=label)
    display(HTML(replay.iframe_html(page, height)))

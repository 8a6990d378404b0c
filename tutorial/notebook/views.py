"""3D views in a notebook: live while their run lives, a recording once it has ended.

A :class:`LiveView` belongs to one run (:class:`tutorial.notebook.runs.BackgroundApp`)
and outlives its Start/Stop cycles.  Its page is a Jupyter widget
(:class:`tutorial.view.widget.widget.MeshcatWidget`): meshcat's own viewer,
fed over the notebook's own connection, so it draws wherever the notebook
opens (on this machine, a course's JupyterHub, behind an SSH tunnel, in
Colab), keeps its scene across a page reload, and shows every restarted
run.  A caption under the page says what the view shows right now:
starting, live, stopped, finished, failed.  When the view closes
(``reset()``), the live page is replaced, in the same output, by a
recording of the run's last seconds, marked as a recording: a saved
notebook (and the book) shows what happened.

A kernel that is restarted or shut down takes its widgets with it: the
page then says the view is not live any more (``widget.js``).

:func:`show` puts one or more views side by side in one output; a view
shows itself the same way (``display(sim.view)``, or ``sim.view`` as a
cell's last expression), and ``sim.show()`` shows a run's view.

Threads: :func:`show` and :meth:`LiveView.close` run on the kernel
thread; :meth:`LiveView.visualizer`, :meth:`LiveView.begin` and
:meth:`LiveView.record` on the run's owner thread; :meth:`LiveView.set_status`
on either (it only sends an output update, which ipykernel accepts from
any thread).  The recorded frames are the one thing both threads touch:
a lock guards them.
"""

from __future__ import annotations

import html
import os
import threading
import time
from collections import deque

from tutorial.notebook import replay

# s without a word from any page after which a run a page has shown pauses (RTT_PAUSE_UNWATCHED)
UNWATCHED = float(os.environ.get("RTT_PAUSE_UNWATCHED", "30"))


class LiveView:
    """The inline 3D view of one run: a Jupyter widget drawing its scene, then a recording of it.

    Args:
        label: what the view shows, e.g. ``"simulation (node /rtt)"``.
        height: height of the page in the notebook, px.
    """

    FPS = 15.0  # recorded frames per second of wall time
    SECONDS = 60.0  # the recording keeps the last this many seconds of the run

    def __init__(self, label: str, height: int = 380):
        from tutorial.view.widget.widget import MeshcatWidget

        self.label = label
        self.height = height
        self.widget = MeshcatWidget(label, height)
        self.status = "not started yet"
        self.closed = False
        self._displays: list[_Display] = []
        self._lock = threading.Lock()  # guards the four below: the owner thread writes, close() reads
        self._model = None
        self._camera = None
        self._overlays = None
        self._frames: deque = deque(maxlen=int(self.FPS * self.SECONDS))  # (qpos, arrows or None)
        self._next_frame = 0.0
        self._paused_since = 0.0  # when pause_while_unwatched paused the run (owner thread)

    # ---- the run's owner thread ---------------------------------------------------
    def visualizer(self):
        """A ``meshcat.Visualizer`` drawing into this view's widget, owned by the calling thread (one per run)."""
        return self.widget.visualizer()

    def pause_while_unwatched(self, sim) -> str | None:
        """Pause ``sim`` (a :class:`tutorial.core.simulator.Simulator`, or None) once no page has said anything
        to this view for :data:`UNWATCHED` s, and resume it when a page does; the run's new status, or None
        when nothing changed (owner thread).

        A run nobody watches then costs nothing (a class's server, a learner who closed the page), and loses
        nothing: simulated time stands still.  Only a run a page has shown pauses (a notebook run without a
        browser, as the tests run them, never does), and never while a cell runs: a running cell is use
        (it may be waiting on this run), and where the views have no kernel subshell a page's messages wait
        behind it.  A view on a visible page says
        so every few seconds (``widget.js``), even when nothing moves.
        """
        from tutorial.view.widget.widget import cell_running

        if sim is None or self.widget.hellos == 0:
            return None
        unwatched = time.monotonic() - self.widget.last_heard > UNWATCHED
        if not sim.paused and unwatched and not cell_running():
            sim.pause()
            sim.wait_paused(1.0)
            self._paused_since = time.monotonic()
            return (
                f"paused at t = {sim.sim_time:.2f} s: no page showed this view for {UNWATCHED:.0f} s "
                "(it goes on when one does)"
            )
        if sim.paused and not unwatched:
            at = sim.sim_time
            sim.resume()
            held = time.monotonic() - self._paused_since
            return f"running (paused at t = {at:.2f} s for {held:.0f} s while no page showed it)"
        return None

    def begin(self, model, camera=None, overlays=None) -> None:
        """A run starts drawing ``model``: its recording starts afresh (owner thread).

        Args:
            model: the run's ``MjModel``.
            camera: ``(position, target)`` the run placed its camera at, m, for the recording.
            overlays: the run's :class:`tutorial.view.meshcat_overlays.Overlays` (arrows its controllers
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
        if not self.closed:
            self.widget.status = status

    # ---- kernel thread ---------------------------------------------------------------------
    def _ipython_display_(self) -> None:
        """``display(view)``, or a view as a cell's last expression: shown as :func:`show` shows it."""
        show(self)

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
        """Replace the live page by the recording and close the widget (kernel thread, once)."""
        if self.closed:
            return
        self.closed = True
        for d in list(self._displays):
            d.view_closed()
        self.release()

    def release(self) -> None:
        """Close the widget once no output shows it live any more (kernel thread)."""
        if self.closed and all(d.done for d in self._displays):
            self.widget.close()


class _Display:
    """One output showing one or more views side by side (each with its caption), then their recordings."""

    def __init__(self, views: list[LiveView], height: int):
        import ipywidgets
        from IPython.display import HTML, display

        self.views = views
        self.height = height
        self.done = False  # every view of it has closed, and it shows their recordings
        for v in views:
            v.widget.height = height
            v.widget.layout = ipywidgets.Layout(flex="1 1 0%", min_width="0")
        self._box = None
        page = views[0].widget
        if len(views) > 1:
            self._box = page = ipywidgets.HBox([v.widget for v in views], layout=ipywidgets.Layout(grid_gap="4px"))
        self.page = display(page, display_id=True)
        self.caption = display(HTML(""), display_id=True)  # says "recorded" once the page is a recording
        for v in views:
            v._displays.append(self)

    def view_closed(self) -> None:
        """Once every view of this output has closed, show their recordings side by side."""
        from IPython.display import HTML

        if not all(v.closed for v in self.views):
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
        self.done = True
        if self._box is not None:
            self._box.close()
        for v in self.views:
            v.release()


def show(*views: LiveView, height: int | None = None) -> None:
    """Display ``views`` side by side in this cell's output (kernel thread).

    The output stays true: a caption says what each view shows, and when
    the views close their pages become their recordings.
    """
    if not views:
        raise ValueError("show: no views given")
    _Display(list(views), height or max(v.height for v in views))


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

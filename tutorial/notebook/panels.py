"""Widget panels that tell the truth: live in JupyterLab, a plain stand-in anywhere else.

An ipywidgets panel needs a running kernel.  Opened without one (a
notebook just cloned, the book), a panel shows what its output bundle
offers instead, so :class:`Panel` gives it a text stand-in (and an HTML one
for the book) that says what the panel is and how to get it back, rather
than ``VBox(children=(HBox(...``.

A closed panel (``reset()``) leaves the stand-in in its place, as a
closed view leaves its recording: its widgets are closed, so a saved
notebook holds no widget that needs a kernel (JupyterLab draws such a
widget's controls crossed by broken-link icons).

Threads: widget callbacks and :meth:`Panel.close` run on the kernel
thread; :meth:`RunControls.refresh` may be called from a run's owner
thread (an ipywidgets trait change sends a comm message, which ipykernel
accepts from any thread).
"""

from __future__ import annotations

import html
import threading


class Panel:
    """A widget panel with a status line, a stand-in, and a ``close()`` that disables it.

    Subclasses build ``self.widget`` (an ipywidgets container whose
    controls are in ``self.controls``) and ``self.line`` (an ``HTML`` widget).

    Args:
        title: what the panel is, e.g. ``"Teleop panel (publishes /joy)"``.
        description: one sentence for where the panel cannot be live.
    """

    def __init__(self, title: str, description: str):
        import ipywidgets as w

        self.title = title
        self.description = description
        self.line = w.HTML()
        self.controls: list = []
        self.closed = False
        self._shown: list = []  # the display handles of the outputs showing this panel (kernel thread)
        # Two threads write the status line: the kernel thread (close(), a panel's first refresh) and a run's
        # owner thread (each new status).  Each write reads the state it shows under this lock, so the write
        # that lands last shows the newest state: without it, a refresh that read "starting" could land after
        # the owner's "running" and the line would say "starting" for good.
        self._lock = threading.Lock()

    def say(self, text: str, warning: bool = False) -> None:
        """Set the status line (kernel thread, or any thread that owns no widget lock)."""
        color = "#b00" if warning else "#444"
        self.line.value = f'<span style="color: {color}">{html.escape(text)}</span>'

    def stand_in(self) -> dict:
        """The output bundle where the panel cannot be live: what it is, and how to get it back."""
        return {
            "text/plain": f"{self.title}: {self.description} "
            "(a live panel, not live now: run this cell to use it, in JupyterLab)",
            "text/html": (
                f'<div style="border: 1px solid #bbb; border-radius: 4px; padding: 6px 10px; '
                f'color: #444"><b>{html.escape(self.title)}</b>: {html.escape(self.description)}'
                "<br><i>Not live now: run this cell to use it (in JupyterLab).</i></div>"
            ),
        }

    def _repr_mimebundle_(self, **kwargs):
        return {**self.widget._repr_mimebundle_(**kwargs), **self.stand_in()}

    def _ipython_display_(self) -> None:
        """Show the panel (``display(panel)``, or a cell's last expression), in an output it can replace."""
        from IPython.display import display

        self._shown.append(display(self._repr_mimebundle_(), raw=True, display_id=True))

    def close(self, why: str = "closed by reset(): run this cell again to use it") -> None:
        """Disable the controls, then leave the stand-in where the panel was shown and close its widgets.

        Kernel thread.  The stand-in's texts are the live bundle's, so a saved
        output reads the same whether the cell was just run or reset since.
        """
        with self._lock:
            if self.closed:
                return
            self.closed = True
            for c in self.controls:
                c.disabled = True
            self.say(why)
        for shown in self._shown:
            shown.update(self.stand_in(), raw=True)
        _close_tree(self.widget)


def _close_tree(widget) -> None:
    """Close an ipywidgets widget and every widget it holds (children, layout, style)."""
    import ipywidgets as w

    for name in widget.keys:
        value = getattr(widget, name, None)
        for held in value if isinstance(value, (list, tuple)) else [value]:
            if isinstance(held, w.Widget) and held is not widget:
                _close_tree(held)
    widget.close()


class RunControls(Panel):
    """Start and Stop buttons for a :class:`tutorial.notebook.runs.BackgroundApp`, with its status.

    Made by ``BackgroundApp.controls()``, which lists the panel with the run and then calls
    :meth:`refresh`, so the line shows every status from then on.
    """

    def __init__(self, run):
        import ipywidgets as w

        super().__init__(
            f"Start/Stop for /{run.node_name}",
            "buttons that start and stop the run, and a line saying what it is doing",
        )
        self.run = run
        self.start = w.Button(description="Start", button_style="success")
        self.stop = w.Button(description="Stop")
        self.start.on_click(lambda _: self._start())
        self.stop.on_click(lambda _: run.stop())
        self.controls = [self.start, self.stop]
        self.widget = w.HBox([self.start, self.stop, self.line])

    def _start(self) -> None:
        try:
            self.run.start()
        except RuntimeError as exc:
            self.say(str(exc), warning=True)

    def refresh(self) -> None:
        """Show the run's status; Start is enabled only when it is not running (any thread)."""
        with self._lock:
            if self.closed:
                return
            status = self.run.status
            # From the status, not from the thread: the owner thread reports "finished" while it is still alive.
            active = status.startswith(("starting", "running", "paused"))  # paused: while no page shows it
            self.start.disabled = active
            self.stop.disabled = not active
            self.say(f"/{self.run.node_name}: {status}", warning=status.startswith("failed"))

"""A meshcat page to draw in by hand (notebook 00's first scene): live in a widget, a still copy once it closes.

:class:`MeshcatPage` gives a ``meshcat.Visualizer`` whose every command goes both
to a :class:`tutorial.view.widget.widget.MeshcatWidget` and to a recording
(:class:`tutorial.notebook.replay.ViewRecording`), so that when the page closes
(``reset()``) the output keeps the scene as it was.  A run's own view is
:class:`tutorial.notebook.views.LiveView`.
"""

from __future__ import annotations

import html

from tutorial.notebook import replay, session


class MeshcatPage:
    """A meshcat page to draw in by hand, shown inline; a still picture of it stays after it closes.

    ``vis`` is a ``meshcat.Visualizer`` that draws both into the live page (a
    :class:`tutorial.view.widget.widget.MeshcatWidget`) and into a recording,
    so :meth:`close` can leave the scene as it was.  Owned by the kernel thread.
    """

    def __init__(self, label: str = "meshcat page", height: int = 350):
        import meshcat

        from tutorial.view.widget.widget import MeshcatWidget

        self.label = label
        self.height = height
        self.widget = MeshcatWidget(label, height)
        self.recording = replay.ViewRecording()
        self.vis = meshcat.Visualizer(window=_Tee(self.widget.window(), self.recording))
        self.closed = False
        self._handle = None
        session.register(self)

    def show(self) -> None:
        """Display the live page, with a caption, in this cell's output."""
        from IPython.display import HTML, display

        self._handle = display(self.widget, display_id=True)  # its caption says "(live)"
        self._caption = display(HTML(""), display_id=True)  # says "a saved copy" once it has closed

    def close(self) -> None:
        """Leave a still copy of the scene in the output, then close the widget (kernel thread)."""
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
        self.widget.close()


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

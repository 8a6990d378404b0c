"""The App of a program on its own, ``rtt-run``: what the lessons' App leaves to the tooling.

:class:`tutorial.app.app.App` is what the notebooks open: it draws in the
view it is given and refuses a model it would need ROS to build.  A
program in a terminal has no notebook around it, so :class:`StandaloneApp`
adds the two things the lessons never import:

- **a meshcat server of its own** for the view (:mod:`tutorial.tools.standalone.meshcat_server`),
  its page also offered through Jupyter's port when it runs under Jupyter;
- **robots from ROS**: a model taken from a robot description topic
  (:func:`tutorial.tools.standalone.descriptions.receive_descriptions`, the URDF tools),
  and a root link placed where an odometry topic says
  (:class:`tutorial.tools.standalone.floating_base.FloatingBase`, attached as ``attach``
  entries are: configured before the project's own controllers).
"""

from __future__ import annotations

from tutorial.app.app import App
from tutorial.core.project import Project
from tutorial.tools.standalone.descriptions import DESCRIPTION_TIMEOUT, receive_descriptions


class StandaloneApp(App):
    """An :class:`App` with a meshcat server of its own, that also runs robots drawn from ROS.

    Args:
        description_timeout: how long :meth:`open` waits for each robot
            description, s (:data:`tutorial.tools.standalone.descriptions.DESCRIPTION_TIMEOUT`).
        **kwargs: :class:`App`'s.

    Same threads as :class:`App`.
    """

    def __init__(self, project: Project, *, description_timeout: float = DESCRIPTION_TIMEOUT, **kwargs):
        super().__init__(project, **kwargs)
        self.description_timeout = description_timeout

    def prepare_project(self, project: Project) -> Project:
        """``project`` with its description models received, and a floating base attached to each model that
        names an odometry topic (owner thread, in :meth:`open`).

        Raises:
            tutorial.interfaces.robot_description.DescriptionError: a description did not come in time.
            KeyboardInterrupt: the App was asked to stop while it waited.
        """
        project = receive_descriptions(
            project, self.node, self.description_timeout, self.output, stopped=lambda: self.stop_requested
        )
        for entry in project.models:
            if entry.odometry is not None:  # its root link placed where the robot's odometry says
                from tutorial.tools.standalone.floating_base import FloatingBase

                self.attach.append((entry.name, f"{entry.name}/floating_base", FloatingBase(entry.odometry)))
        return project

    def frame_sink(self):
        """The fastest way this App's view takes a frame (owner thread): on its own meshcat server, the frame as
        one ``set_transforms`` command (:func:`tutorial.tools.standalone.sinks.frame_sink`)."""
        from tutorial.tools.standalone.sinks import frame_sink

        return frame_sink(self.vis)

    def open_visualizer(self):
        """A meshcat server of this App's own (closed with it), and its ``Visualizer`` (owner thread)."""
        from tutorial.tools.standalone.meshcat_server import start_server

        self.server = start_server()
        return self.server.visualizer()

    def view_address(self) -> tuple[str, str | None]:
        """Its own server's page, and the same page through Jupyter's port when it runs under Jupyter; a view it
        was given (a test's) is not a page of a server."""
        if self.server is None:
            return super().view_address()
        from tutorial.tools.standalone.meshcat_server import through_jupyter

        return self.server.web_url, through_jupyter(self.server.web_url)

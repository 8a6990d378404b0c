"""A run's Start/Stop panel shows the run's newest status, whichever thread wrote last."""

from __future__ import annotations

import threading

import pytest

from tutorial.notebook import panels
from tutorial.notebook.runs import BackgroundApp

pytestmark = pytest.mark.unit


def a_run(status: str) -> BackgroundApp:
    """A BackgroundApp with only what its status and panels need: no app, no view, no session."""
    run = BackgroundApp.__new__(BackgroundApp)
    run.node_name, run.status, run.view, run._panels = "rtt_viewer", status, None, []
    return run


def test_a_status_set_while_the_panel_is_made_is_the_one_it_shows(monkeypatch):
    """The owner thread sets "running" while the kernel thread draws the new panel's "starting" (the race
    that left a JupyterLab run's line at "starting" for good): the panel ends on "running"."""
    run = a_run("starting")
    assigned, errors = threading.Event(), []

    class View:  # the run's view: BackgroundApp._set_status tells it between setting the status and the panels
        def set_status(self, status):
            assigned.set()

    run.view = View()

    def owner():
        try:
            run._set_status("running")
        except BaseException as exc:  # noqa: BLE001 - asserted below
            errors.append(exc)

    say, thread = panels.Panel.say, threading.Thread(target=owner)

    def say_once_the_owner_moved(self, text, warning=False):
        if not thread.is_alive() and not assigned.is_set():  # the panel's first line: let the owner go now
            thread.start()
            assert assigned.wait(10), "the owner thread never set its status"
        say(self, text, warning)

    monkeypatch.setattr(panels.Panel, "say", say_once_the_owner_moved)
    panel = run.controls()
    thread.join(10)
    assert not thread.is_alive() and errors == []
    assert "/rtt_viewer: running" in panel.line.value, panel.line.value
    assert panel.start.disabled and not panel.stop.disabled


def test_a_closed_panel_stays_closed_when_a_late_status_arrives():
    run = a_run("running")
    panel = run.controls()
    panel.close("closed by reset()")
    run.status = "stopped at t = 1.00 s"
    panel.refresh()  # the owner thread's last status, after reset() closed the panel
    assert "closed by reset()" in panel.line.value and panel.start.disabled and panel.stop.disabled

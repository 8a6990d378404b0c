"""A run shown in a notebook pauses when no page has shown it for a while, and goes on when one does.

On a class's server a learner may close the page with a simulation running: it then costs nothing, and
loses nothing (simulated time stands still).  Pages are stood in for by the messages a view's page sends
(its hello, its answers to frames), handed to the widget as the kernel would.
"""

from __future__ import annotations

from tutorial.notebook import views
from tutorial.notebook.runs import BackgroundApp

from conftest import wait_until


def page_says(run: BackgroundApp, message: dict) -> None:
    run.view.widget._on_message(None, message, [])  # what the kernel's thread does with a page's message


def test_a_run_no_page_shows_pauses_and_goes_on_when_one_does(ros, monkeypatch):
    monkeypatch.setattr(views, "UNWATCHED", 0.5)  # s: a class's server waits 30
    run = BackgroundApp("step2.yaml", node_name="rtt_unwatched", label="simulation /rtt_unwatched").start()
    try:
        assert run.wait_started(30), run.error
        assert wait_until(lambda: run.sim_time() > 0.2, 10)
        # Never shown by a page (a notebook run without a browser, as tests and nbval run them): never paused.
        assert not wait_until(lambda: run.app.sim.paused, 1.5)
        page_says(run, {"type": "hello", "id": "page-1"})  # a page shows it, then goes away
        # the status is set by the run's thread just after it paused the simulation: wait for the status
        assert wait_until(lambda: run.status.startswith("paused at t = "), 10), run.status
        assert run.app.sim.paused and "no page showed this view for 0 s" in run.status, run.status
        held = run.sim_time()
        assert not wait_until(lambda: run.sim_time() != held, 1.0), "simulated time went on while paused"
        page_says(run, {"type": "here"})  # a page again (a view on a visible page says so every 10 s)
        assert wait_until(lambda: run.status.startswith(f"running (paused at t = {held:.2f} s for "), 10), run.status
        assert wait_until(lambda: not run.app.sim.paused and run.sim_time() > held + 0.1, 10), run.status
    finally:
        run.close()
    assert run.summary is not None and run.summary.get("error") is None, run.summary

"""A notebook's recording in a real browser: lighter without a GPU, and drawn only while in sight."""

from __future__ import annotations

import mujoco
import pytest

from tutorial.core.world import ModelEntry, build_world
from tutorial.notebook import replay

from browser import chromium, messages_after_one
from conftest import MODEL

pytestmark = [
    pytest.mark.browser,
    pytest.mark.skipif(chromium() is None, reason="chromium is not installed (make test installs it)"),
]


def recording_page() -> str:
    """A notebook output as the notebooks show it: one recording of the tank driving, in an iframe, then
    enough page below it to scroll it out of sight."""
    model = build_world([ModelEntry("Tank", str(MODEL / "tank.xml"))])
    data = mujoco.MjData(model)
    frames = []
    for k in range(30):
        data.qpos[0] = 0.02 * k
        frames.append(data.qpos.copy())
    page = replay.page_html([replay.record_replay(model, frames, 30.0)], ["the tank"])
    return "<body style='margin: 0'>" + replay.iframe_html(page, 380) + "<div style='height: 3000px'></div></body>"


def frames_drawn(frame, seconds: float) -> int:
    """How many times the recording's viewer drew in ``seconds`` s (three.js counts its renders)."""
    before = frame.evaluate("rttViewers[0].renderer.info.render.frame")
    frame.page.wait_for_timeout(seconds * 1000)  # a window to count in; the page runs meanwhile
    return frame.evaluate("rttViewers[0].renderer.info.render.frame") - before


def test_a_recording_is_lighter_without_a_gpu_and_drawn_only_in_sight():
    from jupyterlab import browser

    with browser(800, 600) as page:
        page.set_content(recording_page())
        page.wait_for_function("document.querySelector('iframe').contentWindow.rttViewers !== undefined")
        frame = page.frames[1]
        chosen = frame.evaluate("rttPage")
        assert "SwiftShader" in chosen["renderer"]  # this machine has no GPU: Chromium rasterizes on the CPU
        assert chosen["software"] is True and chosen["antialias"] is False and chosen["detail"] == "low"
        assert frame.evaluate("rttViewers[0].renderer.getContext().getContextAttributes().antialias") is False
        segments = frame.evaluate(
            """(() => { const counts = [];
                rttViewers[0].scene.traverse(o => {
                    const g = o.isMesh ? o.geometry : {};
                    if (g.type === 'CylinderGeometry') counts.push(g.parameters.radialSegments);
                });
                return counts; })()"""
        )
        assert segments and set(segments) == {16}  # meshcat's 50, capped: the tank's turret, wheels, track ends
        assert messages_after_one(frame) == 1  # meshcat's bundled GIF worker does not answer it
        assert frames_drawn(frame, 0.7) > 5  # in sight, the animation plays (60 a second when it can)
        page.evaluate("window.scrollTo(0, 2000)")
        page.wait_for_timeout(300)  # the observer is told after the page's next frame
        assert frames_drawn(frame, 0.7) == 0  # out of sight: nothing drawn
        page.evaluate("window.scrollTo(0, 0)")
        page.wait_for_timeout(300)
        assert frames_drawn(frame, 0.7) > 5  # back in sight: it plays again

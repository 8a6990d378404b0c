"""Record the book's interactive 3D snapshots: ``python book/make_snapshots.py``.

Runs the Step 2 project with the demo script (deterministic, by simulated
time) and writes two self-contained meshcat pages with a looping animation
into ``book/_static/snapshots/``: the whole simulated world, and the tank
alone as the Step 3 viewer poses it from joint states.
"""

from __future__ import annotations

import sys
from pathlib import Path

BOOK = Path(__file__).resolve().parent
sys.path.insert(0, str(BOOK.parent))

import mujoco  # noqa: E402

from tutorial import notebook as nb  # noqa: E402
from tutorial.project import load_project  # noqa: E402
from tutorial.world import build_world  # noqa: E402

FPS = 30.0


def main() -> int:
    out = BOOK / "_static" / "snapshots"
    out.mkdir(parents=True, exist_ok=True)
    summary, app, recorder = nb.run_project("step2.yaml", duration=6.0, fps=FPS)
    world_html = nb.animation_html(app.model, recorder.times, recorder.frames, FPS,
                                   camera=([-2.4, -2.6, 2.4], [1.0, 0.3, 0.0]))
    (out / "step1_drive.html").write_text(world_html)

    # The viewer's model: the tank alone, its joints set from the recorded joint states.
    viewer_model = build_world(load_project(nb.PROJECT / "step3.yaml").models)
    viewer_data = mujoco.MjData(viewer_model)
    from tutorial.body import Body

    sim_tank, viewer_tank = app.bodies["Tank"], Body(viewer_model, viewer_data, "Tank")
    frames = []
    for q in recorder.frames:
        for joint in viewer_tank.joint_infos:
            viewer_data.qpos[joint.qpos_adr] = q[sim_tank.joint(joint.name).info.qpos_adr]
        frames.append(viewer_data.qpos.copy())
    viewer_html = nb.animation_html(viewer_model, recorder.times, frames, FPS, camera=([-1.1, -1.2, 0.8], [0, 0, 0.1]))
    (out / "step3_viewer.html").write_text(viewer_html)
    print(f"wrote {len(recorder.frames)} frames to {out}/step1_drive.html and step3_viewer.html")
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""``rtt-run``'s summary with two tanks: each body's controllers are kept, not the last one's only."""

from __future__ import annotations

import pytest

from conftest import MODEL

pytestmark = pytest.mark.ros

TWO_TANKS = f"""
name: two_tanks
models:
  - name: Tank
    file: {MODEL / "tank.xml"}
    controllers:
      - name: RttJointStatePublisher
        class: tutorial.controllers.joint_state_publisher:RttJointStatePublisher
  - name: Tank2
    file: {MODEL / "tank.xml"}
    position: [1.0, 1.0, 0.0]
    controllers:
      - name: RttJointStatePublisher
        class: tutorial.controllers.joint_state_publisher:RttJointStatePublisher
      - name: RttTankController
        class: tutorial.controllers.tank_controller:RttTankController
simulator:
  time_step: 0.001
"""


def test_two_bodies_with_the_same_controller_name_both_report(ros, tmp_path):
    from tutorial.app.app import App
    from tutorial.core.project import load_project

    path = tmp_path / "two.yaml"
    path.write_text(TWO_TANKS)
    app = App(
        load_project(path),
        node_name="summary_test",
        headless=True,
        realtime_sync=False,
        duration=0.1,
        output=lambda record: None,
    )
    try:
        app.open()
        app.run()
    finally:
        app.close()
    controllers = app.summary()["controllers"]
    # Before, one "RttJointStatePublisher" entry: Tank2's, Tank's lost.  A name only one body has stays plain.
    assert set(controllers) == {"Tank/RttJointStatePublisher", "Tank2/RttJointStatePublisher", "RttTankController"}
    assert controllers["Tank/RttJointStatePublisher"]["topic"] == "/Tank/joint_state"
    assert controllers["Tank2/RttJointStatePublisher"]["topic"] == "/Tank2/joint_state"

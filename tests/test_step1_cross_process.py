"""Step 1 across real processes: rtt-joy --demo drives rtt-run project/step1.yaml over /joy."""

import pytest

from conftest import module_command


@pytest.mark.more  # make test: a hub learner's demo joystick drives their Step 2 tank across processes (test_hub)
def test_demo_joy_drives_the_simulated_tank(procs):
    joy = procs(module_command("tutorial.tools.rtt_joy", "--demo", "--duration", "15"))
    joy.wait_for_line(lambda line: "publishing /joy" in line, timeout=30)
    sim = procs(
        module_command("tutorial.tools.rtt_run", "project/step1.yaml", "--headless", "--duration", "8", "--json")
    )
    assert sim.wait(60) == 0, sim.err
    summary = sim.summary()
    tank = summary["bodies"]["Tank"]
    x, y, _ = tank["root_position"]
    assert summary["simulated_time"] == 8.0
    assert summary["controllers"]["RttTankController"]["joy_received"] > 10
    assert (x * x + y * y) ** 0.5 >= 0.5, tank
    assert abs(tank["joint_positions"]["TURRET_Y"]) > 0.1, tank

"""The notebooks' exercise checks: they pass the worked solutions and fail wrong answers, saying which input failed.

The solutions, the learners' empty stubs and the check calls are read from
the notebooks themselves, so these tests check what a learner sees.  Each
wrong answer is the worked solution with one mistake a learner could make
put in (the replaced text must be found, so an edited notebook cannot make
a wrong answer silently equal the solution); its check must fail, on the
case that catches that mistake, with a message naming the input.
"""

from __future__ import annotations

import json
import re

import pytest

from conftest import ROOT

MODULES = {"01": "tank_controller", "02": "joint_state_publisher", "03": "joint_state_subscriber"}


def exercise(number: str) -> dict:
    """The stub, check call and solution of exercise ``number`` ("1.2"), from its notebook."""
    step = f"{int(number.split('.')[0]):02d}"
    path = next((ROOT / "notebooks").glob(f"{step}_*.ipynb"))
    cells = ["".join(c["source"]) for c in json.loads(path.read_text())["cells"] if c["cell_type"] == "code"]
    i = next(k for k, src in enumerate(cells) if src.startswith(f"# Worked solution to Exercise {number}."))
    check, stub, solution = cells[i - 1], cells[i - 2], cells[i]
    call = re.search(r"^(check_\w+)\((\w+)\)\s*$", check, re.M)
    assert call, check
    return {"stub": stub, "solution": solution, "check": call.group(1), "target": call.group(2),
            "module": MODULES[step], "step": int(step)}


def grade(ex: dict, *sources: str):
    """Run ``sources`` (the stub, then maybe a solution) as the notebook would, then the check; its Result."""
    import importlib

    namespace: dict = {}
    exec(f"from tutorial.controllers.{ex['module']} import *", namespace)  # the cells notebook N exports
    for source in sources:
        # The cell's own check call is left out: the test makes it, to see its Result.
        source = re.sub(rf"^{ex['check']}\({ex['target']}\)\s*$", "", source, flags=re.M)
        exec(compile(source, f"<exercise {ex['target']}>", "exec"), namespace)
    check = getattr(importlib.import_module(f"tutorial.exercises.step{ex['step']}"), ex["check"])
    return check(namespace[ex["target"]])


EXERCISES = ["1.1", "1.2", "2.1", "2.2", "3.1", "3.2"]


@pytest.mark.parametrize("number", EXERCISES)
def test_the_worked_solution_passes(ros, number):
    ex = exercise(number)
    result = grade(ex, ex["stub"], ex["solution"])
    assert result.passed, str(result)
    assert str(result).startswith(f"\u2713 Exercise {number}")


@pytest.mark.parametrize("number", EXERCISES)
def test_the_empty_stub_fails_as_not_done(ros, number):
    result = grade(exercise(number), exercise(number)["stub"])
    assert not result.passed
    assert str(result).startswith(f"\u2717 Exercise {number}")
    assert "not done yet" in result.message and "NotImplementedError" in result.message


# (exercise, text of the solution, the mistake put in its place, the case that must catch it)
MISTAKES = [
    ("1.1", "return forward - turn_left, forward + turn_left", "return forward + turn_left, forward - turn_left",
     "(left)"),
    ("1.1", "forward = DPAD_SPEED * joy.axis(axes, joy.DPAD_V)", "forward = DPAD_SPEED * axes[joy.DPAD_V]",
     "(a Joy with only 4 axes)"),
    ("1.1", "turn_left = DPAD_TURN * joy.axis(axes, joy.DPAD_H)", "turn_left = DPAD_TURN * joy.axis(axes, 0)",
     "(left)"),
    ("1.2", "if down and not self.a_down:", "if down:", "(A held for 10 repeats, then released)"),
    ("1.2", "down = len(buttons) > joy.BUTTON_A and buttons[joy.BUTTON_A] == 1", "down = buttons[0] == 1",
     "(a Joy with no buttons between two presses)"),
    ("1.2", "        super().on_joy(msg)  # store the sticks, as before\n        buttons", "        buttons",
     "(a Joy with the left stick up)"),
    ("2.1", "joints = [io.body.joint(name).info for name in self.selected]",
     "joints = [j for j in io.body.joint_infos if j.name in self.selected]", "joints='TURRET_P,TURRET_Y'"),
    ("2.1", "        if unknown:\n", "        if False:\n", "joints='GUN'"),
    ("2.1", "self.addresses = [(i, j.qpos_adr, j.dof_adr) for i, j in enumerate(joints)]",
     "self.addresses = self.addresses[:n]", "joints='TURRET_P,TURRET_Y'"),
    ("2.2", "o.x, o.y, o.z, o.w = float(qx), float(qy), float(qz), float(w)",
     "o.w, o.x, o.y, o.z = float(qx), float(qy), float(qz), float(w)", "the root's orientation"),
    ("2.2", 'self.msg.header.frame_id = "world"', "pass", "the root's position, frame world"),
    ("2.2", "if self.accumulator.tick():", "if True:", "10 Hz from t = 0"),
    ("3.1", "if not names or not names <= ours:", "if not names & ours:",
     "(one of the tank's joints and one unknown)"),
    ("3.1", "            return None\n", "", "(the crane's message)"),
    ("3.1", "if not names or not names <= ours:", "if names and not names <= ours:", "(an empty message)"),
    ("3.2", "if joint is None or copies[name] > 1 or not math.isfinite(q):",
     "if joint is None or not math.isfinite(q):", "(duplicate name)"),
    ("3.2", 'tolerance = 0.01 if joint.kind == "slide" else 0.05', "tolerance = 0.0", "(past the limit a little)"),
    ("3.2", "        if joint.limited and not low <= q <= high:\n            continue\n",
     "        if joint.limited:\n            q = min(max(q, joint.lower), joint.upper)\n", "(huge)"),
]


@pytest.mark.parametrize("number,right,wrong,caught_by", MISTAKES,
                         ids=[f"{m[0]}-{k}" for k, m in enumerate(MISTAKES)])
def test_a_wrong_answer_fails_naming_the_input(ros, number, right, wrong, caught_by):
    ex = exercise(number)
    assert right in ex["solution"], f"the solution of {number} no longer has {right!r}: update this test"
    result = grade(ex, ex["stub"], ex["solution"].replace(right, wrong))
    assert not result.passed, f"the check of {number} passed a wrong answer ({wrong!r})"
    assert caught_by in result.case, (caught_by, str(result))
    assert result.case in result.message, str(result)  # the failing input is in the line
    assert "not done yet" not in result.message

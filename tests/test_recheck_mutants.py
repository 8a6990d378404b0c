"""scripts/recheck_mutants.py reads a mutant's change as mutmut shows it, and finds the module it is in."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.unit

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts"))
import recheck_mutants  # noqa: E402

SHOWN = """# tutorial.exercises.step5_imu_viewer.x__judge__mutmut_5: survived
--- tutorial/exercises/step5_imu_viewer.py
+++ tutorial/exercises/step5_imu_viewer.py
@@ -1,3 +1,3 @@
 def _judge(newest, stamp, kind):
-    if newest - RESTART * 1e9 <= stamp:
+    if newest - RESTART * 1000000001.0 <= stamp:
         return "out_of_order", newest
"""


def fake_mutmut(tmp_path: Path, shown: str) -> Path:
    bin_dir = tmp_path / ".venv" / "bin"
    bin_dir.mkdir(parents=True)
    (tmp_path / "shown.txt").write_text(shown)
    script = bin_dir / "mutmut"
    script.write_text(f"#!/bin/sh\ncat {tmp_path / 'shown.txt'}\n")
    script.chmod(0o755)
    return tmp_path


def test_a_mutants_change_is_the_function_before_and_after(tmp_path):
    before, after = recheck_mutants.mutant_change(fake_mutmut(tmp_path, SHOWN), "any")
    assert before == (
        "def _judge(newest, stamp, kind):\n    if newest - RESTART * 1e9 <= stamp:\n"
        '        return "out_of_order", newest'
    )
    assert after == before.replace("1e9", "1000000001.0")


def test_no_diff_shown_is_no_change(tmp_path):
    assert recheck_mutants.mutant_change(fake_mutmut(tmp_path, "nothing here\n"), "any") is None


@pytest.mark.parametrize(
    "name, path",
    [
        ("tutorial.exercises.step5_imu_viewer.x__judge__mutmut_5", "tutorial/exercises/step5_imu_viewer.py"),
        ("tutorial.exercises.camera_rig.xǁRigǁ__init____mutmut_3", "tutorial/exercises/camera_rig.py"),
    ],
)
def test_the_module_of_a_mutant_is_found_by_its_name(name, path):
    assert recheck_mutants.module_path(name) == path

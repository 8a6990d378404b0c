"""The environment is exactly uv.lock: what a clean clone's ``make`` installs is what the tests ran with."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.unit

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))

import lock_diff  # noqa: E402


def test_every_installed_package_is_the_locked_version():
    assert lock_diff.differences() == []


def test_the_lock_holds_what_the_notebooks_numbers_depend_on():
    locked, installed = lock_diff.locked_versions(), lock_diff.installed_versions()
    for name in ("mujoco", "numpy", "ros-jazzy-rclpy", "meshcat", "jupyterlab"):
        assert installed[name] in locked[name], (name, installed[name], locked[name])


def test_a_changed_version_is_reported(tmp_path, monkeypatch):
    fake = {"mujoco": "0.0.1", "numpy": next(iter(lock_diff.locked_versions()["numpy"])), "left-pad": "1.0"}
    monkeypatch.setattr(lock_diff, "installed_versions", lambda python=None: fake)
    assert lock_diff.differences() == [
        "left-pad 1.0: not in uv.lock",
        f"mujoco 0.0.1: uv.lock has {next(iter(lock_diff.locked_versions()['mujoco']))}",
    ]

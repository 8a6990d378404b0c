"""The environment is exactly uv.lock: what a clean clone's ``make`` installs is what the tests ran with."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.unit

ROOT = Path(__file__).resolve().parent.parent
UV = Path(sys.executable).with_name("uv")
sys.path.insert(0, str(ROOT / "scripts"))

import lock_diff  # noqa: E402


def test_every_installed_package_is_the_locked_version():
    assert lock_diff.differences() == []


def test_uv_finds_nothing_to_change():
    """uv's own check: the lock matches pyproject.toml (--locked) and the environment matches the lock."""
    if Path(sys.prefix).resolve() != (ROOT / ".venv").resolve():
        pytest.skip(f"not the project's .venv: {sys.prefix}")  # make test-latest's .venv-latest differs on purpose
    run = subprocess.run(
        [str(UV), "sync", "--locked", "--inexact", "--all-extras", "--check", "--offline", "--python", sys.executable],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 0, run.stdout + run.stderr


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

"""Which installed packages differ from uv.lock: ``python scripts/lock_diff.py [PYTHON]``.

Prints one line per package whose installed version is not the locked one
(or that the lock does not hold), for the environment of the interpreter
PYTHON (this one by default).  ``make test-latest`` runs it to say what an
upgrade would change; exit status 0 either way.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


# The project itself, and what pip freeze leaves out too: the installers a venv starts with.
NOT_COMPARED = {"ros-tank-tutorial", "pip", "setuptools", "wheel"}


def normalize(name: str) -> str:
    return name.lower().replace("_", "-").replace(".", "-")


def locked_versions(lock: Path = ROOT / "uv.lock") -> dict[str, set[str]]:
    """``{package: its locked versions}`` (a package may be locked at two versions for two platforms)."""
    data = tomllib.loads(lock.read_text(encoding="utf-8"))
    out: dict[str, set[str]] = {}
    for package in data["package"]:
        if "version" in package and package.get("source", {}).get("editable") is None:
            out.setdefault(normalize(package["name"]), set()).add(package["version"])
    return out


def installed_versions(python: str = sys.executable) -> dict[str, str]:
    """``{package: version}`` of every distribution an installer (uv, pip) installed for ``python``.

    A distribution without an ``INSTALLER`` record came inside another's
    files: the ROS 2 wheels carry the metadata of the ROS packages they hold
    (``ros-jazzy-rclpy`` brings ``rclpy``), which no installer chose.
    """
    code = (
        "import importlib.metadata as m, json; "
        "print(json.dumps({d.metadata['Name']: d.version for d in m.distributions() if d.read_text('INSTALLER')}))"
    )
    found = json.loads(subprocess.run([python, "-c", code], capture_output=True, text=True, check=True).stdout)
    return {normalize(k): v for k, v in found.items()}


def differences(python: str = sys.executable) -> list[str]:
    locked, installed = locked_versions(), installed_versions(python)
    lines = []
    for name, version in sorted(installed.items()):
        if name in NOT_COMPARED:
            continue
        if name not in locked:
            lines.append(f"{name} {version}: not in uv.lock")
        elif version not in locked[name]:
            lines.append(f"{name} {version}: uv.lock has {', '.join(sorted(locked[name]))}")
    return lines


def main() -> int:
    python = sys.argv[1] if len(sys.argv) > 1 else sys.executable
    lines = differences(python)
    print(f"{len(lines)} installed packages differ from uv.lock" + (":" if lines else ""))
    for line in lines:
        print("  " + line)
    return 0


if __name__ == "__main__":
    sys.exit(main())

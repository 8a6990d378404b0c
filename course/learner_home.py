"""A learner's home folder, as a class gives it: their own copies of the notebooks and the project's files.

    python course/learner_home.py HOME [--show-solutions]

Used by the hub before a learner's server starts (``course/jupyterhub_config.py``) and by the learner image's
build (``course/containers/Containerfile``).  Made once: a learner's work is never overwritten.

- ``project/``, ``model/`` and ``launch_py/``: what the notebooks' "Outside Jupyter" sections run from a
  terminal in the home folder (``rtt-run project/step1.yaml``, ...);
- ``notebooks/``: the lessons, their folded worked solutions held back as in the graded assignments (unless
  ``show_solutions``: a workshop that grades nothing), and trusted in the learner's own Jupyter so that
  their recorded 3D views run (JupyterLab runs no script of an untrusted output; a signature is of the
  notebook's content, not its path, and is kept in the learner's ``~/.local``).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))

from assignments import learner_notebook  # noqa: E402 - course/ is on the path only from here

COPIED = ("project", "model", "launch_py")


def close_home(home: Path) -> bool:
    """``home`` readable by its owner alone (mode 700; ``useradd`` makes homes 755 where ``UMASK`` is 022), so
    that no learner reads another's answers or feedback; whether it changed.  Raises ``OSError`` when ``home``
    cannot be changed.  Any thread."""
    mode = home.stat().st_mode & 0o777
    if mode & 0o077:
        os.chmod(home, mode & 0o700)
    return bool(mode & 0o077)


def make_learner_home(
    home: Path, show_solutions: bool = False, jupyter: Path | None = None, give=lambda path: None
) -> list[Path]:
    """Copy what is missing into ``home``; the folders made.

    ``jupyter``: the ``jupyter`` program that trusts the notebooks, run with ``HOME=home`` (default: the one
    beside this Python).  ``give(path)`` is called on each folder as soon as it is made (the hub gives it to
    the learner), so a copy that fails later leaves nothing made that is not theirs.  Raises ``OSError`` when
    ``home`` cannot be written.  Any thread.
    """
    made = []
    for folder in COPIED:
        if not (home / folder).exists():
            shutil.copytree(ROOT / folder, home / folder, ignore=shutil.ignore_patterns("__pycache__"))
            give(home / folder)
            made.append(home / folder)
    target = home / "notebooks"
    if target.exists():
        return made
    # Made whole beside it, then renamed into place: a copy that fails halfway leaves nothing that the next
    # attempt would take as made (with the worked solutions still in it).
    making = home / ".notebooks-being-made"
    shutil.rmtree(making, ignore_errors=True)
    shutil.copytree(ROOT / "notebooks", making, ignore=shutil.ignore_patterns(".*", "*.cfg", "*.toml"))
    if not show_solutions:
        for path in making.glob("*.ipynb"):
            notebook = json.loads(path.read_text(encoding="utf-8"))
            path.write_text(json.dumps(learner_notebook(notebook), indent=1) + "\n", encoding="utf-8")
    jupyter = jupyter or Path(sys.executable).with_name("jupyter")
    subprocess.run(
        [str(jupyter), "trust", *map(str, sorted(making.glob("*.ipynb")))],
        env={"HOME": str(home), "PATH": os.environ.get("PATH", "/usr/bin:/bin")},
        capture_output=True,
        timeout=120,
        check=False,
    )
    give(making)
    making.rename(target)
    made.append(target)
    if (home / ".local").exists():
        give(home / ".local")
        made.append(home / ".local")
    return made


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("home", type=Path)
    parser.add_argument("--show-solutions", action="store_true", help="keep the folded worked solutions")
    args = parser.parse_args(argv)
    for path in make_learner_home(args.home, args.show_solutions):
        print(f"made {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

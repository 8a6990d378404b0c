"""Run notebooks top to bottom and save them with their outputs: the outputs nbval checks.

    python scripts/run_notebooks.py                        # every notebook (make run-notebooks)
    python scripts/run_notebooks.py notebooks/01_*.ipynb   # some

Each notebook runs in a fresh kernel, in ``notebooks/``, the way the test
suite runs it: ``RTT_TEST_MODE=1`` (shorter live runs), localhost-only ROS 2
discovery and a ROS domain of its own.  nbclient saves the outputs and the
widget state (so panels render from a saved notebook) and applies every
display update, so a live view's saved output is the recording it left.
A notebook that raises is not saved, and the script exits 1.
"""

from __future__ import annotations

import argparse
import os
import random
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def run(path: Path, timeout: float) -> float:
    """Execute one notebook in place; its run time, s.

    Raises:
        nbclient.exceptions.CellExecutionError: a cell raised (the notebook is left as it was).
    """
    import nbformat
    from jupyter_client.kernelspec import KernelSpecManager
    from nbclient import NotebookClient

    nb = nbformat.read(path, as_version=4)
    start = time.monotonic()
    NotebookClient(
        nb,
        timeout=timeout,
        kernel_name="python3",
        resources={"metadata": {"path": str(path.parent)}},
        # No output is a widget once its section is reset (tests/test_notebook_export.py): their state
        # would be dead weight.
        store_widget_state=False,
    ).execute()
    nb.metadata.pop("widgets", None)
    # The kernel's own name for itself: JupyterLab writes it on opening, and a notebook saved with another
    # opens marked as changed.
    nb.metadata["kernelspec"]["display_name"] = KernelSpecManager().get_kernel_spec("python3").display_name
    nbformat.write(nb, path)
    return time.monotonic() - start


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("notebooks", nargs="*", type=Path, help="default: notebooks/[0-9][0-9]_*.ipynb")
    parser.add_argument("--timeout", type=float, default=600, help="per cell, s")
    args = parser.parse_args(argv)
    os.environ["RTT_TEST_MODE"] = "1"
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    os.environ.setdefault("ROS_DOMAIN_ID", str(random.randint(1, 100)))
    paths = args.notebooks or sorted((ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb"))
    failed = 0
    for path in paths:
        try:
            print(f"{path.name}: {run(path.resolve(), args.timeout):.1f} s", flush=True)
        except Exception as exc:  # noqa: BLE001 - report, go on with the others
            failed += 1
            print(f"{path.name}: FAILED\n{exc}", file=sys.stderr, flush=True)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())

"""``make bench-figures``: put a run's plots in the book, the one way the book's figures change.

    python -m benchmarks.publish [RUN_DIR]      # default benchmarks/results (what make bench wrote last)

Copies ``bench_scale.png``, ``bench_latency.png`` and ``bench_browser.png``
from the run's folder into ``book/_static/`` and prints which run they come
from (its time and commit, as the plots' titles also say): the captions in
``book/benchmarks.md`` must name that run.  ``make bench`` itself never
writes into the book.
"""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path

from benchmarks.paths import BOOK_STATIC, RESULTS

PLOTS = ("bench_scale.png", "bench_latency.png", "bench_browser.png")


def publish(run_dir: Path = RESULTS, book_static: Path = BOOK_STATIC) -> str:
    """Copy the run's plots into ``book_static``; returns ``"<when>, commit <commit>"`` of the run.

    Raises:
        FileNotFoundError: the folder has no ``latest.json`` or lacks one of the plots.
    """
    run = json.loads((run_dir / "latest.json").read_text())
    missing = [name for name in PLOTS if not (run_dir / name).is_file()]
    if missing:
        raise FileNotFoundError(f"{run_dir} has no {', '.join(missing)}: run make bench first")
    for name in PLOTS:
        shutil.copyfile(run_dir / name, book_static / name)
    return f"{run['when']}, commit {run.get('commit', 'unknown')}"


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    run_dir = Path(argv[0]) if argv else RESULTS
    try:
        which = publish(run_dir)
    except FileNotFoundError as exc:
        print(f"bench-figures: {exc}", file=sys.stderr)
        return 2
    print(f"book/_static/{{{','.join(PLOTS)}}} now show the run of {which}: name it in their captions")
    return 0


if __name__ == "__main__":
    sys.exit(main())

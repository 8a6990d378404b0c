"""Where the benchmarks read and write: the repository, the results folder, the book's figures."""

from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "benchmarks" / "results"  # latest.json, targets.md (git-ignored)
BOOK_STATIC = ROOT / "book" / "_static"  # the book's plots: only make bench-figures writes them

"""``make mutate``'s report: how many of mutmut's mutants the tests caught, module by module, and every survivor.

    python scripts/mutation_report.py [--write book/_static/mutation.json]

Reads mutmut's results (``mutmut results --all true``, after ``mutmut run``)
and ``tests/equivalent_mutants.toml``: the survivors that cannot be caught,
each with why (the mutant behaves as the original does).  A mutant is
*caught* when a test failed on it (killed) or it made the tests hang past
mutmut's timeout.  The score is caught / (mutants - equivalent ones); every
survivor is printed, with its reason or "no reason: a test is missing".

Exit status: 0 when the score is at least 90 % and every survivor has a
reason; else 1.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tomllib
from collections import Counter, defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
EQUIVALENT = ROOT / "tests" / "equivalent_mutants.toml"
TARGET = 0.90
CAUGHT = ("killed", "timeout")


def results() -> dict[str, str]:
    """mutant name -> mutmut's status ("killed", "survived", "timeout", "no tests", ...)."""
    out = subprocess.run(
        [str(Path(sys.executable).with_name("mutmut")), "results", "--all", "true"],
        cwd=ROOT, capture_output=True, text=True, check=True,
    )  # fmt: skip
    found = {}
    for line in out.stdout.splitlines():
        name, sep, status = line.strip().rpartition(": ")
        if sep and name:
            found[name] = status
    if not found:
        raise SystemExit("mutate: mutmut has no results: run `make mutate` (mutmut run) first")
    return found


def module(name: str) -> str:
    """``tutorial.core.call_later.xǁMainLoopǁrun_once__mutmut_9`` -> ``tutorial.core.call_later``."""
    head = name.split("__mutmut_")[0]
    parts = head.split(".")
    return ".".join(p for p in parts[:-1]) if parts[-1].startswith(("x_", "xǁ")) else head


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--write", help="also write the figures as JSON here")
    args = p.parse_args(argv)
    status = results()
    equivalent = tomllib.loads(EQUIVALENT.read_text()) if EQUIVALENT.exists() else {}
    mutated = {module(n) for n in status}
    unknown = sorted(n for n in set(equivalent) - set(status) if module(n) in mutated)  # of another run: not stale
    unchecked = [n for n, s in status.items() if s == "not checked"]  # a run stopped, or a sample's (mutate_seal.py)
    status = {n: s for n, s in status.items() if s != "not checked"}
    by_module: dict[str, Counter] = defaultdict(Counter)
    for name, s in status.items():
        by_module[module(name)][s] += 1
    print(f"{'module':45s} {'mutants':>8s} {'caught':>7s} {'survived':>9s} {'no tests':>9s}")
    for mod in sorted(by_module):
        c = by_module[mod]
        caught = sum(c[k] for k in CAUGHT)
        print(f"{mod:45s} {sum(c.values()):8d} {caught:7d} {c['survived']:9d} {c['no tests']:9d}")
    total = len(status)
    caught = sum(1 for s in status.values() if s in CAUGHT)
    left = {n: s for n, s in status.items() if s not in CAUGHT}
    excused = {n for n in left if n in equivalent}
    score = caught / max(1, total - len(excused))
    share = caught / max(1, total)
    print(f"\n{total} mutants: {caught} caught ({share:.1%}); {len(excused)} equivalent (listed with why)")
    if unchecked:
        print(f"{len(unchecked)} more not run (not counted)")
    print(f"score, equivalent ones left out: {score:.1%} (target {TARGET:.0%})")
    unexplained = sorted(n for n in left if n not in excused)
    if left:
        print("\nsurvivors:")
        for name in sorted(left):
            why = equivalent.get(name, "no reason: a test is missing")
            print(f"  {name} [{left[name]}]: {why}")
    if unknown:
        print(f"\n{len(unknown)} listed as equivalent but not among the mutants (stale): {', '.join(unknown)}")
    if args.write:
        figures = {"mutants": total, "caught": caught, "equivalent": len(excused), "score": round(score, 4),
                   "unexplained": len(unexplained)}  # fmt: skip
        Path(args.write).write_text(json.dumps(figures, indent=1) + "\n")
    return 0 if score >= TARGET and not unexplained else 1


if __name__ == "__main__":
    sys.exit(main())

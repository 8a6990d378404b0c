"""``make mutate-seal``: mutation testing of the grading kernel's seal, which ``make mutate`` cannot reach.

    python scripts/mutate_seal.py [--dir DIR] [--sample N] [--seed S] [--changed-since REV]

The seal (``tutorial/tools/grading/seal.py``) is tested in a Python of its own
(``tests/test_seal.py``: a sealed process stays sealed), where mutmut sees
neither which test reaches which function nor, as it runs, the function it
wraps.  This makes a git worktree of HEAD in ``DIR`` (default: beside this
repository; not under ``/tmp/``, which the seal lets an answer read, so the
tests of what it notes hold there), whose ``[tool.mutmut]`` mutates only the
seal with ``tests/test_seal.py`` as the tests, and there:

1. lets mutmut write its mutants (that first run stops: ``install`` rebuilds
   ``_make_hook`` from its code with private globals, and mutmut's wrapper
   around it is a closure);
2. makes ``install``, in mutmut's copy, rebuild the ``_make_hook`` of the
   mutant under test (``MUTANT_UNDER_TEST``, which the sealed Python inherits;
   its working folder, mutmut's copy, is the first place it imports from);
3. tells mutmut, in its copy of ``tests/test_seal.py``, that the seal's tests
   reach every function of the seal (mutmut counts calls in its own process,
   and the sealed Python of that count runs the original);
4. runs mutmut on every mutant, or on those that change a line ``git diff REV``
   shows changed in the seal (``--changed-since``: a round on what changed since
   the last), or a seeded sample of ``N`` of either, then
   ``scripts/mutation_report.py`` there.

About 35 s a mutant on two cores (2026-11-28, the seal's tests then 17 s): the seal's 1,092 take about eleven hours.
Remove the worktree with ``git worktree remove --force DIR``.
"""

from __future__ import annotations

import argparse
import ast
import difflib
import os
import random
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SEAL = "tutorial/tools/grading/seal.py"
HOOK = """

def _rtt_make_hook_code():  # scripts/mutate_seal.py: the code of the mutant under test's _make_hook
    name = os.environ.get("MUTANT_UNDER_TEST", "")
    prefix = "tutorial.tools.grading.seal.x__make_hook__mutmut_"
    if name.startswith(prefix):
        return globals()["x__make_hook__mutmut_" + name[len(prefix):]].__code__
    return x__make_hook__mutmut_orig.__code__
"""
REACHED = """    if os.environ.get("MUTANT_UNDER_TEST") == "stats":  # scripts/mutate_seal.py: the child is not seen
        env["MUTANT_UNDER_TEST"] = ""  # the child runs the original: mutmut counts calls in this process only
        from mutmut.stats import record_trampoline_hit

        for name in {names!r}:
            record_trampoline_hit("tutorial.tools.grading.seal." + name)
"""


def configure(tree: Path) -> None:
    """The worktree's ``[tool.mutmut]``: only the seal, only its tests."""
    path = tree / "pyproject.toml"
    text = path.read_text()
    text = re.sub(r"only_mutate = \[.*?\]\n", f'only_mutate = ["{SEAL}"]\n', text, count=1, flags=re.S)
    text = re.sub(
        r"pytest_add_cli_args_test_selection = \[.*?\]\n",
        'pytest_add_cli_args_test_selection = ["-m", "", "tests/test_seal.py"]\n',
        text,
        count=1,
        flags=re.S,
    )
    path.write_text(text)


def patch_mutants(tree: Path) -> None:
    """Steps 2 and 3 of the module text, on mutmut's copy (each once)."""
    seal = tree / "mutants" / SEAL
    text = seal.read_text()
    if "_rtt_make_hook_code" not in text:
        if "_make_hook.__code__" not in text:
            raise SystemExit(f"{seal}: no _make_hook.__code__ to replace: has install() changed?")
        seal.write_text(text.replace("_make_hook.__code__", "_rtt_make_hook_code()") + HOOK)
    names = sorted(set(re.findall(r"^def (x_\w+?)__mutmut_orig\(", seal.read_text(), flags=re.M)))
    for tests in (tree / "tests" / "test_seal.py", tree / "mutants" / "tests" / "test_seal.py"):  # mutmut copies
        text = tests.read_text()
        if "record_trampoline_hit" not in text:
            anchor = "\n    done = subprocess.run("  # sealed()'s, at the function's own indent (not a nested one)
            if text.count(anchor) != 1:
                raise SystemExit(f"{tests}: sealed() no longer runs {anchor.strip()!r} once")
            tests.write_text(text.replace(anchor, "\n" + REACHED.format(names=tuple(names)) + anchor[1:]))


def changed_lines(rev: str) -> set[int]:
    """The seal's lines (1-based) that ``git diff REV`` shows added or changed in this repository's HEAD."""
    diff = subprocess.run(
        ["git", "diff", "-U0", rev, "HEAD", "--", SEAL], cwd=ROOT, capture_output=True, text=True, check=True
    ).stdout
    lines = set()
    for start, count in re.findall(r"^@@ -\S+ \+(\d+)(?:,(\d+))? @@", diff, flags=re.M):
        lines.update(range(int(start), int(start) + (1 if count == "" else int(count))))
    return lines


def mutants_on(tree: Path, lines: set[int]) -> list[str]:
    """The mutants, in mutmut's copy of the seal, that change one of the seal's ``lines`` (its own numbering)."""
    source = (ROOT / SEAL).read_text().splitlines()
    first = {line[4:].partition("(")[0]: i + 1 for i, line in enumerate(source) if line.startswith("def ")}
    copy = (tree / "mutants" / SEAL).read_text()
    copied = copy.splitlines()
    functions = {
        node.name: copied[node.lineno - 1 : node.end_lineno]
        for node in ast.walk(ast.parse(copy))
        if isinstance(node, ast.FunctionDef) and "__mutmut_" in node.name
    }
    found = []
    for name, body in functions.items():
        stem, _, number = name.rpartition("__mutmut_")
        start = first.get(stem[2:])  # mutmut names a function's copies x_<name>__mutmut_<n>
        if number == "orig" or f"{stem}__mutmut_orig" not in functions or start is None:
            continue
        original = functions[f"{stem}__mutmut_orig"]
        body = [line.replace(name, f"{stem}__mutmut_orig") for line in body]
        for tag, i1, i2, _, _ in difflib.SequenceMatcher(a=original, b=body, autojunk=False).get_opcodes():
            if tag != "equal" and any(start + i in lines for i in range(i1, max(i2, i1 + 1))):
                found.append(f"tutorial.tools.grading.seal.{name}")
                break
    return sorted(found)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--dir", type=Path, default=ROOT.parent / f"{ROOT.name}-mutate-seal")
    p.add_argument("--sample", type=int, default=None, help="run only N mutants, drawn at random (default all)")
    p.add_argument("--seed", type=int, default=20261128, help="the sample's seed")
    p.add_argument("--changed-since", metavar="REV", help="run only the mutants of lines changed since REV")
    args = p.parse_args(argv)
    tree = args.dir.resolve()
    if str(tree).startswith("/tmp/"):
        raise SystemExit("--dir under /tmp/: the seal allows an answer to read there, and its tests need it not to")
    env = dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST", RTT_TEST_MODE="1")
    env.setdefault("ROS_DOMAIN_ID", str(random.randint(1, 100)))
    if not tree.exists():
        subprocess.run(["git", "worktree", "add", "--detach", str(tree), "HEAD"], cwd=ROOT, check=True)
        (tree / ".venv").symlink_to(ROOT / ".venv")
        configure(tree)
    heads = [
        subprocess.run(["git", "rev-parse", "HEAD"], cwd=d, capture_output=True, text=True).stdout for d in (ROOT, tree)
    ]
    if heads[0] != heads[1]:
        raise SystemExit(f"{tree} is not at this repository's HEAD: remove it (git worktree remove --force {tree})")
    mutmut = [str(tree / ".venv" / "bin" / "mutmut")]
    if not (tree / "mutants" / SEAL).exists():
        subprocess.run([*mutmut, "run"], cwd=tree, env=env, check=False)  # stops at its clean tests: step 1
    patch_mutants(tree)
    names = []  # none: every mutant
    if args.changed_since is not None:
        names = mutants_on(tree, changed_lines(args.changed_since))
        print(f"{len(names)} mutants change a line changed since {args.changed_since}", flush=True)
        if not names:
            return 0
    elif args.sample is not None:
        listed = subprocess.run([*mutmut, "results", "--all", "true"], cwd=tree, capture_output=True, text=True)
        names = sorted(line.split(":")[0].strip() for line in listed.stdout.splitlines() if "__mutmut_" in line)
    if args.sample is not None:
        names = sorted(random.Random(args.seed).sample(names, min(args.sample, len(names))))
    subprocess.run([*mutmut, "run", "--max-children", str(os.cpu_count() or 1), *names], cwd=tree, env=env)
    return subprocess.run([sys.executable, str(tree / "scripts" / "mutation_report.py")], cwd=tree).returncode


if __name__ == "__main__":
    sys.exit(main())

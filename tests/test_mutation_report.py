"""``make mutate``'s report: the score leaves out only the listed equivalent mutants, and the list is not stale."""

from __future__ import annotations

import importlib
import importlib.util
import inspect
import tomllib

import pytest

from conftest import ROOT

pytestmark = pytest.mark.unit


def load_script(name: str):
    """A script of scripts/ as a module (the folder is no package)."""
    spec = importlib.util.spec_from_file_location(name, ROOT / "scripts" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def load_report():
    return load_script("mutation_report")


def test_the_score_leaves_out_the_listed_equivalents_and_fails_on_an_unexplained_survivor(
    tmp_path, monkeypatch, capsys
):
    report = load_report()
    status = {f"pkg.mod.x_f__mutmut_{k}": "killed" for k in range(1, 19)}
    status |= {"pkg.mod.xǁCǁg__mutmut_1": "timeout", "pkg.mod.xǁCǁg__mutmut_2": "survived"}
    monkeypatch.setattr(report, "results", lambda: status)
    monkeypatch.setattr(report, "EQUIVALENT", tmp_path / "none.toml")
    assert report.main([]) == 1  # 19 of 20 caught is 95 %, but one survivor has no reason
    out = capsys.readouterr().out
    assert "20 mutants: 19 caught (95.0%); 0 equivalent" in out
    assert "pkg.mod.xǁCǁg__mutmut_2 [survived]: no reason: a test is missing" in out
    listed = tmp_path / "equivalent.toml"
    listed.write_text('"pkg.mod.xǁCǁg__mutmut_2" = "behaves as the original"\n')
    monkeypatch.setattr(report, "EQUIVALENT", listed)
    assert report.main(["--write", str(tmp_path / "m.json")]) == 0
    assert "score, equivalent ones left out: 100.0% (target 90%)" in capsys.readouterr().out
    status["pkg.mod.x_f__mutmut_1"] = "survived"  # 18 of 19: 94.7 %, still over 90 %, but unexplained
    assert report.main([]) == 1
    assert report.module("tutorial.core.call_later.xǁMainLoopǁrun_once__mutmut_9") == "tutorial.core.call_later"
    assert report.module("tutorial.controllers.tank_controller.x_track_velocities__mutmut_3") == (
        "tutorial.controllers.tank_controller"
    )


def test_every_listed_equivalent_mutant_names_a_function_that_exists_and_says_why():
    listed = tomllib.loads((ROOT / "tests" / "equivalent_mutants.toml").read_text())
    assert listed
    for name, why in listed.items():
        head = name.split("__mutmut_")[0]
        module_name, _, function = head.rpartition(".")
        module = importlib.import_module(module_name)
        if function.startswith("xǁ"):
            _, cls, method = function.split("ǁ")
            target = getattr(getattr(module, cls), method)
        else:
            target = getattr(module, function.removeprefix("x_"))
        assert inspect.isfunction(target), name
        assert len(why) > 20, name


def test_a_sample_counts_only_the_mutants_it_ran_and_a_list_of_another_runs_modules_is_not_stale(
    tmp_path, monkeypatch, capsys
):
    """scripts/mutate_seal.py runs a sample of the seal's mutants: the rest are not counted, and the listed
    equivalents of make mutate's modules are not called stale there (nor the seal's in make mutate)."""
    report = load_report()
    status = {"pkg.mod.x_f__mutmut_1": "killed", "pkg.mod.x_f__mutmut_2": "not checked"}
    monkeypatch.setattr(report, "results", lambda: status)
    listed = tmp_path / "equivalent.toml"
    listed.write_text('"other.mod.x_g__mutmut_1" = "of another run"\n"pkg.mod.x_f__mutmut_9" = "gone"\n')
    monkeypatch.setattr(report, "EQUIVALENT", listed)
    assert report.main([]) == 0
    out = capsys.readouterr().out
    assert "1 mutants: 1 caught (100.0%)" in out and "1 more not run (not counted)" in out
    assert "(stale): pkg.mod.x_f__mutmut_9" in out and "other.mod" not in out


def test_make_mutate_seal_can_patch_todays_seal_and_its_tests(tmp_path):
    """scripts/mutate_seal.py patches mutmut's copy of the seal and sealed()'s one subprocess.run in
    tests/test_seal.py: a test that changes either so that it cannot stops make mutate-seal (it did once)."""
    import shutil

    script = load_script("mutate_seal")
    (tmp_path / "mutants" / script.SEAL).parent.mkdir(parents=True)
    shutil.copy(ROOT / script.SEAL, tmp_path / "mutants" / script.SEAL)
    for folder in (tmp_path / "tests", tmp_path / "mutants" / "tests"):
        folder.mkdir()
        shutil.copy(ROOT / "tests" / "test_seal.py", folder / "test_seal.py")
    script.patch_mutants(tmp_path)
    for folder in (tmp_path / "tests", tmp_path / "mutants" / "tests"):
        patched = (folder / "test_seal.py").read_text()
        assert patched.count("record_trampoline_hit(") == 1
        compile(patched, "test_seal.py", "exec")  # still Python
    assert "_rtt_make_hook_code()" in (tmp_path / "mutants" / script.SEAL).read_text()


def test_a_round_on_what_changed_runs_the_seals_mutants_of_those_lines_alone(tmp_path):
    """``mutate_seal.py --changed-since REV``: of mutmut's copies of a seal function, those whose change falls on
    a line the diff names, and no other (a mutant of another line, the original itself)."""
    import ast

    script = load_script("mutate_seal")
    source = (ROOT / script.SEAL).read_text()
    node = next(n for n in ast.parse(source).body if isinstance(n, ast.FunctionDef) and n.name == "_gated_signal")
    body = source.splitlines()[node.lineno - 1 : node.end_lineno]
    audit = next(i for i, line in enumerate(body) if "sys.audit(" in line)
    returned = next(i for i, line in enumerate(body) if "return previous[0]" in line)

    def copy(number: str, changed_at: int | None) -> str:
        lines = [line.replace("def _gated_signal(", f"def x__gated_signal__mutmut_{number}(", 1) for line in body]
        if changed_at is not None:
            lines[changed_at] = lines[changed_at].replace("previous", "None", 1)
        return "\n".join(lines)

    copied = "\n\n".join([copy("orig", None), copy("1", audit), copy("2", returned)])
    (tmp_path / "mutants" / script.SEAL).parent.mkdir(parents=True)
    (tmp_path / "mutants" / script.SEAL).write_text(copied + "\n")
    prefix = "tutorial.tools.grading.seal.x__gated_signal__mutmut_"
    assert script.mutants_on(tmp_path, {node.lineno + audit}) == [prefix + "1"]
    assert script.mutants_on(tmp_path, {node.lineno + returned, 1}) == [prefix + "2"]
    assert script.mutants_on(tmp_path, {1}) == []

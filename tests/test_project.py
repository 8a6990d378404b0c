"""Project files: a wrong path, key or value gives one clear error naming the file and the key."""

import pytest

from tutorial.core.project import ProjectError, load_project

from conftest import MODEL, PROJECT

GOOD = f"""
name: p
models:
  - name: Tank
    file: {MODEL / "tank.xml"}
    controllers:
      - name: C
        class: tutorial.controllers.joint_state_publisher:RttJointStatePublisher
        parameters: {{rate: 50}}
simulator:
  time_step: 0.001
"""


@pytest.mark.parametrize("name", ["step1.yaml", "step2.yaml", "step3.yaml"])
def test_shipped_projects_load(name):
    project = load_project(PROJECT / name)
    assert [m.name for m in project.models][-1] == "Tank"
    assert (project.simulator is None) == (name == "step3.yaml")


def test_good_project(tmp_path):
    path = tmp_path / "p.yaml"
    path.write_text(GOOD)
    project = load_project(path)
    assert project.models[0].controllers[0].parameters == {"rate": 50.0}
    assert project.simulator.time_step == 0.001 and project.simulator.realtime_sync is True


@pytest.mark.parametrize(
    "old,new,key,message",
    [
        ("simulator:", "simulatr:", "simulatr", "unknown key"),
        ("time_step: 0.001", "time_step: -1", "simulator.time_step", "must be > 0"),
        ("time_step: 0.001", "time_step: fast", "simulator.time_step", "finite number"),
        (f"file: {MODEL / 'tank.xml'}", "file: nowhere.xml", "models[0].file", "no such model file"),
        ("rate: 50", "rate: fifty", "models[0].controllers[0].parameters.rate", "finite number"),
        ("rate: 50", "speed: 50", "models[0].controllers[0].parameters.speed", "unknown parameter"),
        (":RttJointStatePublisher", ":Nope", "models[0].controllers[0].class", "no SimpleController"),
        (
            "tutorial.controllers.joint_state_publisher:",
            "no.such.module:",
            "models[0].controllers[0].class",
            "cannot import",
        ),
        ("- name: Tank", "- name: 9Tank", "models[0].name", "expected a name"),
        ("- name: C", "- nam: C", "models[0].controllers[0].nam", "unknown key"),
    ],
)
def test_errors_name_the_file_and_the_key(tmp_path, old, new, key, message):
    path = tmp_path / "p.yaml"
    assert old in GOOD
    path.write_text(GOOD.replace(old, new))
    with pytest.raises(ProjectError) as info:
        load_project(path)
    text = str(info.value)
    assert text.startswith(f"{path}: {key}: "), text
    assert message in text


def test_missing_models_key(tmp_path):
    path = tmp_path / "p.yaml"
    path.write_text("name: p\n")
    with pytest.raises(ProjectError, match=r"p.yaml: models: missing"):
        load_project(path)


def test_yaml_syntax_error_names_the_file(tmp_path):
    path = tmp_path / "p.yaml"
    path.write_text("models: [\n")
    with pytest.raises(ProjectError, match=r"p.yaml: not valid YAML"):
        load_project(path)


def test_missing_project_file(tmp_path):
    with pytest.raises(ProjectError, match="cannot read the project file"):
        load_project(tmp_path / "absent.yaml")


def test_rtt_run_reports_a_bad_project_with_exit_status_2(tmp_path, procs):
    from conftest import module_command

    path = tmp_path / "p.yaml"
    path.write_text(GOOD.replace("simulator:", "simulatr:"))
    p = procs(module_command("tutorial.tools.rtt_run", str(path), "--headless"))
    assert p.wait(60) == 2
    assert f"{path}: simulatr: unknown key" in p.err


@pytest.mark.parametrize("case", ["binary junk", "model with an XML error", "bad ROS argument"])
def test_rtt_run_gives_one_line_and_status_2_for_a_bad_file_or_argument(tmp_path, procs, case):
    """Each of these ended in a traceback or exit status 1 before issue 26."""
    from conftest import module_command

    project = tmp_path / "p.yaml"
    args = [str(project), "--headless", "--duration", "0.1"]
    if case == "binary junk":
        project.write_bytes(bytes(range(256)) * 4)
        expected = f"{project}: not a text file (byte 128 is not UTF-8)"
    elif case == "model with an XML error":
        model = tmp_path / "m.xml"
        model.write_text('<mujoco><worldbody><body><geom size="0.1"/></body>\n<nope/></worldbody></mujoco>')
        project.write_text(f"models:\n  - name: M\n    file: {model}\n")
        expected = f"{project}: models[0].file: {model}: not a model MuJoCo can load: XML Error"
    else:
        project = PROJECT / "step2.yaml"
        args = [str(project), "--headless", "--ros-args", "-p", "rate"]
        expected = "bad ROS arguments after --ros-args: "
    p = procs(module_command("tutorial.tools.rtt_run", *args))
    assert p.wait(60) == 2, (p.out, p.err)
    [line] = p.err.splitlines()
    assert line.startswith(f"rtt-run: {expected}"), line

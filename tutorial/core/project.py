"""Project files: the ``.cnoid`` analog, in YAML.

A project says which models make the world, which controllers attach to
which body, and whether (and how) to simulate.  Example (``project/step1.yaml``)::

    name: step1
    models:
      - name: Room
        file: ../model/room.xml
      - name: Tank
        file: ../model/tank.xml
        controllers:
          - name: RttTankController
            class: tutorial.controllers.tank_controller:RttTankController
    simulator:
      time_step: 0.001
      realtime_sync: true

Paths are relative to the project file.  A project without ``simulator`` only
loads its models and configures their controllers (Step 3's viewer).  Such a
viewer project may name a robot-description topic instead of a model file
(``description: /Tank/robot_description``): the model is then the URDF the
simulation publishes there (:mod:`tutorial.interfaces.robot_description`),
received when the project is opened.  A model of a viewer project may also
name an odometry topic (``odometry: /Go2/odom``): its root link then floats,
placed where the robot's ``nav_msgs/Odometry`` says
(:mod:`tutorial.tools.standalone.floating_base`).

Every mistake raises one :class:`ProjectError` naming the file and the key,
e.g. ``project/step1.yaml: models[1].controllers[0].class: no module named 'x'``,
in one line: whatever the file holds (binary junk, YAML nested ten
thousand deep, a number too big for a float, a path with a NUL byte)
gives that, never another exception.  ``tests/test_fuzz_files.py`` feeds it
generated files to keep it so.
"""

from __future__ import annotations

import dataclasses
import importlib
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from tutorial.core.controller import SimpleController
from tutorial.core.world import ModelEntry

NAME_PATTERN = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")
# An absolute ROS 2 topic name: /part/part, each part letters, digits and _, not starting with a digit.
TOPIC_PATTERN = re.compile(r"^(/[A-Za-z_][A-Za-z0-9_]*)+$")
# A model's keys -> whether each is required.
MODEL_KEYS = {
    "name": True,
    **dict.fromkeys(("file", "description", "odometry", "position", "yaw", "controllers"), False),
}
MAX_PROJECT_BYTES = 1_000_000  # a project file is a page of YAML; a bigger "project" is the wrong file


class ProjectError(ValueError):
    """A project file cannot be used; the message names the file and the key, in one line.

    A line break that a key, a value or a file name brings into the message
    is written as ``\\n`` (and so for every other line separator).
    """

    def __init__(self, message: str):
        super().__init__(_one_line(message))


_LINE_BREAKS = {c: repr(c)[1:-1] for c in "\n\r\x0b\x0c\x1c\x1d\x1e\x85\u2028\u2029"}


def _one_line(text: str) -> str:
    """``text`` with every character ``str.splitlines`` breaks at written as its escape."""
    return text.translate(str.maketrans(_LINE_BREAKS))


@dataclass
class ControllerEntry:
    """A controller attached to a body.

    Attributes:
        name: its name (also the prefix of its ROS parameters).
        cls: the controller class, a :class:`SimpleController` subclass.
        class_path: ``module:Class`` as written in the project.
        parameters: validated parameter values (project values over defaults).
    """

    name: str
    cls: type
    class_path: str
    parameters: dict = field(default_factory=dict)


@dataclass
class SimulatorSettings:
    """Simulator settings: ``time_step`` in s, ``realtime_sync``, ``gravity`` (3,) m/s^2."""

    time_step: float = 0.001
    realtime_sync: bool = True
    gravity: tuple = (0.0, 0.0, -9.80665)


@dataclass
class Project:
    """A loaded, validated project file."""

    path: Path
    name: str
    models: list[ModelEntry]
    simulator: SimulatorSettings | None

    def with_controller(self, model: str, name: str, cls: type, parameters: dict | None = None) -> Project:
        """A copy of this project with one more controller attached to ``model``.

        This is what adding a controller item under a body item does in
        Choreonoid; a notebook attaches the class it has just built this way.

        Args:
            model: the model (body) name, e.g. ``Tank``.
            name: the controller's name (also the prefix of its ROS parameters).
            cls: the controller class, a :class:`SimpleController` subclass.
            parameters: values for the class's ``PARAMETERS`` (defaults for the rest).

        Raises:
            ProjectError: no such model, a bad or repeated name, a class that is
                not a controller, an unknown parameter or a value of the wrong type.

        Any thread may call this; the project itself is not changed.
        """
        r = _Reader(self.path)
        index = next((i for i, m in enumerate(self.models) if m.name == model), None)
        if index is None:
            raise r.fail("models", f"no model named {model!r}; the project has {[m.name for m in self.models]}")
        key = f"models[{index}].controllers[{len(self.models[index].controllers)}]"
        r.name(name, f"{key}.name")
        if any(c.name == name for c in self.models[index].controllers):
            raise r.fail(f"{key}.name", f"{name!r} is used twice on {model}")
        if not (isinstance(cls, type) and issubclass(cls, SimpleController)):
            raise r.fail(f"{key}.class", f"expected a SimpleController subclass, got {cls!r}")
        params = _parameters(r, cls, parameters or {}, f"{key}.parameters")
        entry = ControllerEntry(name, cls, f"{cls.__module__}:{cls.__qualname__}", params)
        models = list(self.models)
        models[index] = dataclasses.replace(models[index], controllers=[*models[index].controllers, entry])
        return dataclasses.replace(self, models=models)


class _Reader:
    """Walks the YAML tree, raising ProjectError with the file and key path."""

    def __init__(self, path: Path):
        self.path = path

    def fail(self, key: str, message: str) -> ProjectError:
        return ProjectError(f"{self.path}: {key}: {message}" if key else f"{self.path}: {message}")

    def mapping(self, value: Any, key: str, allowed: dict[str, bool]) -> dict:
        """Check a mapping's keys: ``allowed`` maps key -> required."""
        if not isinstance(value, dict):
            raise self.fail(key, f"expected a mapping, got {type(value).__name__}")
        for k in value:
            if k not in allowed:
                raise self.fail(_join(key, str(k)), f"unknown key; allowed: {', '.join(allowed)}")
        for k, required in allowed.items():
            if required and k not in value:
                raise self.fail(_join(key, k), "missing (required)")
        return value

    def number(self, value: Any, key: str, positive: bool = False) -> float:
        if not _is_finite_number(value):
            raise self.fail(key, f"expected a finite number, got {_brief(value)}")
        if positive and value <= 0:
            raise self.fail(key, f"must be > 0, got {value!r}")
        return float(value)

    def vector(self, value: Any, key: str, n: int) -> tuple:
        if not isinstance(value, (list, tuple)) or len(value) != n:
            raise self.fail(key, f"expected a list of {n} numbers, got {_brief(value)}")
        return tuple(self.number(v, f"{key}[{i}]") for i, v in enumerate(value))

    def name(self, value: Any, key: str) -> str:
        if not isinstance(value, str) or not NAME_PATTERN.match(value):
            raise self.fail(
                key, f"expected a name of letters, digits and _, starting with a letter, got {_brief(value)}"
            )
        return value


def _join(prefix: str, key: str) -> str:
    return f"{prefix}.{key}" if prefix else key


def _brief(value: Any, limit: int = 80) -> str:
    """``repr(value)`` on one line, cut to ``limit`` characters: an error message names the value, not a page of it."""
    text = repr(value).replace("\n", " ")
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _is_finite_number(value: Any) -> bool:
    """An int or float (not a bool) that is finite as a float (an int too big for one is not)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return False
    try:
        return math.isfinite(value)
    except OverflowError:  # an int beyond 1.8e308
        return False


def _read_text(path: Path) -> str:
    """The project file's text (UTF-8), or a :class:`ProjectError` saying why there is none."""
    try:
        if not path.is_file():
            what = "no such file" if not path.exists() else "not a regular file"
            raise ProjectError(f"{path}: cannot read the project file: {what}")
        size = path.stat().st_size
        if size > MAX_PROJECT_BYTES:
            raise ProjectError(f"{path}: {size} bytes is too big for a project file (at most {MAX_PROJECT_BYTES})")
        data = path.read_bytes()
    except OSError as exc:
        raise ProjectError(f"{path}: cannot read the project file: {exc.strerror or exc}") from None
    except ValueError as exc:  # a NUL byte in the name
        raise ProjectError(f"{path!r}: cannot read the project file: {exc}") from None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ProjectError(
            f"{path}: not a text file (byte {exc.start} is not UTF-8): a project file is YAML text"
        ) from None


def _parse_yaml(path: Path, text: str) -> Any:
    """The YAML document, or one :class:`ProjectError` line naming where the YAML is wrong."""
    try:
        return yaml.safe_load(text)
    except yaml.MarkedYAMLError as exc:
        where = f" (line {exc.problem_mark.line + 1}, column {exc.problem_mark.column + 1})" if exc.problem_mark else ""
        what = " ".join(str(exc.problem or exc.context or "syntax error").split())
        raise ProjectError(f"{path}: not valid YAML: {what}{where}") from None
    except yaml.YAMLError as exc:
        raise ProjectError(f"{path}: not valid YAML: {' '.join(str(exc).split())[:200]}") from None
    except RecursionError:
        raise ProjectError(f"{path}: not valid YAML: nested too deeply") from None


def load_project(path: str | Path) -> Project:
    """Read and validate a project file.

    Args:
        path: the YAML file.

    Returns:
        The :class:`Project`; model paths are resolved and checked to exist,
        controller classes imported and their parameters validated.

    Raises:
        ProjectError: anything wrong, with the file and the key in the message.

    Any thread may call this (it imports controller modules).
    """
    path = Path(path)
    r = _Reader(path)
    doc = _parse_yaml(path, _read_text(path))
    if doc is None:
        raise ProjectError(f"{path}: the project file is empty")
    r.mapping(doc, "", {"name": False, "description": False, "models": True, "simulator": False})
    name = r.name(doc.get("name", path.stem), "name") if "name" in doc else path.stem
    models_doc = doc["models"]
    if not isinstance(models_doc, list) or not models_doc:
        raise r.fail("models", "expected a non-empty list of models")
    models: list[ModelEntry] = []
    seen: set[str] = set()
    for i, m in enumerate(models_doc):
        key = f"models[{i}]"
        r.mapping(m, key, MODEL_KEYS)
        mname = r.name(m["name"], f"{key}.name")
        if mname in seen:
            raise r.fail(f"{key}.name", f"{mname!r} is used twice; model names must be unique")
        seen.add(mname)
        mfile, description = None, None
        if "file" in m and "description" in m:
            raise r.fail(key, "give either file (a model file) or description (a robot-description topic), not both")
        if "description" in m:
            description = m["description"]
            if not isinstance(description, str) or not TOPIC_PATTERN.match(description):
                raise r.fail(
                    f"{key}.description",
                    f"expected a topic name like /{mname}/robot_description, got {_brief(description)}",
                )
        elif "file" not in m:
            raise r.fail(f"{key}.file", "missing: give file (a model file) or description (a robot-description topic)")
        else:
            if not isinstance(m["file"], str):
                raise r.fail(f"{key}.file", f"expected a path, got {_brief(m['file'])}")
            try:
                mfile = (path.parent / m["file"]).resolve()
                found = mfile.is_file()
            except (OSError, ValueError, RuntimeError) as exc:  # a NUL byte, a name too long, a symlink loop
                raise r.fail(f"{key}.file", f"not a usable path: {_brief(m['file'])} ({exc})") from None
            if not found:
                raise r.fail(f"{key}.file", f"no such model file: {mfile}")
        odometry = m.get("odometry")
        if odometry is not None and (not isinstance(odometry, str) or not TOPIC_PATTERN.match(odometry)):
            raise r.fail(f"{key}.odometry", f"expected a topic name like /{mname}/odom, got {_brief(odometry)}")
        entry = ModelEntry(
            name=mname,
            file=mfile,
            position=r.vector(m.get("position", [0, 0, 0]), f"{key}.position", 3),
            yaw=r.number(m.get("yaw", 0.0), f"{key}.yaw"),
            description=description,
            odometry=odometry,
        )
        controllers = m.get("controllers", [])
        if not isinstance(controllers, list):
            raise r.fail(f"{key}.controllers", "expected a list of controllers")
        cnames: set[str] = set()
        for j, c in enumerate(controllers):
            ckey = f"{key}.controllers[{j}]"
            r.mapping(c, ckey, {"name": True, "class": True, "parameters": False})
            cname = r.name(c["name"], f"{ckey}.name")
            if cname in cnames:
                raise r.fail(f"{ckey}.name", f"{cname!r} is used twice on {mname}")
            cnames.add(cname)
            cls = _import_controller(r, c["class"], f"{ckey}.class")
            params = _parameters(r, cls, c.get("parameters", {}) or {}, f"{ckey}.parameters")
            entry.controllers.append(ControllerEntry(cname, cls, c["class"], params))
        models.append(entry)
    simulator = None
    if "simulator" in doc:
        s = doc["simulator"] or {}
        r.mapping(s, "simulator", {"time_step": False, "realtime_sync": False, "gravity": False})
        rt = s.get("realtime_sync", True)
        if not isinstance(rt, bool):
            raise r.fail("simulator.realtime_sync", f"expected true or false, got {_brief(rt)}")
        simulator = SimulatorSettings(
            time_step=r.number(s.get("time_step", 0.001), "simulator.time_step", positive=True),
            realtime_sync=rt,
            gravity=r.vector(s.get("gravity", [0, 0, -9.80665]), "simulator.gravity", 3),
        )
        for i, m in enumerate(models):
            if m.description is not None:
                raise r.fail(
                    f"models[{i}].description",
                    "a simulated model needs a model file (physics: masses, contacts, actuators); "
                    "a robot-description topic is for a viewer project (no simulator)",
                )
            if m.odometry is not None:
                why = "a simulated model's root moves by its physics; an odometry topic is for a viewer project"
                raise r.fail(f"models[{i}].odometry", why)
    return Project(path=path, name=name, models=models, simulator=simulator)


def _import_controller(r: _Reader, spec: Any, key: str) -> type:
    if not isinstance(spec, str) or spec.count(":") != 1:
        raise r.fail(key, f"expected 'module:Class', got {_brief(spec)}")
    module_name, class_name = spec.split(":")
    try:
        module = importlib.import_module(module_name)
    except Exception as exc:  # noqa: BLE001 - ImportError, and whatever the named module raises as it loads
        detail = " ".join(str(exc).split())[:200] or type(exc).__name__
        raise r.fail(key, f"cannot import module {_brief(module_name)}: {detail}") from None
    cls = getattr(module, class_name, None)
    if not (isinstance(cls, type) and issubclass(cls, SimpleController)):
        raise r.fail(key, f"{module_name} has no SimpleController subclass named {_brief(class_name)}")
    return cls


def _parameters(r: _Reader, cls: type, given: Any, key: str) -> dict:
    if not isinstance(given, dict):
        raise r.fail(key, "expected a mapping of parameter names to values")
    values = {name: default for name, (_, default, _) in cls.PARAMETERS.items()}
    for name, value in given.items():
        if name not in cls.PARAMETERS:
            known = ", ".join(cls.PARAMETERS) or "none"
            raise r.fail(_join(key, str(name)), f"unknown parameter of {cls.__name__}; known: {known}")
        typ = cls.PARAMETERS[name][0]
        values[name] = check_parameter(typ, value, lambda msg: r.fail(_join(key, name), msg))  # noqa: B023 - called in this iteration
    return values


def check_parameter(typ: type, value: Any, fail) -> Any:
    """Validate one controller parameter value (used for project values and ROS overrides).

    Raises:
        whatever ``fail(message)`` returns, when ``value`` is not a ``typ``.
    """
    if typ is float:
        if not _is_finite_number(value):
            raise fail(f"expected a finite number, got {_brief(value)}")
        return float(value)
    if typ is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise fail(f"expected an integer, got {_brief(value)}")
        return value
    if not isinstance(value, typ):
        raise fail(f"expected {typ.__name__}, got {_brief(value)}")
    return value

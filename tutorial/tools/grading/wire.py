"""What crosses between a graded kernel and the judge: values as JSON, built back only from types on a list.

The judge (:mod:`tutorial.tools.grading.judge`) runs the teacher's checks in a
process of its own; the kernel (:mod:`tutorial.tools.grading.judged`) runs the
answer.  Between them goes data, never an object: :func:`encode` turns a value
into JSON's types, :func:`decode` builds it back, and builds only these:

* ``None``, ``bool``, ``int``, ``float`` (NaN and the infinities too), ``str``, ``bytes``;
  ``list``, ``tuple``, ``dict``; NumPy's arrays (as their bytes) and scalars of booleans and numbers;
* the checks' own data classes and the ROS messages they name (:func:`_classes`, :func:`_messages`),
  ``rclpy``'s ``Parameter``, ``QoSProfile`` and ``Duration``;
* a file a check made for the answer to read (a ``Path``): its bytes cross, and the kernel's side writes them
  into a folder of its own (a bag of 7.1's).

Anything else an answer gives back (an object of a class of its own, a float
subclass) arrives as an :class:`Opaque`: its class's name and its ``repr``,
which equals nothing.  So no answer's code ever runs in the judge, and a value
can only say what its data says.  Pure functions; any thread.
"""

from __future__ import annotations

import base64
import dataclasses
import functools
import json
import math
import re
import sys
from pathlib import Path, PurePath

MAX_LINE = 8 << 20  # bytes of one message: a longer one is refused, not read
MAX_DEPTH = 64  # nesting of one value
MAX_TEXT = 300  # characters of an Opaque's repr or an exception's message
MAX_CASE_TEXT = 2000  # characters of what an experiment's failed case says, and of its hint


class WireError(ValueError):
    """A message that is not one :func:`decode` builds: its text says what is wrong with it."""


class Opaque:
    """A value the wire does not carry (an answer's own class): its class's name and repr, equal to nothing.

    ``own_eq``: whether that class (or its metaclass) defines ``__eq__``, so compares as it likes.
    """

    def __init__(self, kind: str, text: str, own_eq: bool = False):
        self.kind, self.text, self.own_eq = kind, text, own_eq

    def __repr__(self) -> str:
        return self.text

    def __eq__(self, other) -> bool:
        return False

    __hash__ = object.__hash__


@functools.cache
def _classes() -> dict:
    from tutorial.core.body import JointInfo
    from tutorial.interfaces.tf import Transform
    from tutorial.tools.bag.series import JointSeries

    return {f"{c.__module__}:{c.__qualname__}": c for c in (JointInfo, Transform, JointSeries)}


@functools.cache
def _messages() -> dict:
    """The ROS messages that cross: 10.1's answer, and what the checks' experiments record (with every message
    type nested in them)."""
    from builtin_interfaces.msg import Time
    from geometry_msgs.msg import Point, Pose, PoseStamped, Quaternion, Vector3, Vector3Stamped
    from rcl_interfaces.msg import SetParametersResult
    from sensor_msgs.msg import CameraInfo, Image, Imu, JointState, RegionOfInterest
    from std_msgs.msg import Float64, Header

    kinds = (SetParametersResult, JointState, PoseStamped, Pose, Point, Quaternion, Imu, Vector3, Vector3Stamped)
    kinds += (Float64, Image, CameraInfo, RegionOfInterest, Header, Time)
    return {_message_name(kind): kind for kind in kinds}


NUMPY_KINDS = "biuf"  # NumPy dtypes the wire carries: booleans, integers, floats
NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]{0,59}")


def encode(value, depth: int = 0):
    """``value`` as JSON's types (tagged dicts for the rest), never calling a method of an answer's class but
    ``repr`` for an :class:`Opaque`'s text.

    Raises:
        WireError: nested deeper than :data:`MAX_DEPTH`.
    """
    if depth > MAX_DEPTH:
        raise WireError(f"a value nested deeper than {MAX_DEPTH}")
    kind = type(value)
    if value is None or kind in (bool, int, str):
        return value
    if kind is float:
        return value if math.isfinite(value) else {"float": repr(value)}
    if kind is list:
        return [encode(v, depth + 1) for v in value]
    if kind is tuple:
        return {"tuple": [encode(v, depth + 1) for v in value]}
    if kind is dict:
        return {"dict": [[encode(k, depth + 1), encode(v, depth + 1)] for k, v in dict.items(value)]}
    if kind is bytes:
        return {"bytes": base64.b64encode(value).decode()}
    module = getattr(kind, "__module__", "")
    if module == "numpy":
        import numpy as np

        if kind is np.ndarray and value.dtype.kind in NUMPY_KINDS:  # its bytes: a picture is 230,400 numbers
            raw = np.ascontiguousarray(value).tobytes()
            return {"raw": [value.dtype.str, list(value.shape), base64.b64encode(raw).decode()]}
        if isinstance(value, np.generic) and value.dtype.kind in NUMPY_KINDS:
            return {"scalar": [value.dtype.str, encode(value.item(), depth + 1)]}
    key = f"{module}:{getattr(kind, '__qualname__', '')}"
    if key in _classes():
        fields = {f.name: encode(getattr(value, f.name), depth + 1) for f in dataclasses.fields(kind)}
        return {"object": [key, fields]}
    message = _message_name(kind)
    if message in _messages():
        fields = {name: encode(_plain(getattr(value, name)), depth + 1) for name in kind.get_fields_and_field_types()}
        return {"message": [message, fields]}
    if module == "rclpy.parameter" and kind.__qualname__ == "Parameter":
        return {"parameter": [value.name, int(value.type_.value), encode(_plain(value.value), depth + 1)]}
    if isinstance(value, PurePath) and kind is type(Path()):  # a file a check made for the answer to read
        if not value.is_file():
            raise WireError(f"a path that is no file: {value}")
        return {"file": [value.name, base64.b64encode(value.read_bytes()).decode()]}
    if module == "rclpy.duration" and kind.__qualname__ == "Duration":
        return {"duration": value.nanoseconds}
    if module == "rclpy.qos" and kind.__qualname__ == "QoSProfile":
        return {"qos": {p: encode(_policy(getattr(value, p)), depth + 1) for p in QOS_FIELDS}}
    return {"opaque": [_kind_name(kind), _short_repr(value), _own_eq(kind)]}


QOS_FIELDS = (
    "history",
    "depth",
    "reliability",
    "durability",
    "lifespan",
    "deadline",
    "liveliness",
    "liveliness_lease_duration",
    "avoid_ros_namespace_conventions",
)


def _policy(value):
    """A QoS policy's value: an enum's int, a Duration, a bool or an int as they are."""
    return int(value) if hasattr(type(value), "__members__") else value


def _plain(value):
    """A message field's value as the wire's types: an ``array.array`` as a list, of bytes as ``bytes``."""
    if type(value).__module__ == "array":
        return value.tobytes() if value.typecode == "B" else value.tolist()
    return value


def _message_name(kind) -> str | None:
    """``pkg/msg/Type`` of a ROS message class, or None."""
    module = getattr(kind, "__module__", "")
    parts = module.split(".")
    if len(parts) >= 2 and parts[1] == "msg" and hasattr(kind, "get_fields_and_field_types"):
        return f"{parts[0]}/msg/{kind.__name__}"
    return None


def _kind_name(kind) -> str:
    name = type.__dict__["__name__"].__get__(kind) if isinstance(kind, type) else "object"
    return name if NAME.fullmatch(name) else "object"


def _short_repr(value) -> str:
    try:
        text = repr(value)
    except Exception:  # noqa: BLE001 - an answer's repr that raises: its class's name says enough
        text = f"<a {_kind_name(type(value))}>"
    text = text if type(text) is str else "<?>"
    return text[:MAX_TEXT] + ("..." if len(text) > MAX_TEXT else "")


def _own_eq(kind) -> bool:
    try:
        classes = [*kind.__mro__[:-1], *type(kind).__mro__[:-1]]
        library = kind.__module__ == "numpy" or str(kind.__module__).split(".")[0] in sys.stdlib_module_names
        return any("__eq__" in vars(k) for k in classes) and not library  # a deque, an OrderedDict: not its own
    except Exception:  # noqa: BLE001 - a class too strange to read: say it may compare as it likes
        return True


def decode(data, depth: int = 0, folder: str | None = None):
    """The value :func:`encode` made ``data`` from (a new object), built only from the types it lists.

    ``folder``: where a file the value carries is written (the kernel's side gives one; the judge's, none).

    Raises:
        WireError: ``data`` is not one :func:`encode` makes: a tag, a class, a message or a dtype not listed, a
            field the class lacks, nesting deeper than :data:`MAX_DEPTH`.
    """
    if depth > MAX_DEPTH:
        raise WireError(f"a value nested deeper than {MAX_DEPTH}")
    kind = type(data)
    if data is None or kind in (bool, int, str, float):
        return data
    if kind is list:
        return [decode(v, depth + 1, folder) for v in data]
    if kind is not dict or len(data) != 1:
        raise WireError(f"not a value: a {kind.__name__}")
    (tag, body), deeper = next(iter(data.items())), depth + 1
    try:
        return _DECODERS[tag](body, deeper, folder)
    except KeyError:
        if tag not in _DECODERS:
            raise WireError(f"no such kind of value: {tag!r:.40}") from None
        raise WireError(f"a {tag} without what it needs") from None
    except (TypeError, ValueError, AttributeError, AssertionError) as exc:
        if isinstance(exc, WireError):
            raise
        raise WireError(f"a {tag} that cannot be built: {exc}"[:MAX_TEXT]) from None


def _list(body) -> list:
    if type(body) is not list:
        raise WireError("a tuple or a dict is sent as a list")
    return body


def _float(body, depth, folder):
    if body not in ("nan", "inf", "-inf"):
        raise WireError(f"not a float: {body!r:.40}")
    return float(body)


def _numpy_dtype(text):
    import numpy as np

    dtype = np.dtype(str(text))
    if dtype.kind not in NUMPY_KINDS:
        raise WireError(f"an array of {dtype}: only booleans and numbers cross")
    return dtype


def _raw(body, depth, folder):
    import numpy as np

    dtype, shape, content = body
    dtype, shape = _numpy_dtype(dtype), [int(n) for n in shape]
    raw = base64.b64decode(str(content), validate=True)
    if any(n < 0 for n in shape) or len(raw) != dtype.itemsize * math.prod(shape):
        raise WireError(f"an array of shape {shape} and {len(raw)} bytes")
    return np.frombuffer(raw, dtype).reshape(shape).copy()


def _scalar(body, depth, folder):
    dtype, value = body
    return _numpy_dtype(dtype).type(decode(value, depth, folder))


def _object(body, depth, folder):
    key, fields = body
    cls = _classes().get(key)
    if cls is None:
        raise WireError(f"no such class on the wire: {key!r:.80}")
    return cls(**{str(k): decode(v, depth, folder) for k, v in dict(fields).items()})


def _message(body, depth, folder):
    name, fields = body
    cls = _messages().get(name)
    if cls is None:
        raise WireError(f"no such message on the wire: {name!r:.80}")
    message = cls()
    for field, value in dict(fields).items():
        if field not in cls.get_fields_and_field_types():
            raise WireError(f"{name} has no field {field!r:.40}")
        setattr(message, field, decode(value, depth, folder))
    return message


def _parameter(body, depth, folder):
    from rclpy.parameter import Parameter

    name, type_, value = body
    return Parameter(str(name), Parameter.Type(int(type_)), decode(value, depth, folder))


def _duration(body, depth, folder):
    from rclpy.duration import Duration

    if type(body) is not int:
        raise WireError("a duration is whole nanoseconds")
    return Duration(nanoseconds=body)


def _qos(body, depth, folder):
    from rclpy.qos import QoSProfile

    given = {str(k): decode(v, depth, folder) for k, v in dict(body).items() if k in QOS_FIELDS}
    return QoSProfile(**given)


def _file(body, depth, folder):
    if folder is None:
        raise WireError("a file goes only to the kernel")
    name, content = body
    if not re.fullmatch(r"[A-Za-z0-9_-]{1,60}(\.[A-Za-z0-9]{1,8})?", str(name)):
        raise WireError(f"not a file's name: {name!r:.40}")
    path = Path(folder) / str(name)
    path.write_bytes(base64.b64decode(content, validate=True))
    return path


def _opaque(body, depth, folder):
    kind, text, own_eq = body
    return Opaque(str(kind)[:60], str(text)[: MAX_TEXT + 3], bool(own_eq))


_DECODERS = {
    "float": _float,
    "tuple": lambda body, depth, folder: tuple(decode(_list(body), depth, folder)),
    "dict": lambda body, depth, folder: {decode(k, depth, folder): decode(v, depth, folder) for k, v in _list(body)},
    "file": _file,
    "raw": _raw,
    "bytes": lambda body, depth, folder: base64.b64decode(str(body), validate=True),
    "scalar": _scalar,
    "object": _object,
    "message": _message,
    "parameter": _parameter,
    "duration": _duration,
    "qos": _qos,
    "opaque": _opaque,
}


def dumps(message: dict) -> bytes:
    """One message as a line of JSON (NaN and the infinities are tagged by :func:`encode` beforehand)."""
    return json.dumps(message, separators=(",", ":"), allow_nan=False).encode() + b"\n"


def loads(line: bytes) -> dict:
    """A line :func:`dumps` made, as a dict.

    Raises:
        WireError: not a JSON object, longer than :data:`MAX_LINE`, or with a NaN or an infinity untagged.
    """
    if len(line) > MAX_LINE:
        raise WireError(f"a message of more than {MAX_LINE} bytes")
    try:
        message = json.loads(line, parse_constant=_no_constant)
    except (ValueError, RecursionError) as exc:
        raise WireError(f"not JSON: {exc}"[:MAX_TEXT]) from None
    if type(message) is not dict:
        raise WireError("a message is a JSON object")
    return message


def _no_constant(name):
    raise WireError(f"an untagged {name}")

"""ROS 2 messages as YAML and back, by type name: what ``ros2 topic echo`` prints and ``ros2 topic pub`` reads.

ros2cli does this with ``rosidl_runtime_py``, which has no wheel here; these
functions follow its output: each field in its declared order, nested
messages as nested mappings, arrays and sequences as lists (longer ones cut
to ``truncate_length`` items, with ``'...'`` last), YAML in block style.
Any thread may call them.
"""

from __future__ import annotations

import array
import importlib
from collections.abc import Mapping

import numpy as np

_KINDS = {"msg", "srv", "action"}


def interface_type(name: str, kind: str = "msg"):
    """The Python class of an interface named ``pkg/msg/Name`` (or ``pkg/Name``), e.g. ``sensor_msgs/msg/Joy``.

    Raises:
        ValueError: not of that form, or no such package or type here (the
            message says which; only the packages installed as wheels exist).
    """
    parts = name.strip("/").split("/")
    if len(parts) == 2:
        parts = [parts[0], kind, parts[1]]
    if len(parts) != 3 or parts[1] not in _KINDS or not all(parts):
        raise ValueError(f"{name!r}: expected a type like sensor_msgs/{kind}/Name")
    package, folder, type_name = parts
    try:
        module = importlib.import_module(f"{package}.{folder}")
    except ImportError:
        raise ValueError(f"{name}: no package {package} here (its wheel is not installed)") from None
    cls = getattr(module, type_name, None)
    if cls is None:
        raise ValueError(f"{name}: {package}.{folder} has no type {type_name}")
    return cls


def type_name(cls) -> str:
    """``pkg/msg/Name`` of a message or service class, as ``ros2 topic list -t`` prints it."""
    package, folder = cls.__module__.split(".")[:2]
    return f"{package}/{folder.removeprefix('_')}/{cls.__name__}"


def to_dict(msg, truncate_length: int | None = None) -> dict:
    """``msg`` as plain Python (dicts, lists, numbers, strings), its fields in their declared order."""
    return {field: _plain(getattr(msg, field), truncate_length) for field in msg.get_fields_and_field_types()}


def _plain(value, truncate_length):
    if hasattr(value, "get_fields_and_field_types"):
        return to_dict(value, truncate_length)
    if isinstance(value, (list, tuple, array.array, np.ndarray, bytes)):
        items = [_plain(v.item() if isinstance(v, np.generic) else v, truncate_length) for v in value]
        if truncate_length is not None and len(items) > truncate_length:
            items = [*items[:truncate_length], "..."]
        return items
    if isinstance(value, str) and truncate_length is not None and len(value) > truncate_length:
        return value[:truncate_length] + "..."
    return value.item() if isinstance(value, np.generic) else value


def to_yaml(msg, truncate_length: int | None = 128) -> str:
    """``msg`` as ``ros2 topic echo`` prints it (without the ``---`` line that follows each message)."""
    import yaml

    return yaml.safe_dump(to_dict(msg, truncate_length), sort_keys=False, allow_unicode=True, width=10_000)


def set_fields(msg, values: Mapping | None, where: str = "") -> None:
    """Set ``msg``'s fields from a mapping (e.g. parsed from ``'{axes: [0.0, 1.0]}'``), nested ones too.

    Raises:
        ValueError: a field the message does not have, or a value of the
            wrong kind for its field; the message names the field.
    """
    if values is None:
        return
    if not isinstance(values, Mapping):
        raise ValueError(f"{where or 'the message'}: expected a mapping of field names, got {values!r}")
    fields = msg.get_fields_and_field_types()
    for name, value in values.items():
        path = f"{where}.{name}" if where else str(name)
        if name not in fields:
            raise ValueError(f"{path}: {type(msg).__name__} has no such field (it has {', '.join(fields)})")
        current = getattr(msg, name)
        if hasattr(current, "get_fields_and_field_types"):
            set_fields(current, value, path)
            continue
        try:
            if isinstance(value, list) and fields[name].startswith("sequence<") and "/" in fields[name]:
                value = [_nested(msg, name, item, f"{path}[{i}]") for i, item in enumerate(value)]
            setattr(msg, name, value)
        except (TypeError, ValueError, AssertionError) as exc:
            raise ValueError(f"{path}: {value!r} does not fit {fields[name]} ({exc})") from None


def _nested(msg, name: str, item, path: str):
    """One item of a sequence of messages, built from its mapping."""
    slot = msg.SLOT_TYPES[list(msg.get_fields_and_field_types()).index(name)].value_type
    cls = getattr(importlib.import_module(".".join(slot.namespaces)), slot.name)
    element = cls()
    set_fields(element, item, path)
    return element

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
    if folder != kind:
        raise ValueError(f"{name}: a {folder} type, where a {kind} type is asked for")
    try:
        module = importlib.import_module(f"{package}.{folder}")
    except ImportError:
        raise ValueError(f"{name}: no package {package} here (its wheel is not installed)") from None
    cls = getattr(module, type_name, None)
    if cls is None:
        raise ValueError(f"{name}: {package}.{folder} has no type {type_name}")
    return cls


def to_dict(msg, truncate_length: int | None = None) -> dict:
    """``msg`` as plain Python (dicts, lists, numbers, strings), its fields in their declared order."""
    return {field: _plain(getattr(msg, field), truncate_length) for field in msg.get_fields_and_field_types()}


def _plain(value, truncate_length):
    if hasattr(value, "get_fields_and_field_types"):
        return to_dict(value, truncate_length)
    if isinstance(value, bytes):  # an octet is a bytes object of one: printed as its number
        return value[0] if len(value) == 1 else list(value)
    if isinstance(value, (list, tuple, array.array, np.ndarray)):
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
    """Set ``msg``'s fields from a mapping (e.g. parsed from ``'{axes: [0, 1.0]}'``), nested ones too.

    Each value is converted to its field's type as ``ros2 topic pub`` does:
    a whole number into a float field, a number into a byte.

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
        base, many = _element(fields[name])
        slot = msg.SLOT_TYPES[list(fields).index(name)]
        if many:
            size = fields[name][fields[name].rindex("[") + 1 : -1] if fields[name].endswith("]") else ""
            if not isinstance(value, list) or (size.isdigit() and len(value) != int(size)):
                raise ValueError(f"{path}: {value!r} does not fit {fields[name]} (expected a list of {size or 'any'})")
            value = [
                _one(item, base, getattr(slot, "value_type", None), f"{path}[{i}]") for i, item in enumerate(value)
            ]
        else:
            value = _one(value, base, slot, path)
        try:
            setattr(msg, name, value)
        except (TypeError, ValueError, AssertionError) as exc:
            raise ValueError(f"{path}: {values[name]!r} does not fit {fields[name]} ({exc})") from None


_FLOATS = {"float", "double", "long double"}
_INTEGERS = {"int8", "uint8", "int16", "uint16", "int32", "uint32", "int64", "uint64", "char"}


def _element(field_type: str) -> tuple[str, bool]:
    """``(element type, is an array)`` of a field's type: ``sequence<double, 5>``, ``double[9]``, ``string<=8``."""
    if field_type.startswith("sequence<"):
        return field_type[len("sequence<") : -1].split(",")[0].strip().split("<=")[0], True
    if field_type.endswith("]"):
        return field_type[: field_type.rindex("[")].split("<=")[0], True
    return field_type.split("<=")[0], False


def _one(value, base: str, slot, path: str):
    """One value for a field (or an array's item) of type ``base``, converted as ros2cli converts it."""
    if "/" in base:  # a message: built from its mapping
        element = getattr(importlib.import_module(".".join(slot.namespaces)), slot.name)()
        set_fields(element, value, path)
        return element
    number = isinstance(value, (int, float)) and not isinstance(value, bool)
    if base in _FLOATS and number:
        return float(value)
    if base in _INTEGERS and isinstance(value, int) and not isinstance(value, bool):
        return value
    if base == "boolean" and isinstance(value, bool):
        return value
    if base == "octet" and isinstance(value, int) and not isinstance(value, bool) and 0 <= value <= 255:
        return bytes([value])
    if base in ("string", "wstring") and isinstance(value, str):
        return value
    raise ValueError(f"{path}: {value!r} does not fit {base}")

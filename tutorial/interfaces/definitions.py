"""Message definitions as rosbag2 stores them, and message classes by type name.

An MCAP file of the ``ros2`` profile keeps, for each message type, a schema
of encoding ``ros2msg``: the ``.msg`` text of the type followed by the text
of every type it uses, each after a line of 80 ``=`` and a ``MSG: pkg/Name``
line.  A reader needs nothing else to decode the CDR bytes (Foxglove, the
``mcap-ros2-support`` decoder, ``rosbags``).

rosbag2 (Jazzy) builds that text in ``rosbag2_cpp``'s
``LocalMessageDefinitionSource`` from the ``.msg`` files installed in each
package's ``share/<pkg>/msg/`` folder.  The ROS 2 wheels ship those files
(``<venv>/share/sensor_msgs/msg/JointState.msg``), so :func:`full_text` does
the same, with the same dependency search (same regular expression, same
order, same separators): a file recorded here carries the same text a
``ros2 bag record`` would write.  Neither ``mcap-ros2-support`` (it takes
the text from its caller) nor ``rosbags`` (it generates a normalized text,
comments stripped, from its own bundled copy of the type) reads the
installed files.

No ROS import here: the functions work on files and names.
"""

from __future__ import annotations

import importlib
import os
import re
import sys
from pathlib import Path

SEPARATOR = "=" * 80 + "\n"
MAX_DEPTH = 50  # rosbag2's ROSBAG2_CPP_LOCAL_MESSAGE_DEFINITION_SOURCE_MAX_RECURSION_DEPTH

# The three regular expressions of rosbag2_cpp/local_message_definition_source.cpp, verbatim.
_PACKAGE_TYPENAME = re.compile(r"^([a-zA-Z0-9_]+)/(?:msg/|srv/)?([a-zA-Z0-9_]+)$")
_MSG_FIELD_TYPE = re.compile(r"(?:^|\n)\s*([a-zA-Z0-9_/]+)(?:\[[^\]]*\])?\s+")
_IDL_FIELD_TYPE = re.compile(r"(?:^|\n)#include\s+(?:\"|<)([a-zA-Z0-9_/]+)\.idl(?:\"|>)")
PRIMITIVE_TYPES = frozenset(
    {
        "bool",
        "byte",
        "char",
        "float32",
        "float64",
        "int8",
        "uint8",
        "int16",
        "uint16",
        "int32",
        "uint32",
        "int64",
        "uint64",
        "string",
    }
)


class UnknownMessageType(LookupError):
    """A message type that is not installed here (no Python class, or no definition file)."""


# Definitions no wheel ships (tf2_msgs/msg/TFMessage), kept in the repository as data.
BUNDLED_SHARE = Path(__file__).resolve().parent.parent / "interfaces" / "share"


def share_directories() -> list[Path]:
    """Where packages keep their ``share/<pkg>`` folders, in search order.

    ``AMENT_PREFIX_PATH`` (a sourced ROS install) first, then this Python
    environment's prefix, where the ROS 2 wheels install their data files,
    then :data:`BUNDLED_SHARE`, the definitions no wheel ships.
    """
    prefixes = [p for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
    prefixes += [sys.prefix, sys.base_prefix]
    seen: list[Path] = []
    for share in [Path(prefix) / "share" for prefix in prefixes] + [BUNDLED_SHARE]:
        if share.is_dir() and share not in seen:
            seen.append(share)
    return seen


def _definition_file(type_name: str, extension: str) -> str:
    """The text of ``pkg/msg/Name.<extension>``; raises :class:`UnknownMessageType`."""
    match = _PACKAGE_TYPENAME.match(type_name)
    if not match:
        raise UnknownMessageType(f"{type_name!r} is not a type name like pkg/msg/Name")
    package, name = match.groups()
    for share in share_directories():
        path = share / package / "msg" / f"{name}.{extension}"
        if path.is_file():
            return path.read_text(encoding="utf-8")
    raise UnknownMessageType(
        f"no {name}.{extension} of package {package} in " + ", ".join(str(s) for s in share_directories())
    )


def _dependencies(text: str, package: str, extension: str) -> list[str]:
    """The types a definition uses, sorted as rosbag2's ``std::set`` sorts them."""
    if extension == "idl":
        return sorted({m.group(1) for m in _IDL_FIELD_TYPE.finditer(text)})
    found = set()
    for m in _MSG_FIELD_TYPE.finditer(text):
        name = m.group(1)
        if name in PRIMITIVE_TYPES:
            continue
        found.add(name if "/" in name else f"{package}/{name}")
    return sorted(found)


def full_text(type_name: str) -> tuple[str, str]:
    """The schema of a message type as rosbag2 writes it: ``(encoding, text)``.

    Args:
        type_name: e.g. ``sensor_msgs/msg/JointState``.

    Returns:
        ``("ros2msg", text)`` from the ``.msg`` files; ``("ros2idl", text)``
        when the type only has an ``.idl`` file (rosbag2's fall-back).

    Raises:
        UnknownMessageType: no definition file of the type or of a type it
            uses is installed (rosbag2 then writes an empty ``unknown``
            schema; :class:`tutorial.tools.bag.record.BagRecorder` does the same).

    Any thread may call this (it reads files only).
    """
    for extension, encoding in (("msg", "ros2msg"), ("idl", "ros2idl")):
        try:
            text = _append_recursive(type_name, extension, set(), MAX_DEPTH)
        except UnknownMessageType:
            if extension == "idl":
                raise
            continue
        if extension == "idl":
            text = SEPARATOR + f"IDL: {type_name}\n" + text
        return encoding, text
    raise AssertionError("unreachable")


def _append_recursive(type_name: str, extension: str, seen: set[str], depth: int) -> str:
    if depth <= 0:
        raise UnknownMessageType(f"definition of {type_name} nests deeper than {MAX_DEPTH} levels")
    text = _definition_file(type_name, extension)
    package = _PACKAGE_TYPENAME.match(type_name).group(1)
    result = text
    for dep in _dependencies(text, package, extension):
        if dep not in seen:
            seen.add(dep)
            result += "\n" + SEPARATOR + f"{'MSG' if extension == 'msg' else 'IDL'}: {dep}\n"
            result += _append_recursive(dep, extension, seen, depth - 1)
    return result


def message_class(type_name: str):
    """The Python class of a ROS 2 message type, e.g. ``sensor_msgs.msg.JointState``.

    Args:
        type_name: ``pkg/msg/Name`` as ROS 2 spells it in the graph and in bags.

    Raises:
        UnknownMessageType: the name is not of that form, or the package's
            Python module is not installed here.

    This is what ``rosidl_runtime_py.utilities.get_message`` does (no wheel
    of it on PyPI).  Any thread may call this.
    """
    match = re.fullmatch(r"([a-zA-Z0-9_]+)/msg/([a-zA-Z0-9_]+)", type_name)
    if not match:
        raise UnknownMessageType(f"{type_name!r} is not a message type name like pkg/msg/Name")
    package, name = match.groups()
    try:
        module = importlib.import_module(f"{package}.msg")
    except ImportError:
        raise UnknownMessageType(
            f"message type {type_name} is not installed here (no Python module {package}.msg)"
        ) from None
    cls = getattr(module, name, None)
    if cls is None:
        raise UnknownMessageType(f"message type {type_name} is not installed here ({package}.msg has no {name})")
    return cls

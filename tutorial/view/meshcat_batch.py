"""A frame's transforms as one meshcat message: the ``set_transforms`` command.

meshcat's protocol has one message per command, so a frame that moves
three bodies costs the server three forwards and the page three WebSocket
messages, each a task on the page's busy main thread.  On a machine
without a GPU the page rasterizes on the same cores as the simulation,
and those tasks were most of the time from the viewer's send to the
pixel (``make bench``'s publish-to-pixel experiment; the book's Benchmarks
page).

``set_transforms`` holds a frame's ``set_transform`` commands, each exactly
as meshcat-python lowers it::

    {"type": "set_transforms", "commands": [{"type": "set_transform", "path": ..., "matrix": [16 floats]}, ...]}

sent to the server as the zmq frames ``[b"set_transforms", b"", packed]``.
The project's server (:mod:`tutorial.view.meshcat_server`) keeps each inner
command in its scene tree, as if it had come alone (a page that opens
later is sent the newest pose of each body, by meshcat's own code), and
forwards the whole as one WebSocket message.  The page it serves
(:data:`tutorial.view.meshcat_page.PAGE_HTML`) hands each inner command to
meshcat's own ``handle_command``.  meshcat's own server does not know the command: it
answers ``error: ...`` and forwards nothing, and the scene then sends one
command per transform again (:class:`tutorial.view.scene.Scene`).

Every function here may be called from any thread.
"""

from __future__ import annotations

import msgpack

SET_TRANSFORMS = "set_transforms"


class BadBatch(ValueError):
    """A ``set_transforms`` message that is not a list of ``set_transform`` commands (the server refuses it)."""


def pack_batch(commands: list[dict]) -> bytes:
    """The bytes of one ``set_transforms`` command holding ``commands``.

    Args:
        commands: lowered ``set_transform`` commands (``SetTransform(...).lower()``).
    """
    return msgpack.packb({"type": SET_TRANSFORMS, "commands": commands})


def split_batch(data: bytes) -> list[tuple[list[str], bytes]]:
    """The server's side: each inner command's path (split, as meshcat's server splits it) and its own bytes.

    The bytes are what meshcat-python would have sent for that transform
    alone (msgpack packs byte for byte as its umsgpack does), so the scene
    tree holds the same as after single commands.

    Raises:
        BadBatch: ``data`` is not msgpack, or not a ``set_transforms`` command whose
            every entry is a ``set_transform`` with a string path and 16 numbers.
    """
    try:
        batch = msgpack.unpackb(data, strict_map_key=True)
    except Exception as error:  # msgpack raises several types for bad bytes; all mean the same here
        raise BadBatch(f"not msgpack: {type(error).__name__}") from None
    if (
        not isinstance(batch, dict)
        or batch.get("type") != SET_TRANSFORMS
        or not isinstance(batch.get("commands"), list)
    ):
        raise BadBatch("expected {'type': 'set_transforms', 'commands': [...]}")
    out = []
    for command in batch["commands"]:
        if not (
            isinstance(command, dict)
            and command.get("type") == "set_transform"
            and isinstance(command.get("path"), str)
            and isinstance(command.get("matrix"), list)
            and len(command["matrix"]) == 16
            and all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in command["matrix"])
        ):
            raise BadBatch("every command must be a set_transform with a path and 16 numbers")
        path = [part for part in command["path"].split("/") if part]
        out.append((path, msgpack.packb(command)))
    return out

"""A frame's transforms as one meshcat message: the ``set_transforms`` command.

meshcat's protocol has one message per command, so a frame that moves
three bodies costs the server three forwards and the page three WebSocket
messages, each a task on the page's main thread.  On a machine without a
GPU the page rasterizes on the same cores as the simulation, and those
tasks add to the time from the viewer's send to the pixel; one message a
frame takes them away (``make bench``'s publish-to-pixel experiment: the
book's Benchmarks page, "From publish to pixel").

``set_transforms`` holds a frame's ``set_transform`` commands, each exactly
as meshcat-python lowers it::

    {"type": "set_transforms", "commands": [{"type": "set_transform", "path": ..., "matrix": [16 floats]}, ...]}

sent to the server as the zmq frames ``[b"set_transforms", b"", packed]``.
The project's server (:mod:`tutorial.tools.standalone.meshcat_server`) keeps each inner
command in its scene tree, as if it had come alone (a page that opens
later is sent the newest pose of each body, by meshcat's own code), and
forwards the whole as one WebSocket message.  The page it serves
(:mod:`tutorial.view.meshcat_page`) hands each inner command to
meshcat's own ``handle_command``.  meshcat's own server does not know the
command: it answers ``error: unrecognized comand`` and forwards nothing,
and the scene's sink then sends one command per transform again
(:class:`tutorial.tools.standalone.sinks.BatchSink`).

Every function here may be called from any thread.
"""

from __future__ import annotations

import msgpack

SET_TRANSFORMS = "set_transforms"
# Limits of one batch: far above any frame the tutorial draws (a tank moves 3 bodies, the 48-joint arm 48),
# low enough that a bad message is refused at once: meshcat's scene tree is walked one call per path part,
# and a path deeper than Python's recursion limit would stop the server's only thread.
MAX_COMMANDS = 10_000
MAX_PATH_PARTS = 64
MAX_PATH_CHARS = 1024
MAX_BATCH_BYTES = 8 * 1024 * 1024


class BadBatch(ValueError):
    """A ``set_transforms`` message that is not a list of ``set_transform`` commands (the server refuses it)."""


def pack_batch(commands: list[dict]) -> bytes:
    """The bytes of one ``set_transforms`` command holding ``commands``.

    Args:
        commands: lowered ``set_transform`` commands (``SetTransform(...).lower()``): each a
            ``path`` (str, e.g. ``/meshcat/rtt/Tank/CHASSIS``) and a ``matrix``, the 4x4 pose
            as 16 floats in column-major order, translation in m.
    """
    return msgpack.packb({"type": SET_TRANSFORMS, "commands": commands})


def _is_transform(command) -> bool:
    if not (isinstance(command, dict) and command.get("type") == "set_transform"):
        return False
    path, matrix = command.get("path"), command.get("matrix")
    return (
        isinstance(path, str)
        and len(path) <= MAX_PATH_CHARS
        and path.count("/") <= MAX_PATH_PARTS
        and isinstance(matrix, list)
        and len(matrix) == 16
        and all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in matrix)
    )


def split_batch(data: bytes) -> list[tuple[list[str], bytes]]:
    """The server's side: each inner command's path (split, as meshcat's server splits it) and its own bytes.

    The bytes are what meshcat-python would have sent for that transform
    alone (msgpack packs byte for byte as its umsgpack does), so the scene
    tree holds the same as after single commands.  The whole batch is
    checked before anything is returned: a bad command refuses it all.
    Non-finite numbers pass, as meshcat's own server passes them.

    Raises:
        BadBatch: ``data`` is not msgpack, or not a ``set_transforms`` command whose every
            entry is a ``set_transform`` with a string path and 16 numbers, or it is over a
            limit (:data:`MAX_COMMANDS` commands, :data:`MAX_PATH_PARTS` path parts,
            :data:`MAX_PATH_CHARS` path characters, :data:`MAX_BATCH_BYTES` bytes).
    """
    if len(data) > MAX_BATCH_BYTES:
        raise BadBatch(f"over {MAX_BATCH_BYTES} bytes")
    try:
        batch = msgpack.unpackb(
            data, max_array_len=MAX_COMMANDS, max_map_len=16, max_str_len=MAX_PATH_CHARS, max_bin_len=0
        )
    except Exception as error:  # msgpack raises several types for bad bytes; all mean the same here
        raise BadBatch(f"not msgpack within the limits: {type(error).__name__}") from None
    if (
        not isinstance(batch, dict)
        or batch.get("type") != SET_TRANSFORMS
        or not isinstance(batch.get("commands"), list)
    ):
        raise BadBatch("expected {'type': 'set_transforms', 'commands': [...]}")
    if not all(_is_transform(command) for command in batch["commands"]):
        raise BadBatch(
            f"every command must be a set_transform with a path (at most {MAX_PATH_PARTS} parts, "
            f"{MAX_PATH_CHARS} characters) and 16 numbers"
        )
    return [([part for part in c["path"].split("/") if part], msgpack.packb(c)) for c in batch["commands"]]

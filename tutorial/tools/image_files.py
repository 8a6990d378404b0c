"""Camera pictures as PNG: bytes, files written whole or not at all, and ``rtt-image``'s status line.

Tooling around :mod:`tutorial.view.images` (what ``rtt-image`` does with the
pictures it receives); the notebooks show theirs with an ``ipywidgets.Image``.
"""

from __future__ import annotations

import io
import os
from pathlib import Path

import numpy as np

from tutorial.view.images import ReceivedImage


class PngWriter:
    """Writes pictures to ``path``: one file replaced each time, or numbered files.

    Args:
        path: a file name, or a pattern with ``{n}`` (``frames/image_{n:04d}.png``)
            for numbered files.
        max_files: with a pattern, the most files written; later writes are refused.

    Raises:
        ValueError: ``path`` is a directory, or a pattern that does not format.

    One thread only (the main thread of ``rtt-image``).
    """

    def __init__(self, path: str, max_files: int = 100):
        self.pattern = "{n" in path
        if os.path.isdir(path):
            raise ValueError(f"--output {path} is a directory: give a file name or a pattern with {{n}}")
        if self.pattern:
            try:
                path.format(n=0)
            except (KeyError, IndexError, ValueError) as exc:
                raise ValueError(f"--output {path}: not a pattern of {{n}}: {exc}") from None
        self.path = path
        self.max_files = max_files
        self.written = 0

    def write(self, pixels: np.ndarray) -> str | None:
        """Write one ``(H, W, 3)`` uint8 picture; the file name, or None when the limit is reached."""
        if self.pattern and self.written >= self.max_files:
            return None
        target = Path(self.path.format(n=self.written) if self.pattern else self.path)
        target.parent.mkdir(parents=True, exist_ok=True)
        tmp = target.with_name(f".{target.name}.tmp")
        tmp.write_bytes(png_bytes(pixels))
        os.replace(tmp, target)  # whole or not at all: a reader never sees half a PNG
        self.written += 1
        return str(target)


def format_image_status(received: dict, rate: float, newest: ReceivedImage | None) -> str:
    """The once-a-second status line of ``rtt-image`` (without its node prefix)."""
    rejected = received["rejected"]
    reject_text = "none" if not rejected else f"{rejected} (last: {received['last_error']})"
    if newest is None:
        return f"{rate:.1f} img/s, no picture yet, rejected: {reject_text}"
    h, w, _ = newest.pixels.shape
    size = f" ({newest.size / 1000:.1f} kB)" if "compressed" in newest.encoding else ""
    return (
        f"{rate:.1f} img/s, {w}x{h} {newest.encoding}{size} frame {newest.frame_id or '(none)'}, "
        f"newest stamp {newest.stamp:.3f} s, {received['accepted']} accepted, rejected: {reject_text}"
    )


def png_bytes(pixels: np.ndarray) -> bytes:
    """An ``(H, W, 3)`` uint8 RGB array as PNG bytes (for ``ipywidgets.Image`` or a file).

    Any thread may call it (it draws no figure).

    Raises:
        ValueError: the array is not ``(H, W, 3)`` uint8.
    """
    from matplotlib.image import imsave

    if pixels.ndim != 3 or pixels.shape[2] != 3 or pixels.dtype != np.uint8:
        raise ValueError(f"expected an (H, W, 3) uint8 array, got {pixels.shape} {pixels.dtype}")
    buf = io.BytesIO()
    imsave(buf, pixels, format="png")
    return buf.getvalue()

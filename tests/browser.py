"""Headless Chromium for the browser tests: screenshots of localhost pages."""

from __future__ import annotations

import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np

FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--enable-unsafe-swiftshader",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-quic",
    "--window-size=800,600",
    "--hide-scrollbars",
]


def chromium() -> str | None:
    return shutil.which("chromium") or shutil.which("chromium-browser")


def screenshot(url: str, path: Path, budget_ms: int = 3000, timeout: float = 60.0) -> np.ndarray:
    """Load ``url`` (localhost only) and return the screenshot as an (H, W, 3) float array in 0..1.

    ``budget_ms`` of virtual time: Chromium waits for the page's loads (meshcat's script, its WebSocket) and
    lets it run that long before the picture; 3 s draws every page here (8 s took 2 to 3 s longer a picture).
    """
    import matplotlib.image

    assert url.startswith("http://127.0.0.1:"), url
    with tempfile.TemporaryDirectory() as profile:
        subprocess.run(
            [
                chromium(),
                *FLAGS,
                f"--user-data-dir={profile}",
                f"--virtual-time-budget={budget_ms}",
                f"--screenshot={path}",
                url,
            ],
            check=True,
            timeout=timeout,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
    return matplotlib.image.imread(str(path))[:, :, :3]


def greenish_pixels(image: np.ndarray) -> int:
    """Pixels where green clearly beats blue: the tank's olive paint against meshcat's blue background."""
    r, g, b = image[..., 0], image[..., 1], image[..., 2]
    return int(np.count_nonzero((g > b + 0.06) & (g >= r)))


# Count the messages a page's window gets for ``ms`` after one is posted to it (Playwright's page or frame).
MESSAGES_AFTER_ONE = """(ms) => new Promise((done) => {
  let n = 0;
  const count = () => { n += 1; };
  window.addEventListener("message", count);
  window.postMessage("one message, as a browser extension or an embedding page may post", "*");
  setTimeout(() => { window.removeEventListener("message", count); done(n); }, ms);
})"""


def messages_after_one(frame, ms: int = 500) -> int:
    """How many messages a meshcat page's window gets in ``ms`` after one is posted to it: 1 unless something
    answers it (meshcat's bundled GIF worker did, endlessly: :data:`tutorial.view.meshcat_page.UNHOOK_SCRIPT`)."""
    return frame.evaluate(MESSAGES_AFTER_ONE, ms)

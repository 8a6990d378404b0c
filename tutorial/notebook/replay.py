"""Self-contained 3D pages: meshcat's viewer and recorded scenes, with no server.

A live 3D view needs a meshcat server, which is gone once the run has
ended or the notebook is closed.  What stays in the notebook, and in the
book, is a *recording*: one HTML page holding meshcat's own viewer script
and the drawing commands of one or more scenes, each in its own pane, side
by side, with an animation of what the robot did.

The commands are meshcat's own (``SetObject``, ``SetTransform``,
``SetAnimation``, packed with msgpack as its server stores them).
:class:`ViewRecording` collects them in place of a server and keeps the
same scene tree meshcat's server keeps (``meshcat.servers.tree``), so a
:class:`tutorial.view.scene.Scene` draws into it exactly as into a live page,
and the page replays the tree the way meshcat's own static page does.

Size: meshcat's viewer script is 850 kB.  A page carries it once,
gzip-compressed (about 290 kB as base64), and the browser unpacks it with
its built-in ``DecompressionStream``.  Animation values are rounded to
0.1 mm and 1e-4 and packed as 32-bit floats, and a body gets a key only
where its pose changes, so a recording stays small and is byte-identical
for identical runs.

In the browser, each pane's viewer is made lighter where WebGL runs on the
CPU, as the live page is (``rttLighten``, :mod:`tutorial.view.meshcat_page`:
no multisampling, fewer triangles for round shapes, opaque closed shapes
from the front only, the background painted once), and draws only while
the page is in sight.  A recording loops its animation for as long as it is
open, and a browser draws an offscreen frame's animation as well: without
a GPU, each recording in a notebook took Chromium more than a core, scrolled
out of sight too (measured in ``benchmarks/RESULTS.md``).

Any thread may build a page: nothing here touches a live server.
"""

from __future__ import annotations

import base64
import functools
import html
import json
import re
from collections.abc import Sequence

import numpy as np

from tutorial.view.meshcat_overlays import key_frames
from tutorial.view.meshcat_page import LIGHTEN_SCRIPT, UNHOOK_SCRIPT, viewer_script_gzip

DECIMALS = 4  # animation values: 0.1 mm, 1e-4 of a unit quaternion
_UUID = re.compile(r"^[0-9a-f]{8}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{12}$")


class ViewRecording:
    """A meshcat "window" that keeps the scene tree instead of sending it to a server.

    ``visualizer()`` gives a ``meshcat.Visualizer`` drawing into it.  The
    tree follows meshcat's server: ``set_object`` replaces an object and
    clears its properties, ``set_transform`` and ``set_animation`` replace,
    ``set_property`` appends, ``delete`` removes a subtree.  Owned by one
    thread at a time.
    """

    zmq_url = None  # tells tutorial.view.scene.Scene to send every command through send()

    def __init__(self):
        from meshcat.servers.tree import SceneTree

        self.tree = SceneTree()
        self._uuids: dict[str, str] = {}  # meshcat's random ids -> ids numbered in order of appearance

    def _stable_ids(self, value):
        """``value`` with meshcat's random object ids (uuid1) replaced by numbered ones.

        The same scene then records to the same bytes every time, and ids that
        refer to each other (an object to its geometry and material) still agree.
        """
        if isinstance(value, dict):
            return {k: self._stable_ids(v) for k, v in value.items()}
        if isinstance(value, list):
            return [self._stable_ids(v) for v in value]
        if isinstance(value, str) and _UUID.match(value):
            return self._uuids.setdefault(value, f"00000000-0000-4000-8000-{len(self._uuids):012d}")
        return value

    def visualizer(self):
        """A ``meshcat.Visualizer`` whose commands land in this recording."""
        import meshcat

        return meshcat.Visualizer(window=self)

    def send(self, command) -> None:
        """Record one meshcat command (what ``ViewerWindow.send`` would send to a server)."""
        import umsgpack
        from meshcat.servers.tree import SceneTree, find_node

        data = self._stable_ids(command.lower())
        kind = data["type"]
        path = [p for p in data["path"].split("/") if p]
        packed = umsgpack.packb(data, force_float_precision="single")
        if kind == "delete":
            if path:
                parent = find_node(self.tree, path[:-1])
                if path[-1] in parent:
                    del parent[path[-1]]
            else:
                self.tree = SceneTree()
            return
        node = find_node(self.tree, path)
        if kind == "set_object":
            node.object, node.properties = packed, []
        elif kind == "set_transform":
            node.transform = packed
        elif kind == "set_property":
            node.properties.append(packed)
        elif kind == "set_animation":
            node.animation = packed
        else:
            raise ValueError(f"ViewRecording: meshcat command {kind!r} is not recorded")

    def commands(self) -> list[bytes]:
        """The packed commands that rebuild the scene, in meshcat's static-page order."""
        from meshcat.servers.tree import walk

        out: list[bytes] = []
        for node in walk(self.tree):
            if node.object is not None:
                out.append(node.object)
            out.extend(node.properties)
            if node.transform is not None:
                out.append(node.transform)
            if node.animation is not None:
                out.append(node.animation)
        return out


def record_scene(model, qpos, camera=None, root: str = "rtt") -> ViewRecording:
    """A recording holding ``model`` drawn at one posture (no animation).

    Args:
        model: the ``MjModel`` to draw.
        qpos: (nq,) positions to draw it at.
        camera: optional ``(position (3,), target (3,))`` in m, world frame.
    """
    return record_replay(model, [qpos], fps=1.0, camera=camera, root=root, animate=False)


def record_replay(
    model,
    frames: Sequence[np.ndarray],
    fps: float,
    camera=None,
    root: str = "rtt",
    animate: bool = True,
    overlays=None,
    overlay_frames=None,
) -> ViewRecording:
    """A recording holding ``model`` and a looping animation of ``frames``.

    Args:
        model: the ``MjModel`` the frames belong to.
        frames: (nq,) ``qpos`` arrays, ``1/fps`` s apart; at least one.
        fps: frames per second of the recording.
        camera: optional ``(position, target)`` for the initial view, m.
        root: the meshcat path everything is drawn under.
        animate: False draws the first frame only.
        overlays: optional :class:`tutorial.view.meshcat_overlays.Overlays` whose arrows to draw too,
            as ``overlay_frames`` says: one :meth:`~tutorial.view.meshcat_overlays.Overlays.snapshot`
            per frame (the arrows of a run are not in ``qpos``).

    Raises:
        ValueError: no frames, or not one overlay snapshot per frame.
    """
    import mujoco
    from meshcat.animation import Animation, AnimationClip

    from tutorial.view.scene import Scene

    if len(frames) == 0:
        raise ValueError("record_replay: no frames to record")
    if overlays is not None and len(overlay_frames or ()) != len(frames):
        raise ValueError(f"record_replay: {len(overlay_frames or ())} overlay snapshots for {len(frames)} frames")
    recording = ViewRecording()
    vis = recording.visualizer()
    data = mujoco.MjData(model)
    data.qpos[:] = frames[0]
    mujoco.mj_kinematics(model, data)
    scene = Scene(vis, model, root)
    scene.build(data)
    if camera is not None:
        scene.set_camera(*camera)
    if overlays is not None:
        from tutorial.view.meshcat_overlays import draw_arrow_snapshot

        draw_arrow_snapshot(vis, overlays, overlay_frames[0])
    if not animate or len(frames) < 2:
        return recording
    bodies = scene.moving_bodies
    # (frames, bodies, 7): position x y z, then quaternion x y z w (three.js order)
    poses = np.empty((len(frames), len(bodies), 7))
    for i, q in enumerate(frames):
        data.qpos[:] = q
        mujoco.mj_kinematics(model, data)
        poses[i, :, :3] = data.xpos[bodies]
        poses[i, :, 3:] = data.xquat[bodies][:, [1, 2, 3, 0]]
    poses = np.round(poses, DECIMALS) + 0.0  # + 0.0: no -0.0 in the page
    animation = Animation(default_framerate=fps)
    for k, body in enumerate(bodies):
        keep = key_frames(poses[:, k])
        clip = AnimationClip(fps=fps)
        for frame in keep:
            clip.set_property(int(frame), "position", "vector3", poses[frame, k, :3].tolist())
            clip.set_property(int(frame), "quaternion", "quaternion", poses[frame, k, 3:].tolist())
        animation.clips[vis[scene.body_path(body)].path] = clip
    if overlays is not None:
        from tutorial.view.meshcat_overlays import add_arrow_clips

        add_arrow_clips(vis, overlays, overlay_frames, animation, fps, decimals=DECIMALS)
    vis.set_animation(animation, play=True, repetitions=np.inf)
    return recording


@functools.lru_cache(maxsize=1)
def _viewer_script_gzip_base64() -> str:
    """meshcat's own viewer script, gzip-compressed (same bytes every time), as base64."""
    return base64.b64encode(viewer_script_gzip()).decode("ascii")


_PAGE = """<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>{title}</title><style>
body {{ margin: 0; display: flex; height: 100vh; background: #fff; font: 12px sans-serif; }}
.pane {{ flex: 1; position: relative; min-width: 0; border-left: 1px solid #ccc; }}
.pane:first-child {{ border-left: none; }}
.label {{ position: absolute; left: 6px; bottom: 6px; z-index: 2; padding: 2px 6px;
          background: rgba(255,255,255,0.8); border-radius: 3px; pointer-events: none; }}
.view {{ position: absolute; inset: 0; }}
</style></head><body>
{panes}
<script>
{lighten}
(async () => {{
  const unpack = (b64) => Uint8Array.from(atob(b64), (c) => c.charCodeAt(0));
  const script = unpack("{script}");
  const stream = new Blob([script]).stream().pipeThrough(new DecompressionStream("gzip"));
  (0, eval)(await new Response(stream).text());  // meshcat's viewer: defines MeshCat
  {unhook}
  const scenes = {scenes};
  // Drawn only while in sight: a notebook holds many recordings, each looping its animation, and a
  // browser draws a page's frames (offscreen ones too) as long as it is open.  Out of sight, a
  // viewer's render is skipped and its scene stays marked for the next one.
  let inSight = true;
  const viewers = scenes.map((commands, i) => {{
    const viewer = new MeshCat.Viewer(document.getElementById("view" + i));
    window.rttPage = rttLighten(viewer, "");  // lighter without a GPU (tutorial/view/meshcat_page.py)
    const render = viewer.render.bind(viewer);
    viewer.render = () => {{ if (inSight) render(); }};
    for (const c of commands) viewer.handle_command_bytearray(unpack(c));
    return viewer;
  }});
  window.rttViewers = viewers;  // for a look from the browser's console (and the tests)
  new IntersectionObserver((entries) => {{
    inSight = entries[entries.length - 1].isIntersecting;
    if (inSight) viewers.forEach((viewer) => viewer.set_dirty());
  }}).observe(document.body);
}})();
</script></body></html>
"""


def page_html(scenes: Sequence[ViewRecording], labels: Sequence[str] = (), title: str = "recording") -> str:
    """One HTML page showing ``scenes`` side by side, each with an optional label.

    Args:
        scenes: the recorded scenes, left to right.
        labels: one short text per scene, shown in its top-left corner.
        title: the page title.

    Returns:
        A complete page that needs no server and no network.
    """
    panes = "\n".join(
        '<div class="pane">'
        + (f'<div class="label">{html.escape(label)}</div>' if label else "")
        + f'<div class="view" id="view{i}"></div></div>'
        for i, label in enumerate(list(labels) + [""] * (len(scenes) - len(labels)))
    )
    encoded = [[base64.b64encode(c).decode("ascii") for c in s.commands()] for s in scenes]
    return _PAGE.format(
        title=html.escape(title),
        lighten=LIGHTEN_SCRIPT,  # defines rttLighten (no "</" in it: it cannot end the <script>)
        unhook=UNHOOK_SCRIPT,
        panes=panes,
        script=_viewer_script_gzip_base64(),
        scenes=json.dumps(encoded, separators=(",", ":")),
    )


def iframe_html(page: str, height: int = 380) -> str:
    """``page`` in an ``<iframe srcdoc=...>``: how a notebook output or a book page embeds it."""
    return (
        f'<div><iframe srcdoc="{html.escape(page, quote=True)}" '
        f'style="width: 100%; height: {int(height)}px; border: none"></iframe></div>'
    )

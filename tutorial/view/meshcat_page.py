"""The page the project's meshcat server serves at ``/static/``: meshcat's own page, and a script of ours.

The page is meshcat's own ``index.html``, as the installed meshcat ships
it, with :data:`PAGE_SCRIPT` added at the end of its body
(:func:`with_page_script`).  The script runs right after meshcat's own,
which has made the ``viewer`` and opened its WebSocket, before the first
message is handled and before the first frame is drawn.  It does two
things:

- **it draws ``set_transforms``**, a frame's transforms in one message
  (:mod:`tutorial.view.meshcat_batch`): each inner command goes to meshcat's
  own ``handle_command``, which also marks the scene for the next render, so
  a frame's transforms are drawn together, in the next animation frame;
- **it drops multisampling on a software renderer**.  meshcat asks for a
  4x multisampled (antialiased) canvas.  Without a GPU, Chromium rasterizes
  WebGL on the CPU (SwiftShader; Mesa's llvmpipe, Windows' WARP
  elsewhere), where multisampling costs a third to a half of the frame
  rate (measured, drawing every frame on an idle 2-core machine: 8 tanks
  30.7 -> 48.1 frames/s, the 48-joint arm 7.7 -> 17.8); on a GPU it is
  nearly free and is kept.  The script asks WebGL which renderer it got
  and, on a software one, gives meshcat's viewer a renderer without it
  (meshcat reads ``viewer.renderer`` each time it draws, resizes or
  captures; its camera controls are on the page's pane, not the canvas).
  ``?antialias=1`` or ``?antialias=0`` (also ``true``/``false``,
  ``yes``/``no``, ``on``/``off``) in the page's address decides instead.
  ``window.rttPage`` says what was chosen:
  ``{renderer: "...", software: true, antialias: false}``.

The page runs in the browser; this module only holds the script and adds
it (any thread), for :mod:`tutorial.view.meshcat_server`.
"""

from __future__ import annotations

PAGE_SCRIPT = """// ros-tank-tutorial's additions to meshcat's page (tutorial/view/meshcat_page.py)
(function () {
  if (typeof viewer === "undefined" || typeof MeshCat === "undefined") {
    return;  // meshcat's script did not run: nothing to add to
  }
  // A frame's transforms in one message: each goes to meshcat's own handler.
  const handleOne = viewer.handle_command.bind(viewer);
  viewer.handle_command = function (cmd) {
    if (cmd.type === "set_transforms") {
      cmd.commands.forEach(handleOne);
    } else {
      handleOne(cmd);
    }
  };
  // No multisampling where WebGL runs on the CPU, unless the address asks for it.
  const THREE = MeshCat.THREE;
  const old = viewer.renderer;
  const gl = old.getContext();
  const info = gl.getExtension("WEBGL_debug_renderer_info");
  const name = String(gl.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : gl.RENDERER));
  const software = /swiftshader|llvmpipe|softpipe|software|microsoft basic render/i.test(name);
  const asked = new URLSearchParams(location.search).get("antialias");
  const antialias = asked === null ? !software : !/^(0|false|no|off)$/i.test(asked);
  if (!antialias && gl.getContextAttributes().antialias) {
    const renderer = new THREE.WebGLRenderer({antialias: false, alpha: true});
    renderer.shadowMap.enabled = old.shadowMap.enabled;
    renderer.shadowMap.type = old.shadowMap.type;
    renderer.setPixelRatio(old.getPixelRatio());
    const size = old.getSize(new THREE.Vector2());
    renderer.setSize(size.x, size.y);
    old.domElement.replaceWith(renderer.domElement);
    old.forceContextLoss();  // its multisampled buffers go now, not at the next garbage collection
    old.dispose();
    viewer.renderer = renderer;
    viewer.set_dirty();
  }
  window.rttPage = {renderer: name, software: software, antialias: antialias};
})();
"""


def with_page_script(index_html: str) -> str:
    """meshcat's ``index.html`` text with :data:`PAGE_SCRIPT` inline at the end of its body.

    Inline, not a file of its own: a script the page had to fetch could let
    a WebSocket message be handled before it ran.
    """
    tag = f"<script>\n{PAGE_SCRIPT}</script>\n"
    end = index_html.rfind("</body>")
    return index_html + tag if end < 0 else index_html[:end] + tag + index_html[end:]

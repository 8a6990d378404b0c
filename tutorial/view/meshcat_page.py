"""The page the project's meshcat server serves at ``/static/``: meshcat's own page, and a script of ours.

The page is meshcat's own ``index.html``, as the installed meshcat ships
it, with :data:`PAGE_SCRIPT` added at the end of its body
(:func:`with_page_script`).  The script runs right after meshcat's own,
which has made the ``viewer`` and opened its WebSocket, before the first
message is handled and before the first frame is drawn.  It clears a
message handler that meshcat's script leaves on the page
(:data:`UNHOOK_SCRIPT`), and does three things:

- **it draws ``set_transforms``**, a frame's transforms in one message
  (:mod:`tutorial.view.meshcat_batch`): each inner command goes to meshcat's
  own ``handle_command``, which also marks the scene for the next render, so
  a frame's transforms are drawn together, in the next animation frame;
- **it drops multisampling on a software renderer**.  meshcat asks for a
  4x multisampled (antialiased) canvas.  Without a GPU, Chromium rasterizes
  WebGL on the CPU (SwiftShader; Mesa's llvmpipe, Windows' WARP
  elsewhere), where multisampling costs a large share of the frame rate
  (the book's Benchmarks page, "From publish to pixel"); on a GPU it is
  nearly free and is kept.  The script asks WebGL which renderer it got
  and, on a software one, gives meshcat's viewer a renderer without it
  (meshcat reads ``viewer.renderer`` each time it draws, resizes or
  captures; its camera controls are on the page's pane, not the canvas).
  ``?antialias=1`` or ``?antialias=0`` (also ``true``/``false``,
  ``yes``/``no``, ``on``/``off``) in the page's address decides instead;
- **it draws a lighter scene on a software renderer** (low detail): first,
  round shapes with fewer triangles.  meshcat asks three.js for 20 x 20
  segments a sphere and 50 a cylinder: a capsule is about 1,700
  triangles, and the 48-joint arm's 48 capsules are 83,000.  Low detail
  caps the counts at :data:`COARSE_SEGMENTS` (a capsule about 400
  triangles).  The page changes its
  own copy of each ``set_object`` before meshcat's loader reads it; the
  server keeps meshcat's counts, so each page chooses for itself.  Boxes
  and meshes keep their triangles.  Low detail also draws opaque closed
  shapes (whole boxes, spheres, cylinders) from the front only: meshcat's
  materials are two-sided, so each face was rasterized and lit a second
  time from behind, where it is never seen (a see-through material, or
  one drawn over everything, keeps both sides: its back faces show).  And
  it paints meshcat's background gradient once, as CSS under a
  transparent canvas, where meshcat draws it as a textured quad over the
  whole canvas every frame; a frame read back as a picture (meshcat's
  ``capture_image``, its animation recording) is drawn with meshcat's own.
  Screenshots of the tank and the arm are the same to a unit of rounding
  (tests/test_browser.py); what each change saves is measured on the
  book's Benchmarks page ("From publish to pixel"; the history in
  ``benchmarks/RESULTS.md``).  ``?detail=full`` or ``?detail=low`` decides instead.

``window.rttPage`` says what was chosen:
``{renderer: "...", software: true, antialias: false, detail: "low"}``.

The last two are :data:`LIGHTEN_SCRIPT`'s ``rttLighten(viewer, search)``,
which the notebooks' recordings (:mod:`tutorial.notebook.replay`) call on
each of their viewers too.

The page runs in the browser; this module only holds the scripts and adds
them (any thread), for :mod:`tutorial.tools.standalone.meshcat_server`.
"""

from __future__ import annotations

import functools
import gzip
import json
from pathlib import Path

# Low detail (see the module's docstring): the most segments a round shape gets, by three.js geometry type.
COARSE_SEGMENTS = {
    "SphereGeometry": {"widthSegments": 12, "heightSegments": 8},
    "CylinderGeometry": {"radialSegments": 16},
}

LIGHTEN_SCRIPT = """// ros-tank-tutorial: lighter where WebGL runs on the CPU (tutorial/view/meshcat_page.py)
function rttLighten(viewer, search) {
  // Which renderer WebGL got, and what the address's query (search) asks for.
  const THREE = MeshCat.THREE;
  const old = viewer.renderer;
  const gl = old.getContext();
  const info = gl.getExtension("WEBGL_debug_renderer_info");
  const name = String(gl.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : gl.RENDERER));
  const software = /swiftshader|llvmpipe|softpipe|software|microsoft basic render/i.test(name);
  const query = new URLSearchParams(search);
  const askedAntialias = query.get("antialias");
  const antialias = askedAntialias === null ? !software : !/^(0|false|no|off)$/i.test(askedAntialias);
  const askedDetail = query.get("detail");
  const detail = askedDetail === "full" || askedDetail === "low" ? askedDetail : software ? "low" : "full";
  // A whole box, sphere or cylinder (three.js's own parameters; absent ones are three.js's defaults).
  const whole = (value, full) => value === undefined || value >= full - 1e-9;
  const closedShape = (g) =>
    !!g &&
    (/^Box(Buffer)?Geometry$/.test(g.type) ||
      (/^Sphere(Buffer)?Geometry$/.test(g.type) && whole(g.phiLength, 2 * Math.PI) && whole(g.thetaLength, Math.PI)) ||
      (/^Cylinder(Buffer)?Geometry$/.test(g.type) && !g.openEnded && whole(g.thetaLength, 2 * Math.PI)));
  // Low detail: in this page's copy of each set_object, before meshcat's own handler (and its
  // loader) reads it, round shapes get at most COARSE's segments, and opaque closed shapes are drawn
  // from the front only: their back faces are never seen, and meshcat's materials are two-sided, which
  // rasterizes and lights every face a second time.  A see-through material (or one drawn over
  // everything, depthTest off) keeps both sides: there the back faces show through the front ones.
  if (detail === "low") {
    const COARSE = __COARSE__;
    const handle = viewer.handle_command.bind(viewer);
    viewer.handle_command = function (cmd) {
      const o = cmd.type === "set_object" && cmd.object;
      const geometries = o && Array.isArray(o.geometries) ? o.geometries : [];
      for (const g of geometries) {
        const most = COARSE[g && g.type] || {};
        for (const key in most) {
          if (typeof g[key] === "number" && g[key] > most[key]) g[key] = most[key];
        }
      }
      if (geometries.length > 0 && geometries.every(closedShape)) {
        for (const m of Array.isArray(o.materials) ? o.materials : []) {
          const opaque = m && !m.transparent && !(m.opacity < 1) && m.depthTest !== false;
          if (opaque && m.side === THREE.DoubleSide) m.side = THREE.FrontSide;
        }
      }
      handle(cmd);
    };
  }
  // No multisampling: a renderer without it in place of meshcat's (meshcat reads viewer.renderer
  // each time it draws, resizes or captures; its camera controls are on the pane, not the canvas).
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
  if (detail === "low") {
    // meshcat draws its background gradient as a textured quad over the whole canvas, each frame.
    // Here the canvas is left transparent over a CSS gradient of the same two colours, painted once.
    // A frame that is read back as a picture (meshcat's capture_image, its animation recording) is
    // drawn with meshcat's own background, whose texture is made once for each pair of colours.
    const meshcatsShow = viewer.show_background.bind(viewer);
    const render = viewer.render.bind(viewer);
    const captureImage = viewer.capture_image.bind(viewer);
    let shown = false;  // the Background is on (meshcat's own control)
    let picture = false;  // this frame is read back as a picture
    let texture = null;
    let textureColours = "";
    const drop = (v) => {  // the scene's background texture, unless it is the one kept
      if (v.scene.background && v.scene.background !== texture && v.scene.background.dispose) {
        v.scene.background.dispose();
      }
      v.scene.background = null;
    };
    const meshcatsTexture = (v) => {
      const node = v.scene_tree.find(["Background"]).object;
      const colours = JSON.stringify([node.top_color, node.bottom_color]);
      if (texture === null || colours !== textureColours) {
        drop(v);
        if (texture) texture.dispose();
        meshcatsShow();  // makes meshcat's texture for these colours and sets it as the background
        texture = v.scene.background;
        textureColours = colours;
      }
      return texture;
    };
    viewer.show_background = function () {
      const node = this.scene_tree.find(["Background"]).object;  // its colours are 0-255, as meshcat keeps them
      const rgb = (c) => "rgb(" + c.map((x) => Math.round(x)).join(",") + ")";
      drop(this);
      this.renderer.domElement.style.background =
        "linear-gradient(" + rgb(node.top_color) + ", " + rgb(node.bottom_color) + ")";
      shown = true;
      this.set_dirty();
    };
    viewer.hide_background = function () {
      drop(this);
      this.renderer.domElement.style.background = "";
      shown = false;
      this.set_dirty();
    };
    viewer.render = function () {
      if (!shown || !(picture || this.animator.recording)) return render();
      this.scene.background = meshcatsTexture(this);
      try {
        return render();
      } finally {
        this.scene.background = null;
      }
    };
    viewer.capture_image = function () {
      picture = true;
      try {
        return captureImage();
      } finally {
        picture = false;
      }
    };
    if (viewer.scene.background) viewer.show_background();
  }
  return {renderer: name, software: software, antialias: antialias, detail: detail};
}
""".replace("__COARSE__", json.dumps(COARSE_SEGMENTS))

# meshcat's viewer script bundles gif.js (its animation recorder), and loading the script also runs the code
# of gif.js's worker on the page itself.  That code sets ``self.onmessage``: it takes any message posted to
# the page's window as a picture to encode, and posts its result back to the same window, so one message
# (from a browser extension, an embedding page) starts a loop that keeps the page's thread busy for as long
# as it is open (gif.js issue 143).  meshcat never uses the window's handler (its recorder's workers are
# workers of their own), so every page of ours clears it once meshcat's script has run.
UNHOOK_SCRIPT = (
    "if (typeof window.onmessage === 'function') window.onmessage = null;  "
    "// gif.js's worker code on the page (tutorial/view/meshcat_page.py)"
)

PAGE_SCRIPT = (
    LIGHTEN_SCRIPT
    + """// ros-tank-tutorial's additions to meshcat's page (tutorial/view/meshcat_page.py)
(function () {
  if (typeof viewer === "undefined" || typeof MeshCat === "undefined") {
    return;  // meshcat's script did not run: nothing to add to
  }
  """
    + UNHOOK_SCRIPT
    + """
  window.rttPage = rttLighten(viewer, location.search);
  // Behind a proxy (Jupyter's /proxy/PORT/, a JupyterHub's /user/NAME/proxy/PORT/) the server's WebSocket is
  // at the page's own path without static/, not at the host's root, where meshcat's connect() looks.
  const base = location.pathname.replace(/static\\/(index\\.html)?$/, "");
  if (base !== "/" && viewer.connection) {
    viewer.connection.onclose = null;
    viewer.connection.close();
    viewer.connect(`ws://${location.host}${base}`);  // meshcat's connect() makes it wss: on an https: page
  }
  // A frame's transforms in one message: each goes to the viewer's handler, one by one.
  const handleOne = viewer.handle_command.bind(viewer);
  viewer.handle_command = function (cmd) {
    if (cmd.type === "set_transforms") {
      cmd.commands.forEach(handleOne);
    } else {
      handleOne(cmd);
    }
  };
})();
"""
)


def with_page_script(index_html: str) -> str:
    """meshcat's ``index.html`` text with :data:`PAGE_SCRIPT` inline at the end of its body.

    Inline, not a file of its own: a script the page had to fetch could let
    a WebSocket message be handled before it ran.
    """
    tag = f"<script>\n{PAGE_SCRIPT}</script>\n"
    end = index_html.rfind("</body>")
    return index_html + tag if end < 0 else index_html[:end] + tag + index_html[end:]


@functools.lru_cache(maxsize=1)
def viewer_script_gzip() -> bytes:
    """meshcat's own viewer script (``main.min.js``, 850 kB), gzip-compressed to about 220 kB.

    The fixed ``mtime`` makes the same bytes every time, so a page that
    carries them (a recording) is the same for the same scene.  Any thread.
    """
    import meshcat

    path = Path(meshcat.__file__).parent / "viewer" / "dist" / "main.min.js"
    return gzip.compress(path.read_bytes(), compresslevel=9, mtime=0)
